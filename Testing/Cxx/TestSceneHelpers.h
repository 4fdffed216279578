// Small synthetic scenes for the tracer's unit tests.
#pragma once

#include <cmath>
#include <cstring>
#include <functional>
#include <vector>

#include "scene.h"

namespace mmrtm::test {

// A float volume of dims n^3 ... with value f(i, j, k), unit spacing at the origin.
inline HostVolume MakeVolume(int nx, int ny, int nz, const std::function<float(int, int, int)>& f, float spacing = 1.f,
                             const char* name = "scalars") {
  HostVolume v;
  v.name = name;
  v.source = name;
  v.type = VoxelType::Float32;
  v.dims = {nx, ny, nz};
  v.voxels.resize((size_t)nx * ny * nz * sizeof(float));
  float* p = reinterpret_cast<float*>(v.voxels.MutableData());
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) p[i + (size_t)nx * (j + (size_t)ny * k)] = f(i, j, k);
  v.indexToWorld = IndexToWorld({0, 0, 0}, {spacing, spacing, spacing}, {1, 0, 0, 0, 1, 0, 0, 0, 1});
  return v;
}

inline HostVolume MakeConstantVolume(int n, float value, float spacing = 1.f) {
  return MakeVolume(
      n, n, n, [value](int, int, int) { return value; }, spacing);
}

// A CCTF over proxy 0 mapping value v to v (identity), for density.
inline TransferFunctionDesc IdentityCCTF(float lo, float hi, int proxy = 0) {
  TransferFunctionDesc tf;
  tf.where = "test";
  tf.type = TFType::CCTF;
  tf.proxy = proxy;
  tf.channels = 1;
  tf.keys = {lo, hi};
  tf.values = {lo, hi};
  return tf;
}

// One material whose sigma_t equals the voxel value of proxy 0 (times
// `density`), with the given albedo; a constant environment; camera in front.
inline Scene MakeMediumScene(HostVolume volume, float density, RGB albedo, float g = 0.f) {
  Scene s;
  auto range = volume.ValueRange();
  s.proxies.push_back(std::move(volume));
  s.tfs.push_back(IdentityCCTF(std::min(range[0], 0.f), std::max(range[1], 1.f)));
  MaterialDesc m;
  m.name = "medium";
  m.base[0] = density;
  m.base[1] = albedo.r;
  m.base[2] = albedo.g;
  m.base[3] = albedo.b;
  m.base[10] = g;
  m.bindings.push_back({0, Quantity::Density});
  s.materials.push_back(m);
  s.defaultMaterial = 0;
  s.render.width = 16;
  s.render.height = 16;
  s.render.samplesPerPixel = 16;
  s.render.integrator.shadowExtinctionScale = 1.f;
  return s;
}

// A lit scene over `volume` (TestDeterminism's): the
// medium of MakeMediumScene with albedo (0.9, 0.7, 0.5) and g 0.3, half the
// collisions on the surface BSDF, a sky and a sun, the shadow scale 0.8.
inline Scene MakeLitSurfaceScene(HostVolume volume) {
  Scene s = MakeMediumScene(std::move(volume), 1.f, RGB(0.9f, 0.7f, 0.5f), 0.3f);
  s.materials[0].base[6] = 0.5f;  // half the collisions scatter on the surface BSDF
  s.environment = EnvironmentMap::DefaultSky();
  Light sun;
  sun.type = LightType::Directional;
  sun.vector = Normalize(Vec3{1.f, -1.f, 2.f});
  sun.L = RGB(2.f);
  s.lights.push_back(sun);
  s.render.integrator.shadowExtinctionScale = 0.8f;
  return s;
}

// Makes `s` (a 12^3 scene of one material) not plain: a label proxy whose
// label 1 (every other x slab) picks a copy of material 0 named "other".
inline void AddLabelledSecondMaterial(Scene& s) {
  s.proxies.push_back(MakeVolume(
      12, 12, 12, [](int i, int, int) { return (float)(i % 2); }, 1.f, "labels"));
  s.materials.push_back(s.materials[0]);
  s.materials.back().name = "other";
  TransferFunctionDesc selector;
  selector.where = "test";
  selector.type = TFType::MDPTF;
  selector.proxy = (int)s.proxies.size() - 1;
  selector.keys = {1.f};
  selector.materials = {(int)s.materials.size() - 1};
  s.tfs.push_back(selector);
  s.selectors.push_back((int)s.tfs.size() - 1);
}

}  // namespace mmrtm::test
