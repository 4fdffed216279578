// Classification of a point in three steps (paper section 5, DESIGN.md):
//   1. sample every proxy (trilinear or nearest);
//   2. pick the material: material TFs (MPCTF, MDPTF) in priority order; the
//      first that names a material whose density is above zero there wins;
//      otherwise the default material (if any) classifies the point;
//   3. evaluate that material's coefficients, multiplying the coefficient
//      TFs of each quantity across proxies.
// Step 2 is the paper's rule "MDPTF wins where its opacity exceeds zero,
// otherwise the CCTF of the original volume classifies".
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/material.h"
#include "mmrtm/transfer_function.h"
#include "mmrtm/volume.h"

namespace mmrtm {

constexpr int kMaxProxies = 4;
// The largest optical depth one voxel may have (Classifier::maxExtinction).
constexpr float kMaxOpticalDepthPerVoxel = 64.f;
// The largest radiance a light or an emitting material may give: beyond it
// (a typo, not a scene) the film's float sums would overflow to infinity.
// Lights above it are an error in the scene format; emission is clamped to
// [0, kMaxRadiance] (a product of a base and TF values can exceed it).
constexpr float kMaxRadiance = 1e20f;

// Emission bounded to [0, kMaxRadiance]; NaN (an overflowed product times
// 0) is 0.
MMRTM_CPU_GPU inline float BoundedEmission(float x) { return x > 0.f ? (x < kMaxRadiance ? x : kMaxRadiance) : 0.f; }

struct ProxySamples {
  float v[kMaxProxies] = {};
};

struct Classification {
  int material = kNoMaterial;
  float sigma_t = 0.f;
  ProxySamples proxies;
};

struct Classifier {
  VolumeView proxies[kMaxProxies];
  int proxyCount = 0;
  const TransferFunctionView* tfs = nullptr;
  int tfCount = 0;
  const MaterialView* materials = nullptr;
  int materialCount = 0;
  const CoefficientBinding* bindings = nullptr;
  const int* selectors = nullptr;  // material-TF indices into tfs, highest priority first
  int selectorCount = 0;
  int defaultMaterial = kNoMaterial;
  int gradientProxy = 0;  // whose gradient gives the surface normal
  // Additive merge (VTK's independent components): every material is
  // present at once, as a mixture of particles. sigma_t is the sum of the
  // materials' extinctions, and the other coefficients are their means
  // weighted by extinction (the collision's particle is of material m with
  // probability sigma_m / sigma_t). Material TFs and the default are unused.
  bool additive = false;
  // A plain scene: one proxy, one material (the default) with one density
  // TF, no material TFs, not additive, not cropped. Classify then takes its
  // shortest path (one lookup, one TF), so that the multi-material
  // machinery costs such a scene nothing (DESIGN.md rule 3; Documentation/performance.md).
  bool plain = false;
  // sigma_t is at most this (per mm): Scene::Build sets it to an optical
  // depth of kMaxOpticalDepthPerVoxel over the tracked volume's finest
  // spacing. Beyond it a voxel passes less than e^-64 of the light either
  // way, but the null collisions a ray takes through a cell grow with the
  // majorant: an extinction of 1e30/mm from a typed density, or VTK's
  // opacity over a unit distance near 0, would never finish a ray. The
  // majorants are clamped alike, so they stay bounds.
  float maxExtinction = kInfinity;

  // VTK's cropping regions (vtkVolumeMapper::SetCroppingRegionFlags) other
  // than the subvolume, which SceneView::DomainInterval clips: two planes
  // per axis of the data's coordinates (`worldToCrop` takes a world point
  // there) cut space into 27 regions, region x + 3y + 9z (each 0 below the
  // low plane, 1 between, 2 above) kept where its bit of cropKeep is set,
  // as VTK numbers them. The volume is empty elsewhere. kNoCropping: all
  // kept. The majorants ignore cropping (they stay bounds; Scene::Build
  // drops the minorants while cropping).
  static constexpr uint32_t kNoCropping = (1u << 27) - 1u;
  uint32_t cropKeep = kNoCropping;
  Affine3 worldToCrop;
  float cropLo[3] = {0.f, 0.f, 0.f}, cropHi[3] = {0.f, 0.f, 0.f};

  MMRTM_CPU_GPU bool Cropped(Vec3 world) const {
    const Vec3 p = worldToCrop.ApplyPoint(world);
    const float x[3] = {p.x, p.y, p.z};
    int region = 0;
    for (int a = 2; a >= 0; --a) region = 3 * region + (x[a] < cropLo[a] ? 0 : x[a] > cropHi[a] ? 2 : 1);
    return !((cropKeep >> region) & 1u);
  }

  // Proxies on proxy 0's voxel grid (OnSameVoxelGrid: a label map or a
  // derived proxy resampled to the image; proxy 0 itself) are sampled at
  // proxy 0's index coordinates, which the tracker has from its index-space
  // ray: no transform per lookup, and the very coordinates over which the
  // majorant grid summarizes them (exact voxel boxes, MajorantGrid).
  bool onProxy0Grid[kMaxProxies] = {true};

  MMRTM_CPU_GPU ProxySamples SampleProxies(Vec3 world) const {
    ProxySamples s;
    SampleProxies(world, proxies[0].worldToIndex.ApplyPoint(world), &s);
    return s;
  }
  // The same into `s`, with `index0`, `world` in proxy 0's index space
  // (Classify's own: the tracker has index0, and no temporary is copied).
  MMRTM_CPU_GPU void SampleProxies(Vec3 world, Vec3 index0, ProxySamples* s) const {
    for (int i = 0; i < proxyCount; ++i)
      s->v[i] = onProxy0Grid[i] ? proxies[i].SampleIndex(index0) : proxies[i].SampleWorld(world);
  }

  // Extinction of material m at the sampled proxy values.
  MMRTM_CPU_GPU float Density(int m, const ProxySamples& s) const {
    const MaterialView& mat = materials[m];
    float d = mat.base[0];
    for (int b = 0; b < mat.densityBindingCount && d > 0.f; ++b) {
      const TransferFunctionView& tf = tfs[bindings[mat.bindingBegin + b].tf];
      float v;
      tf.Evaluate(s.v[tf.proxy], &v);
      d *= v;
    }
    return d;
  }

  // A plain scene's one density TF, and the extinction where it gives
  // `density`.
  MMRTM_CPU_GPU const TransferFunctionView& PlainDensityTF() const {
    return tfs[bindings[materials[0].bindingBegin].tf];
  }
  MMRTM_INLINE MMRTM_CPU_GPU float PlainExtinction(float density) const {
    return Min(materials[0].base[0] * density, maxExtinction);
  }
  // Makes *c a plain scene's classification where the volume's value is
  // `value` and the extinction sigma_t.
  MMRTM_CPU_GPU static void SetPlainClassification(float value, float sigma_t, Classification* c) {
    c->proxies.v[0] = value;
    c->sigma_t = sigma_t;
    c->material = 0;
  }

  MMRTM_CPU_GPU Classification Classify(Vec3 world) const {
    return Classify(world, proxies[0].worldToIndex.ApplyPoint(world));
  }

  // The same at a point given also in proxy 0's index space (`index0`; the
  // tracker computes it from its index-space ray).
  MMRTM_CPU_GPU Classification Classify(Vec3 world, Vec3 index0) const {
    Classification c;
#ifdef MMRTM_PLAIN_SCENE_ONLY
    // Compiled only into the benchmark that measures what the general path
    // costs a plain scene (Testing/Benchmarks/mmrtm-bench-plain-scene.cpp).
    constexpr bool shortest = true;
#else
    const bool shortest = plain;
#endif
    if (shortest) {
      c.proxies.v[0] = proxies[0].SampleIndex(index0);
      float v;
      PlainDensityTF().Evaluate(c.proxies.v[0], &v);
      SetPlainClassification(c.proxies.v[0], PlainExtinction(v), &c);
      return c;
    }
    if (cropKeep != kNoCropping && Cropped(world)) return c;  // (a cropped scene is not plain)
    SampleProxies(world, index0, &c.proxies);
    if (additive) {
      for (int m = 0; m < materialCount; ++m) c.sigma_t += Density(m, c.proxies);
      c.material = c.sigma_t > 0.f ? 0 : kNoMaterial;  // a mixture: see Coefficients
      c.sigma_t = Min(c.sigma_t, maxExtinction);
      return c;
    }
    for (int i = 0; i < selectorCount; ++i) {
      const TransferFunctionView& tf = tfs[selectors[i]];
      int m = tf.EvaluateMaterial(c.proxies.v[tf.proxy]);
      if (m == kNoMaterial) continue;
      float d = Density(m, c.proxies);
      if (d > 0.f) {
        c.material = m;
        c.sigma_t = Min(d, maxExtinction);
        return c;
      }
    }
    if (defaultMaterial != kNoMaterial) {
      c.material = defaultMaterial;
      c.sigma_t = Min(Density(defaultMaterial, c.proxies), maxExtinction);
    }
    return c;
  }

  // Material m's coefficients (base times its coefficient TFs) at the
  // sampled proxy values, the density slot excepted.
  MMRTM_CPU_GPU void MaterialCoefficientArray(int m, const ProxySamples& s, float* k) const {
    const MaterialView& mat = materials[m];
    for (int i = 0; i < kCoefficientFloats; ++i) k[i] = mat.base[i];
    for (int b = mat.densityBindingCount; b < mat.bindingCount; ++b) {
      const CoefficientBinding& bind = bindings[mat.bindingBegin + b];
      const TransferFunctionView& tf = tfs[bind.tf];
      float v[kMaxTFChannels];
      tf.Evaluate(s.v[tf.proxy], v);
      int offset = QuantityOffset(bind.quantity), n = QuantityChannels(bind.quantity);
      for (int ch = 0; ch < n; ++ch) k[offset + ch] *= v[tf.channels == 1 ? 0 : ch];
    }
  }

  // All coefficients of the classified material (at real collisions only).
  MMRTM_CPU_GPU MaterialCoefficients Coefficients(const Classification& c) const {
    MaterialCoefficients out;
    if (c.material == kNoMaterial) return out;
    float k[kCoefficientFloats];
    if (additive) {
      // The mixture: each material's coefficients weighted by its share of
      // sigma_t (of the sum before the clamp, so that the shares add up to
      // 1; summed again only where the clamp applied).
      for (int i = 0; i < kCoefficientFloats; ++i) k[i] = 0.f;
      float total = c.sigma_t;
      if (!(total < maxExtinction)) {
        total = 0.f;
        for (int m = 0; m < materialCount; ++m) total += Density(m, c.proxies);
      }
      for (int m = 0; m < materialCount; ++m) {
        const float d = Density(m, c.proxies);
        if (!(d > 0.f)) continue;
        float km[kCoefficientFloats];
        MaterialCoefficientArray(m, c.proxies, km);
        const float w = d / total;
        for (int i = 0; i < kCoefficientFloats; ++i) k[i] += w * km[i];
      }
    } else {
      MaterialCoefficientArray(c.material, c.proxies, k);
    }
    out.sigma_t = c.sigma_t;
    out.albedo = RGB(Clamp(k[1], 0.f, 1.f), Clamp(k[2], 0.f, 1.f), Clamp(k[3], 0.f, 1.f));
    out.roughness = Clamp(k[4], 0.f, 1.f);
    out.metallic = Clamp(k[5], 0.f, 1.f);
    out.surfaceProbability = Clamp(k[6], 0.f, 1.f);
    out.emission = RGB(BoundedEmission(k[7]), BoundedEmission(k[8]), BoundedEmission(k[9]));
    out.g = Clamp(k[10], -0.99f, 0.99f);
    return out;
  }

  // World-space gradient of the gradient proxy (by default the original
  // volume): the surface normal of the MM-RTM (paper section 3).
  MMRTM_CPU_GPU Vec3 Gradient(Vec3 world) const { return proxies[gradientProxy].GradientWorld(world); }
};

}  // namespace mmrtm
