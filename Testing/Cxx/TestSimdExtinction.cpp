// The SIMD extinction of a plain scene (cuda/simd/plain_extinction.h)
// against the scalar path that the renderer and CUDA run (Classifier::
// Classify), on every Highway target this machine runs.
//
// The bound is 0: the same bits. Both instantiate the same per-lane
// templates, whose operations (min, max, truncation, int-to-float, +, -,
// *, /) are exactly rounded IEEE operations in the same order, and the
// SIMD file is compiled without contraction into fused multiply-adds as
// the x86-64 scalar path is (plain_extinction.cpp). So any difference is a
// defect, not rounding.
//
// The voxels of every volume end at a page that may not be read, so a gather
// past the end of the buffer crashes the test instead of reading what
// happens to lie there.
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "mmrtm/classifier.h"
#include "plain_extinction.h"
#include "simd_targets.h"

using namespace mmrtm;

namespace {

// Voxel bytes placed so that they end where an unreadable page begins.
class GuardedVoxels {
 public:
  explicit GuardedVoxels(size_t bytes) {
    const size_t page = (size_t)sysconf(_SC_PAGESIZE);
    pages_ = (bytes + page - 1) / page + 1;
    mapping_ = mmap(nullptr, pages_ * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    EXPECT_NE(mapping_, MAP_FAILED);
    char* guard = static_cast<char*>(mapping_) + (pages_ - 1) * page;
    EXPECT_EQ(mprotect(guard, page, PROT_NONE), 0);
    data_ = guard - bytes;
  }
  ~GuardedVoxels() { munmap(mapping_, pages_ * (size_t)sysconf(_SC_PAGESIZE)); }
  GuardedVoxels(const GuardedVoxels&) = delete;
  GuardedVoxels& operator=(const GuardedVoxels&) = delete;
  char* data() { return data_; }

 private:
  void* mapping_ = nullptr;
  size_t pages_ = 0;
  char* data_ = nullptr;
};

// A plain scene: one proxy of random voxels of type T, one material whose
// density TF is given; the classifier points into this object.
struct PlainScene {
  std::unique_ptr<GuardedVoxels> voxels;
  std::vector<float> keys, values;
  TransferFunctionView tf;
  MaterialView material;
  CoefficientBinding binding;
  Classifier classifier;
  float lo = 0.f, hi = 0.f;  // the voxels' value range

  PlainScene(const PlainScene&) = delete;
  PlainScene() = default;
};

template <typename T>
void FillVoxels(PlainScene* s, int nx, int ny, int nz, Interpolation interpolation, std::mt19937* rng) {
  const size_t count = (size_t)nx * ny * nz;
  s->voxels = std::make_unique<GuardedVoxels>(count * sizeof(T));
  T* v = reinterpret_cast<T*>(s->voxels->data());
  if constexpr (std::is_floating_point_v<T>) {
    s->lo = -500.f;
    s->hi = 1500.f;
  } else {
    s->lo = (float)std::numeric_limits<T>::lowest();
    s->hi = (float)std::numeric_limits<T>::max();
  }
  std::uniform_real_distribution<double> value(s->lo, s->hi);
  for (size_t i = 0; i < count; ++i) {
    const double x = value(*rng);
    v[i] = std::is_floating_point_v<T> ? (T)x : (T)std::llround(x);
  }
  VolumeView& view = s->classifier.proxies[0];
  view.data = v;
  view.type = std::is_same_v<T, uint8_t>    ? VoxelType::UInt8
              : std::is_same_v<T, int16_t>  ? VoxelType::Int16
              : std::is_same_v<T, uint16_t> ? VoxelType::UInt16
                                            : VoxelType::Float32;
  view.interpolation = interpolation;
  view.SetExtent(nx, ny, nz);
}

enum class Curve { Uniform, Searched, OneKey, PiecewiseConstant };

// The density TF over the voxels' range: evenly spaced keys jittered by up
// to a fifth of a step (the segment estimate is then off by one at times,
// as Scene::Build allows a quarter), keys at random places (the binary
// search), one key, or a CPCTF (which the SIMD code evaluates lane by lane).
void SetCurve(PlainScene* s, Curve curve, std::mt19937* rng) {
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  TransferFunctionView& tf = s->tf;
  const float span = s->hi - s->lo;
  s->keys.clear();
  s->values.clear();
  tf.type = TFType::CCTF;
  tf.uniformInverseStep = 0.f;
  if (curve == Curve::Uniform) {
    const int n = 33;
    const float step = span / (n - 1) * 0.8f;  // the curve covers the middle 80 %
    for (int i = 0; i < n; ++i)
      s->keys.push_back(s->lo + 0.1f * span + step * (i + (i > 0 && i < n - 1 ? 0.4f * (unit(*rng) - 0.5f) : 0.f)));
    tf.uniformInverseStep = 1.f / step;
  } else if (curve == Curve::Searched) {
    for (int i = 0; i < 11; ++i) s->keys.push_back(s->lo + span * unit(*rng));
    std::sort(s->keys.begin(), s->keys.end());
  } else if (curve == Curve::OneKey) {
    s->keys.push_back(s->lo + 0.5f * span);
  } else {
    tf.type = TFType::CPCTF;
    for (int i = 0; i < 4; ++i) {
      const float a = s->lo + span * unit(*rng), b = s->lo + span * unit(*rng);
      s->keys.push_back(std::min(a, b));
      s->keys.push_back(std::max(a, b));
    }
  }
  const size_t entries = tf.type == TFType::CPCTF ? s->keys.size() / 2 : s->keys.size();
  for (size_t i = 0; i < entries; ++i) s->values.push_back(4.f * unit(*rng));
  tf.count = (int)entries;
  tf.channels = 1;
  tf.keys = s->keys.data();
  tf.values = s->values.data();

  s->material.base[0] = 0.75f;
  s->material.bindingBegin = 0;
  s->material.densityBindingCount = 1;
  s->material.bindingCount = 1;
  s->binding.tf = 0;
  s->binding.quantity = Quantity::Density;
  Classifier& c = s->classifier;
  c.proxyCount = 1;
  c.tfs = &s->tf;
  c.tfCount = 1;
  c.materials = &s->material;
  c.materialCount = 1;
  c.bindings = &s->binding;
  c.defaultMaterial = 0;
  c.plain = true;
  c.maxExtinction = 2.5f;  // below the largest value * base: the clamp is taken at times
}

// Index points: inside, outside the domain by up to 3 voxels, on voxel
// centres and the domain's faces, and NaN, infinite and huge coordinates.
struct Points {
  std::vector<float> x, y, z;
};
Points MakePoints(const VolumeView& v, size_t count, std::mt19937* rng) {
  Points p;
  const float n[3] = {(float)v.nx, (float)v.ny, (float)v.nz};
  const float special[] = {std::nanf(""),
                           std::numeric_limits<float>::infinity(),
                           -std::numeric_limits<float>::infinity(),
                           1e30f,
                           -1e30f,
                           -0.f,
                           0.f};
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  std::uniform_int_distribution<int> kind(0, 15);
  for (size_t i = 0; i < count; ++i) {
    float q[3];
    for (int a = 0; a < 3; ++a) {
      const int k = kind(*rng);
      if (k == 0)
        q[a] = special[(size_t)(unit(*rng) * 7) % 7];
      else if (k == 1)
        q[a] = std::floor(unit(*rng) * n[a]);  // a voxel centre
      else if (k == 2)
        q[a] = unit(*rng) < 0.5f ? 0.f : n[a] - 1.f;  // a face of the domain
      else
        q[a] = -3.f + (n[a] + 5.f) * unit(*rng);
    }
    p.x.push_back(q[0]);
    p.y.push_back(q[1]);
    p.z.push_back(q[2]);
  }
  return p;
}

// Runs the SIMD and the scalar extinction at `points` on every available
// target; counts the points whose bits differ and reports the first.
void ExpectSameBits(const PlainScene& s, const Points& p, const std::string& what) {
  const size_t n = p.x.size();
  std::vector<float> scalar(n), simd(n);
  PlainExtinctionScalar(s.classifier, p.x.data(), p.y.data(), p.z.data(), n, scalar.data());
  for (const SimdTarget& target : AvailableSimdTargets()) {
    ForceSimdTarget(target.bits);
    ASSERT_EQ(std::string(PlainExtinctionTarget()), target.name);
    std::fill(simd.begin(), simd.end(), -1.f);
    PlainExtinctionSimd(s.classifier, p.x.data(), p.y.data(), p.z.data(), n, simd.data());
    size_t differing = 0, first = n;
    for (size_t i = 0; i < n; ++i)
      if (std::memcmp(&scalar[i], &simd[i], sizeof(float)) != 0) {
        if (!differing) first = i;
        ++differing;
      }
    EXPECT_EQ(differing, 0u) << what << " on " << target.name << ": first at (" << p.x[first] << ", " << p.y[first]
                             << ", " << p.z[first] << "): scalar " << scalar[first] << ", SIMD " << simd[first];
  }
  ForceSimdTarget(0);
}

template <typename T>
void CheckType(Interpolation interpolation, const std::string& name, int seed) {
  std::mt19937 rng(seed);
  // Odd extents (no lane count divides them), one with every axis of 2.
  const int extents[][3] = {{13, 7, 5}, {2, 2, 2}, {31, 17, 3}};
  for (const auto& e : extents)
    for (Curve curve : {Curve::Uniform, Curve::Searched}) {
      PlainScene s;
      FillVoxels<T>(&s, e[0], e[1], e[2], interpolation, &rng);
      SetCurve(&s, curve, &rng);
      const Points p = MakePoints(s.classifier.proxies[0], 4099, &rng);
      ExpectSameBits(s, p, name + " " + std::to_string(e[0]) + "x" + std::to_string(e[1]) + "x" + std::to_string(e[2]));
    }
}

}  // namespace

// Catches a dispatch that ignores the forced target (every other test here
// would then test one instruction set only), and an AVX-512 machine that
// does not run the AVX2 code as well.
TEST(SimdExtinction, EachTargetCanBeForced) {
  const std::vector<SimdTarget> targets = AvailableSimdTargets();
  ASSERT_FALSE(targets.empty());
  std::string names;
  for (const SimdTarget& t : targets) {
    names += t.name + " ";
    ForceSimdTarget(t.bits);
    EXPECT_EQ(std::string(PlainExtinctionTarget()), t.name);
  }
  ForceSimdTarget(0);
  EXPECT_EQ(std::string(PlainExtinctionTarget()), targets.front().name);
  std::printf("SIMD targets of this machine: %s\n", names.c_str());
  const bool avx512 = std::any_of(targets.begin(), targets.end(), [](const SimdTarget& t) { return t.name == "AVX3"; });
  if (avx512)
    EXPECT_TRUE(std::any_of(targets.begin(), targets.end(), [](const SimdTarget& t) { return t.name == "AVX2"; }));
}

// Trilinear lookups of each native voxel type and the CCTF after them, at
// random, outside, NaN and infinite points. Catches a wrong clamp, corner,
// fraction or cell step in the lanes; a voxel taken from the wrong byte of
// its gathered word or not sign-extended (int16) or sign-extended (uint16);
// a wrong segment of the curve (estimated or searched); the clamp of the
// extinction; and a gather past the voxels' end (the guard page).
TEST(SimdExtinction, TrilinearMatchesScalarForEachVoxelType) {
  CheckType<uint8_t>(Interpolation::Trilinear, "uint8", 1);
  CheckType<int16_t>(Interpolation::Trilinear, "int16", 2);
  CheckType<uint16_t>(Interpolation::Trilinear, "uint16", 3);
  CheckType<float>(Interpolation::Trilinear, "float", 4);
}

// Nearest lookups (label maps): catches a rounding or clamp of the nearest
// voxel that differs from the scalar one, and a nearest lookup that reads
// more than one voxel's bytes at the buffer's end.
TEST(SimdExtinction, NearestMatchesScalarForEachVoxelType) {
  CheckType<uint8_t>(Interpolation::Nearest, "uint8", 5);
  CheckType<int16_t>(Interpolation::Nearest, "int16", 6);
  CheckType<uint16_t>(Interpolation::Nearest, "uint16", 7);
  CheckType<float>(Interpolation::Nearest, "float", 8);
}

// Flat axes (one voxel: a 2D image, a single slice) and volumes of fewer
// bytes than a gathered word. Catches a corner step along a flat axis that
// reads the neighbouring row or slice, the x pair read from one word where
// there is no second voxel, and the word moved back past the buffer's start.
TEST(SimdExtinction, FlatAxesAndTinyVolumes) {
  const int extents[][3] = {{1, 9, 6}, {9, 1, 6}, {9, 6, 1}, {1, 1, 7}, {7, 1, 1}, {1, 1, 1}, {2, 1, 1}, {3, 1, 1}};
  std::mt19937 rng(9);
  for (Interpolation interpolation : {Interpolation::Trilinear, Interpolation::Nearest})
    for (const auto& e : extents) {
      const std::string name = std::to_string(e[0]) + "x" + std::to_string(e[1]) + "x" + std::to_string(e[2]);
      PlainScene a, b, c, d;
      FillVoxels<uint8_t>(&a, e[0], e[1], e[2], interpolation, &rng);
      FillVoxels<int16_t>(&b, e[0], e[1], e[2], interpolation, &rng);
      FillVoxels<uint16_t>(&c, e[0], e[1], e[2], interpolation, &rng);
      FillVoxels<float>(&d, e[0], e[1], e[2], interpolation, &rng);
      for (PlainScene* s : {&a, &b, &c, &d}) {
        SetCurve(s, Curve::Uniform, &rng);
        ExpectSameBits(*s, MakePoints(s->classifier.proxies[0], 1031, &rng), name);
      }
    }
}

// The density TF's other shapes: one key (a constant), and a CPCTF, which
// the lanes hand to Evaluate one at a time. Catches an end rule of the
// curve that differs from Evaluate's, and a lane-by-lane fallback that
// mixes up lanes.
TEST(SimdExtinction, OtherDensityTFs) {
  std::mt19937 rng(10);
  for (Curve curve : {Curve::OneKey, Curve::PiecewiseConstant}) {
    PlainScene s;
    FillVoxels<int16_t>(&s, 11, 10, 9, Interpolation::Trilinear, &rng);
    SetCurve(&s, curve, &rng);
    ExpectSameBits(s, MakePoints(s.classifier.proxies[0], 2053, &rng), curve == Curve::OneKey ? "one key" : "CPCTF");
  }
}
