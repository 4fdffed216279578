#include "scene.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <type_traits>

namespace mmrtm {

namespace {

// Discrete TFs over keys spanning at most this many integers get a dense
// index table (label maps); wider ones use a binary search.
constexpr int kMaxDenseSpan = 1 << 16;

std::string Str(float v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// 1 / the spacing of CCTF keys that are evenly spaced to within a quarter
// of it (TransferFunctionView::uniformInverseStep: the segment estimate is
// then off by at most one), else 0. Short curves keep the binary search.
float UniformInverseStep(const std::vector<float>& keys) {
  const size_t n = keys.size();
  if (n < 8) return 0.f;
  const double step = ((double)keys.back() - keys.front()) / (double)(n - 1);
  if (!(step > 0.0) || !std::isfinite(step)) return 0.f;
  for (size_t i = 0; i < n; ++i)
    if (!(std::abs((double)keys[i] - (keys.front() + step * (double)i)) <= 0.25 * step)) return 0.f;
  return (float)(1.0 / step);
}

// The bytes of what a refit of the majorant grid reads, field by field (no
// struct padding): two equal keys give equal majorants, so an unchanged
// render skips the refit without any front end having to say what changed.
class RefitKey {
 public:
  template <typename T>
  void Add(const T& v) {
    static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T> || std::is_pointer_v<T>);
    const auto* b = reinterpret_cast<const uint8_t*>(&v);
    bytes_.insert(bytes_.end(), b, b + sizeof v);
  }
  template <typename T>
  void AddAll(const std::vector<T>& values) {
    Add(values.size());
    for (const T& v : values) Add(v);
  }
  std::vector<uint8_t> Take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
};

// The next stamp of the process-wide build clock (never 0).
uint64_t NextBuildStamp() {
  static std::atomic<uint64_t> clock{0};
  return ++clock;
}

}  // namespace

std::vector<uint8_t> Scene::MakeRefitKey() const {
  RefitKey k;
  k.Add(render.accelerator.kind);
  k.Add(proxies.size());
  for (const HostVolume& v : proxies) {
    k.Add(v.voxels.data());
    k.Add(v.type);
    k.Add(v.interpolation);
    for (int a = 0; a < 3; ++a) k.Add(v.dims[a]);
    for (const auto& row : v.indexToWorld.m)
      for (float x : row) k.Add(x);
  }
  // Of the classification, the refit reads what gives sigma_t: the
  // materials' base densities and density TFs, and the material TFs. A
  // colour, surface or emission edit leaves the majorants as they are.
  std::vector<char> read(tfs.size(), 0);
  for (const MaterialDesc& m : materials)
    for (const MaterialDesc::Binding& b : m.bindings)
      if (b.quantity == Quantity::Density && b.tf >= 0 && b.tf < (int)tfs.size()) read[(size_t)b.tf] = 1;
  k.Add(tfs.size());
  for (size_t i = 0; i < tfs.size(); ++i) {
    const TransferFunctionDesc& tf = tfs[i];
    k.Add(read[i] || IsMaterialTF(tf.type));
    if (!read[i] && !IsMaterialTF(tf.type)) continue;
    k.Add(tf.type);
    k.Add(tf.proxy);
    k.Add(tf.channels);
    k.AddAll(tf.keys);
    k.AddAll(tf.values);
    k.AddAll(tf.materials);
  }
  k.Add(materials.size());
  for (const MaterialDesc& m : materials) {
    k.Add(m.base[0]);
    for (const MaterialDesc::Binding& b : m.bindings)
      if (b.quantity == Quantity::Density) k.Add(b.tf);
    k.Add(-1);  // the end of this material's density bindings
  }
  k.AddAll(selectors);
  k.Add(defaultMaterial);
  k.Add(gradientProxy);
  k.Add(additiveMaterials);
  return k.Take();
}

int Scene::ProxyIndex(const std::string& name) const {
  for (size_t i = 0; i < proxies.size(); ++i)
    if (proxies[i].name == name) return (int)i;
  return -1;
}

int Scene::MaterialIndex(const std::string& name) const {
  for (size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == name) return (int)i;
  return -1;
}

void Scene::Validate() const {
  if (proxies.empty()) throw InputError("scene: no volume");
  // The tracked region lies between the first and last voxel centres (as
  // VTK's image bounds): one voxel along an axis leaves nothing to render,
  // which is better said than shown as an empty image.
  for (int a = 0; a < 3; ++a)
    if (proxies[0].dims[a] < 2)
      throw InputError(proxies[0].Where() + ": " + std::to_string(proxies[0].dims[0]) + " x " +
                       std::to_string(proxies[0].dims[1]) + " x " + std::to_string(proxies[0].dims[2]) +
                       " voxels: volume rendering needs at least 2 voxels along every axis (the volume spans "
                       "from the first to the last voxel centre, so a single slice has no thickness)");
  if ((int)proxies.size() > kMaxProxies)
    throw InputError("scene: " + std::to_string(proxies.size()) + " proxy volumes; at most " +
                     std::to_string(kMaxProxies) + " are supported");
  if (materials.empty()) throw InputError("scene: no material");
  if (gradientProxy < 0 || gradientProxy >= (int)proxies.size()) throw InputError("scene: bad gradient proxy");
  for (const TransferFunctionDesc& tf : tfs) {
    const std::string& w = tf.where;
    if (tf.proxy < 0 || tf.proxy >= (int)proxies.size()) throw InputError(w + ": unknown proxy volume");
    if (tf.keys.empty()) throw InputError(w + ": a transfer function needs at least one point");
    const bool range = IsRangeTF(tf.type), material = IsMaterialTF(tf.type);
    const size_t n = range ? tf.keys.size() / 2 : tf.keys.size();
    if (range && tf.keys.size() % 2) throw InputError(w + ": ranges need a low and a high value");
    for (float k : tf.keys)
      if (!std::isfinite(k)) throw InputError(w + ": non-finite value in a transfer function");
    if (material) {
      if (tf.materials.size() != n) throw InputError(w + ": one material per entry is needed");
      for (int m : tf.materials)
        if (m < 0 || m >= (int)materials.size()) throw InputError(w + ": unknown material");
    } else {
      if (tf.channels != 1 && tf.channels != 3) throw InputError(w + ": coefficients have 1 or 3 channels");
      if (tf.values.size() != n * tf.channels) throw InputError(w + ": wrong number of values");
      for (float v : tf.values)
        if (!std::isfinite(v) || v < 0.f) throw InputError(w + ": coefficients must be finite and non-negative");
    }
    if (range) {
      for (size_t i = 0; i < n; ++i)
        if (!(tf.keys[2 * i] < tf.keys[2 * i + 1]))
          throw InputError(w + ": range [" + Str(tf.keys[2 * i]) + ", " + Str(tf.keys[2 * i + 1]) + ") is empty");
    } else {
      for (size_t i = 1; i < n; ++i) {
        bool ok = IsDiscreteTF(tf.type) ? tf.keys[i] > tf.keys[i - 1] : tf.keys[i] >= tf.keys[i - 1];
        if (!ok) throw InputError(w + ": points must be in increasing order of value");
      }
      if (IsDiscreteTF(tf.type))
        for (float k : tf.keys)
          if (k != std::floor(k)) throw InputError(w + ": discrete keys must be integers (label values)");
    }
  }
  for (int s : selectors)
    if (s < 0 || s >= (int)tfs.size() || !IsMaterialTF(tfs[s].type))
      throw InputError("scene: a material selector must be an MPCTF or MDPTF");
  if (defaultMaterial != kNoMaterial && (defaultMaterial < 0 || defaultMaterial >= (int)materials.size()))
    throw InputError("scene: unknown default material");
  if (defaultMaterial == kNoMaterial && selectors.empty() && !additiveMaterials)
    throw InputError("scene: no material classifies any point (set a default material or a material TF)");
  for (const MaterialDesc& m : materials)
    for (float b : m.base)
      if (!std::isfinite(b)) throw InputError("materials[" + m.name + "]: non-finite coefficient");
  const RenderSettings& r = render;
  if (r.width <= 0 || r.height <= 0 || r.width > 16384 || r.height > 16384)
    throw InputError("render: image size must be between 1 and 16384 pixels");
  if (r.samplesPerPixel <= 0) throw InputError("render: samples per pixel must be positive");
  if (r.threads < 0 || r.threads > 1024) throw InputError("render: threads must be 0 (all) to 1024");
  if (!(r.integrator.shadowExtinctionScale > 0.f && r.integrator.shadowExtinctionScale <= 1.f))
    throw InputError("render: shadow extinction scale must be in (0, 1]");
  if (!(r.integrator.rayMarchStep > 0.f)) throw InputError("render: ray marching step must be positive");
  if (r.integrator.maxBounces < 0) throw InputError("render: bounce limit must not be negative");
}

float Scene::MaxExtinction() const {
  float finest = kInfinity;
  for (int c = 0; c < 3; ++c) {
    const Affine3& m = proxies[0].indexToWorld;
    finest = std::min(finest, std::sqrt(m.m[0][c] * m.m[0][c] + m.m[1][c] * m.m[1][c] + m.m[2][c] * m.m[2][c]));
  }
  return finest > 0.f ? kMaxOpticalDepthPerVoxel / finest : kInfinity;
}

float Scene::GlobalMajorant() const { return std::min(UnclampedGlobalMajorant(), MaxExtinction()); }

float Scene::UnclampedGlobalMajorant() const {
  // Each material's density is bounded by its base times the maximum of each
  // density TF over its proxy's whole value range; the classified density is
  // one of these, so their maximum bounds sigma_t everywhere.
  const std::vector<std::array<float, 2>>& ranges = valueRanges_;
  float majorant = 0.f;
  for (size_t m = 0; m < materialViews_.size(); ++m) {
    const MaterialView& mv = materialViews_[m];
    float d = mv.base[0];
    for (int b = 0; b < mv.densityBindingCount; ++b) {
      const TransferFunctionView& tf = tfViews_[bindings_[mv.bindingBegin + b].tf];
      float maxValue[kMaxTFChannels];
      tf.MaxOverRange(ranges[tf.proxy][0], ranges[tf.proxy][1], maxValue);
      d *= maxValue[0];
    }
    majorant = additiveMaterials ? majorant + d : std::max(majorant, d);  // a mixture's extinctions add up
  }
  return majorant;
}

CameraView Scene::BuildCamera() const {
  const CameraDesc& c = camera;
  CameraView v;
  v.projection = c.projection;
  v.width = render.width;
  v.height = render.height;
  const float tanHalf = std::tan(0.5f * c.fovY * kPi / 180.f);
  Vec3 position = c.position, lookAt = c.lookAt, up = c.up;
  // Radius of the sphere around the domain, for framing and orthographic size.
  auto bounds = proxies[0].WorldBounds();
  const float radius = 0.5f * Length(bounds[1] - bounds[0]);
  if (c.autoFrame) {
    lookAt = proxies[0].WorldCenter();
    const float az = c.azimuth * kPi / 180.f, el = c.elevation * kPi / 180.f;
    // Anterior view in LPS: the camera sits at -y and looks toward +y, head up (+z).
    Vec3 toCamera{-std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el), std::sin(el)};
    const float fit = (c.projection == Projection::Perspective) ? radius / std::sin(std::atan(tanHalf)) : 2.f * radius;
    position = lookAt + toCamera * (fit / std::max(c.zoom, 1e-3f));
    up = std::fabs(toCamera.z) > 0.999f ? Vec3{0.f, 1.f, 0.f} : Vec3{0.f, 0.f, 1.f};
  }
  Vec3 forward = lookAt - position;
  if (!(Length(forward) > 0.f)) throw InputError("camera: position and look-at point coincide");
  v.forward = Normalize(forward);
  Vec3 right = Cross(v.forward, up);
  if (!(Length(right) > 1e-6f)) throw InputError("camera: up vector is parallel to the view direction");
  v.right = Normalize(right);
  v.up = Cross(v.right, v.forward);
  v.position = position;
  v.tanHalfFovY = tanHalf;
  v.orthoHalfHeight = c.orthoHeight > 0.f ? 0.5f * c.orthoHeight : radius / std::max(c.zoom, 1e-3f);
  v.lensRadius = c.lensRadius;
  v.focusDistance = c.focusDistance > 0.f ? c.focusDistance : Length(lookAt - position);
  v.windowCenterX = c.windowCenter[0];
  v.windowCenterY = c.windowCenter[1];
  return v;
}

bool Scene::AdoptDataSummariesFrom(Scene& previous) {
  if (previous.dataModified_ || !previous.modifiedRegions_.empty() ||
      previous.summarisedVoxels_.size() != proxies.size())
    return false;
  for (size_t i = 0; i < proxies.size(); ++i)
    if (proxies[i].voxels.data() != previous.summarisedVoxels_[i]) return false;
  grid_ = std::move(previous.grid_);
  valueRanges_ = previous.valueRanges_;
  summarisedVoxels_ = previous.summarisedVoxels_;
  stamps_.voxels = previous.stamps_.voxels;
  stamps_.summaries = previous.stamps_.summaries;
  dataModified_ = false;
  return true;
}

SceneView Scene::Build() {
  Validate();
  // What depends on the voxels alone is checked and measured once per data
  // load, so that a TF change costs only the refit.
  dataModified_ = dataModified_ || valueRanges_.size() != proxies.size();
  if (dataModified_ || !modifiedRegions_.empty()) {
    valueRanges_.clear();
    summarisedVoxels_.clear();
    for (const HostVolume& v : proxies) {
      v.Validate();
      valueRanges_.push_back(v.ValueRange());
      summarisedVoxels_.push_back(v.voxels.data());
    }
    stamps_.voxels = NextBuildStamp();
  }

  // Flatten the TFs: offsets first (the pools must not reallocate under the views).
  floatPool_.clear();
  intPool_.clear();
  struct Offsets {
    size_t keys, values, materials, dense;
    int denseMin, denseCount;
  };
  std::vector<Offsets> offsets;
  for (const TransferFunctionDesc& tf : tfs) {
    Offsets o{};
    o.keys = floatPool_.size();
    floatPool_.insert(floatPool_.end(), tf.keys.begin(), tf.keys.end());
    o.values = floatPool_.size();
    floatPool_.insert(floatPool_.end(), tf.values.begin(), tf.values.end());
    o.materials = intPool_.size();
    intPool_.insert(intPool_.end(), tf.materials.begin(), tf.materials.end());
    o.dense = intPool_.size();
    if (IsDiscreteTF(tf.type)) {
      const double span = (double)tf.keys.back() - (double)tf.keys.front() + 1.0;
      if (span <= kMaxDenseSpan) {
        o.denseMin = (int)tf.keys.front();
        o.denseCount = (int)span;
        intPool_.resize(intPool_.size() + o.denseCount, -1);
        for (size_t i = 0; i < tf.keys.size(); ++i) intPool_[o.dense + (int)tf.keys[i] - o.denseMin] = (int)i;
      }
    }
    offsets.push_back(o);
  }
  tfViews_.clear();
  for (size_t i = 0; i < tfs.size(); ++i) {
    const TransferFunctionDesc& tf = tfs[i];
    const Offsets& o = offsets[i];
    TransferFunctionView v;
    v.type = tf.type;
    v.proxy = (uint8_t)tf.proxy;
    v.channels = (uint8_t)tf.channels;
    v.count = (int)(IsRangeTF(tf.type) ? tf.keys.size() / 2 : tf.keys.size());
    v.keys = floatPool_.data() + o.keys;
    v.values = tf.values.empty() ? nullptr : floatPool_.data() + o.values;
    v.materials = tf.materials.empty() ? nullptr : intPool_.data() + o.materials;
    v.denseIndex = o.denseCount ? intPool_.data() + o.dense : nullptr;
    v.denseMin = o.denseMin;
    v.denseCount = o.denseCount;
    v.uniformInverseStep = tf.type == TFType::CCTF ? UniformInverseStep(tf.keys) : 0.f;
    tfViews_.push_back(v);
  }

  // Materials, with each material's density bindings first.
  bindings_.clear();
  materialViews_.clear();
  for (const MaterialDesc& m : materials) {
    MaterialView mv;
    std::copy(m.base, m.base + kCoefficientFloats, mv.base);
    mv.bindingBegin = (int)bindings_.size();
    for (int pass = 0; pass < 2; ++pass)
      for (const MaterialDesc::Binding& b : m.bindings) {
        if ((b.quantity == Quantity::Density) != (pass == 0)) continue;
        if (b.tf < 0 || b.tf >= (int)tfs.size() || IsMaterialTF(tfs[b.tf].type))
          throw InputError("materials[" + m.name + "]: a coefficient needs a CCTF, CPCTF or CDPTF");
        bindings_.push_back({b.tf, b.quantity});
        if (pass == 0) ++mv.densityBindingCount;
      }
    mv.bindingCount = (int)bindings_.size() - mv.bindingBegin;
    materialViews_.push_back(mv);
  }

  SceneView s;
  Classifier& c = s.classifier;
  c.proxyCount = (int)proxies.size();
  for (int i = 0; i < c.proxyCount; ++i) {
    c.proxies[i] = proxies[i].View();
    c.onProxy0Grid[i] = i == 0 || OnSameVoxelGrid(proxies[i], proxies[0]);
  }
  c.tfs = tfViews_.data();
  c.materials = materialViews_.data();
  c.bindings = bindings_.data();
  c.selectors = selectors.data();
  c.selectorCount = (int)selectors.size();
  c.defaultMaterial = defaultMaterial;
  c.gradientProxy = gradientProxy;
  c.additive = additiveMaterials;
  for (int a = 0; a < 3; ++a) s.domain[a] = proxies[0].dims[a];

  c.tfCount = (int)tfViews_.size();
  c.materialCount = (int)materialViews_.size();
  c.plain = c.proxyCount == 1 && c.materialCount == 1 && c.selectorCount == 0 && !c.additive &&
            c.defaultMaterial == 0 && materialViews_[0].densityBindingCount == 1;

  // Majorants: the global bound always (it is cheap), the grid when asked
  // for. The grid's summaries depend only on the voxels; a TF change refits.
  const AcceleratorSettings& acc = render.accelerator;
  s.majorants.kind = acc.kind;
  c.maxExtinction = MaxExtinction();
  s.majorants.globalMajorant = GlobalMajorant();
  extinctionWarning_.clear();
  if (const float reach = UnclampedGlobalMajorant(); !(reach <= c.maxExtinction)) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "the materials' extinction reaches %.3g per mm; it is clamped to %.3g per mm (an optical depth of "
                  "%.0f across the finest voxel spacing, %.3g mm), beyond which every voxel is opaque anyway",
                  reach, c.maxExtinction, kMaxOpticalDepthPerVoxel, kMaxOpticalDepthPerVoxel / c.maxExtinction);
    extinctionWarning_ = text;
  }
  gridBuilt_ = false;
  gridRefitted_ = false;
  if (acc.kind != MajorantKind::Global) {
    const MajorantGridOptions& o = acc.grid;
    const bool layoutChanged = grid_ && (grid_->Options().leafLevel != o.leafLevel ||
                                         grid_->Options().margin != o.margin || grid_->Options().summary != o.summary);
    gridBuilt_ = !grid_ || dataModified_ || layoutChanged;
    if (gridBuilt_) {
      if (!grid_) grid_ = std::make_unique<MajorantGrid>();
      grid_->Build(proxies, o, buildProgress);
    } else {
      for (const auto& region : modifiedRegions_) grid_->UpdateRegion(proxies, region[0], region[1]);
    }
    std::vector<uint8_t> key = MakeRefitKey();
    gridRefitted_ = gridBuilt_ || !modifiedRegions_.empty() || key != refitKey_;
    if (gridBuilt_ || !modifiedRegions_.empty()) stamps_.summaries = NextBuildStamp();
    if (gridRefitted_) {
      grid_->Refit(c);
      refitKey_ = std::move(key);
      stamps_.majorants = NextBuildStamp();
    }
    s.majorants.grid = grid_->View();
  }
  // Cropping after the refit, which bounds the uncropped volume.
  c.cropKeep = cropping.keep;
  c.worldToCrop = cropping.worldToData;
  for (int a = 0; a < 3; ++a) {
    c.cropLo[a] = cropping.lo[a];
    c.cropHi[a] = cropping.hi[a];
  }
  if (cropping.keep != Classifier::kNoCropping) {
    s.majorants.grid.minorants = nullptr;
    c.plain = false;  // its shortest path does not crop
  }
  dataModified_ = false;
  modifiedRegions_.clear();

  s.camera = BuildCamera();
  if (clipPlanes.size() > (size_t)kMaxClipPlanes)
    throw InputError("scene: " + std::to_string(clipPlanes.size()) + " clip planes; at most " +
                     std::to_string(kMaxClipPlanes) + " are supported");
  for (const ClipPlane& p : clipPlanes) s.clipPlanes[s.clipPlaneCount++] = p;
  if (!cameraRayMaxDistance.empty()) {
    if (cameraRayMaxDistance.size() != (size_t)render.width * render.height)
      throw InputError("scene: cameraRayMaxDistance holds " + std::to_string(cameraRayMaxDistance.size()) +
                       " values for a " + std::to_string(render.width) + " x " + std::to_string(render.height) +
                       " image");
    s.cameraRayMaxDistance = cameraRayMaxDistance.data();
  }
  lightViews_ = lights;
  for (const CameraLight& cl : cameraLights) {
    const float az = cl.azimuth * kPi / 180.f, el = cl.elevation * kPi / 180.f;
    const Vec3 horizontal = -s.camera.forward * std::cos(az) + s.camera.right * std::sin(az);
    lightViews_.at(cl.light).vector = Normalize(horizontal * std::cos(el) + s.camera.up * std::sin(el));
  }
  if (environment) {
    Light env;
    env.type = LightType::Environment;
    s.environmentLight = (int)lightViews_.size();
    lightViews_.push_back(env);
    s.environment = environment->View();
  }
  s.lights = lightViews_.data();
  s.lightCount = (int)lightViews_.size();
  s.settings = render.integrator;
  return s;
}

}  // namespace mmrtm
