#include "derived_proxies.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "mmrtm/planted_defect.h"
#include "mmrtm/transfer_function.h"
#include "parallel_for.h"

namespace mmrtm {

namespace {

HostVolume EmptyLike(const HostVolume& source, const std::string& name, const std::string& what) {
  HostVolume out;
  out.name = name;
  out.source = what + " of " + source.Where();
  out.interpolation = Interpolation::Trilinear;  // all derived proxies are continuous
  out.dims = source.dims;
  out.indexToWorld = source.indexToWorld;
  return out;
}

std::vector<float> ToFloat(const HostVolume& v) {
  std::vector<float> f((size_t)v.VoxelCount());
  ParallelFor(v.VoxelCount(), 0, [&](int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) f[i] = v.Value(i);
  });
  return f;
}

template <typename T>
void Store(HostVolume& out, const std::vector<float>& values) {
  out.voxels.resize(values.size() * sizeof(T));
  T* p = reinterpret_cast<T*>(out.voxels.MutableData());
  ParallelFor((int64_t)values.size(), 0, [&](int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) p[i] = (T)values[i];
  });
}

// Fills out's voxels from `values`: float32 as they are, or (integer) rounded
// to integers in the smallest type that holds their range.
void StoreSmallest(HostVolume& out, std::vector<float>& values, bool integer) {
  if (!integer) {
    out.type = VoxelType::Float32;
    return Store<float>(out, values);
  }
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (float& v : values) {
    v = std::nearbyint(v);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (lo >= 0.f && hi <= 255.f) {
    out.type = VoxelType::UInt8;
    Store<uint8_t>(out, values);
  } else if (lo >= -32768.f && hi <= 32767.f) {
    out.type = VoxelType::Int16;
    Store<int16_t>(out, values);
  } else if (lo >= 0.f && hi <= 65535.f) {
    out.type = VoxelType::UInt16;
    Store<uint16_t>(out, values);
  } else {
    out.type = VoxelType::Float32;
    Store<float>(out, values);
  }
}

// Spacing along index axis a: the length of indexToWorld's column a.
float Spacing(const HostVolume& v, int a) {
  const Affine3& m = v.indexToWorld;
  return std::sqrt(m.m[0][a] * m.m[0][a] + m.m[1][a] * m.m[1][a] + m.m[2][a] * m.m[2][a]);
}

// One pass of a 1D kernel (radius = kernel.size() / 2) along index axis
// `axis`, clamping indexes at the border.
void Convolve(const std::vector<float>& in, std::vector<float>& out, std::array<int, 3> dims, int axis,
              const std::vector<float>& kernel) {
  const int r = (int)kernel.size() / 2, n = dims[axis];
  const int64_t stride = axis == 0 ? 1 : (axis == 1 ? dims[0] : (int64_t)dims[0] * dims[1]);
  ParallelFor(dims[2], 0, [&](int64_t z0, int64_t z1) {
    for (int64_t k = z0; k < z1; ++k)
      for (int j = 0; j < dims[1]; ++j)
        for (int i = 0; i < dims[0]; ++i) {
          const int64_t at = i + (int64_t)dims[0] * (j + (int64_t)dims[1] * k);
          const int c = axis == 0 ? i : (axis == 1 ? j : (int)k);
          const int64_t base = at - c * stride;  // the line's first voxel
          float sum = 0.f;
          for (int t = -r; t <= r; ++t) sum += kernel[t + r] * in[base + std::clamp(c + t, 0, n - 1) * stride];
          out[at] = sum;
        }
  });
}

}  // namespace

HostVolume GradientMagnitudeProxy(const HostVolume& source, const std::string& name) {
  source.Validate();
  const Affine3 w2i = source.View().worldToIndex;
  HostVolume out = EmptyLike(source, name, "gradient magnitude");
  const std::array<int, 3> d = source.dims;
  const int64_t stride[3] = {1, d[0], (int64_t)d[0] * d[1]};
  std::vector<float> g((size_t)source.VoxelCount());
  ParallelFor(d[2], 0, [&](int64_t z0, int64_t z1) {
    for (int64_t k = z0; k < z1; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) {
          const int64_t at = i + stride[1] * j + stride[2] * k;
          const int c[3] = {i, j, (int)k};
          Vec3 gi;  // dv/d(index)
          for (int a = 0; a < 3; ++a) {
            if (d[a] == 1) continue;
            const int lo = std::max(c[a] - 1, 0), hi = std::min(c[a] + 1, d[a] - 1);
            gi[a] = (source.Value(at + (hi - c[a]) * stride[a]) - source.Value(at + (lo - c[a]) * stride[a])) /
                    float(hi - lo);
          }
          // dv/dworld = (d index / d world)^T dv/d(index).
          g[at] = Length(w2i.ApplyTransposeLinear(gi)) * (Planted(Defect::VtkGradientMagnitude) ? 1.01f : 1.f);
        }
  });
  StoreSmallest(out, g, source.type != VoxelType::Float32);
  return out;
}

HostVolume SmoothedProxy(const HostVolume& source, float sigmaMm, const std::string& name) {
  if (!(std::isfinite(sigmaMm) && sigmaMm > 0.f)) {
    std::ostringstream msg;
    msg << name << ": the smoothing sigma must be a positive number of mm, got " << sigmaMm;
    throw InputError(msg.str());
  }
  source.Validate();
  HostVolume out = EmptyLike(source, name, "smoothed");
  std::vector<float> a = ToFloat(source), b(a.size());
  for (int axis = 0; axis < 3; ++axis) {
    const double sigma = sigmaMm / Spacing(source, axis);  // voxels
    const int r = (int)std::ceil(3.0 * sigma);
    std::vector<float> kernel(2 * r + 1);
    double sum = 0;
    for (int t = -r; t <= r; ++t) sum += std::exp(-0.5 * t * t / (sigma * sigma));
    for (int t = -r; t <= r; ++t) kernel[t + r] = (float)(std::exp(-0.5 * t * t / (sigma * sigma)) / sum);
    Convolve(a, b, source.dims, axis, kernel);
    a.swap(b);
  }
  StoreSmallest(out, a, source.type != VoxelType::Float32);
  return out;
}

HostVolume OpacityProxy(const HostVolume& source, const std::vector<std::array<float, 2>>& points,
                        const std::string& name) {
  if (points.empty()) throw InputError(name + ": an opacity transfer function needs at least one point");
  std::vector<float> keys, values;
  for (size_t i = 0; i < points.size(); ++i) {
    const float x = points[i][0], o = points[i][1];
    std::ostringstream at;
    at << name << ": opacity point " << i << " [" << x << ", " << o << "]";
    if (!std::isfinite(x) || !std::isfinite(o)) throw InputError(at.str() + " is not finite");
    if (i > 0 && x < keys.back()) throw InputError(at.str() + ": values must not decrease");
    if (o < 0.f || o > 1.f) throw InputError(at.str() + ": opacity must be in 0..1");
    keys.push_back(x);
    values.push_back(o);
  }
  source.Validate();
  // Evaluated by the tracer's own CCTF code, so the proxy is exactly the
  // opacity a CCTF with these points would give.
  TransferFunctionView tf;
  tf.type = TFType::CCTF;
  tf.count = (int)keys.size();
  tf.keys = keys.data();
  tf.values = values.data();
  HostVolume out = EmptyLike(source, name, "opacity");
  out.type = VoxelType::UInt8;
  out.voxels.resize((size_t)source.VoxelCount());
  uint8_t* opacity = out.voxels.MutableData();
  ParallelFor(source.VoxelCount(), 0, [&](int64_t b, int64_t e) {
    for (int64_t i = b; i < e; ++i) {
      float o;
      tf.Evaluate(source.Value(i), &o);
      opacity[i] = (uint8_t)std::lround(o * 255.f);
    }
  });
  return out;
}

}  // namespace mmrtm
