// See scene_relocation.h. Every pointer field of SceneView and of the views
// it holds is handled here, with the length of its array; a field added to
// a view without a line here is caught by TestSceneRelocation.
#include "scene_relocation.h"

#include <algorithm>
#include <vector>

namespace mmrtm {
namespace {

template <typename T>
const T* Move(const T* p, size_t count, SceneArrayKind kind, const SceneUploader& upload) {
  if (!p || count == 0) return nullptr;
  return static_cast<const T*>(upload(p, count * sizeof(T), kind));
}

size_t VoxelBytes(const VolumeView& v) { return (size_t)v.nx * v.ny * v.nz * VoxelTypeSize(v.type); }

size_t KeyCount(const TransferFunctionView& tf) { return (size_t)tf.count * (IsRangeTF(tf.type) ? 2 : 1); }

size_t BindingCount(const Classifier& c) {
  size_t n = 0;
  for (int m = 0; m < c.materialCount; ++m)
    n = std::max(n, (size_t)(c.materials[m].bindingBegin + c.materials[m].bindingCount));
  return n;
}

size_t MajorantCount(const MajorantSource& m) {
  if (m.kind == MajorantKind::Global || !m.grid.majorants) return 0;
  const int L = m.grid.leafLevel;
  return (size_t)m.grid.offset[L] + (size_t)m.grid.res[L][0] * m.grid.res[L][1] * m.grid.res[L][2];
}

// Applies `visit(pointer, count, kind)` to every array of the scene, in one
// order for both measuring and relocating. Arrays of structures with
// pointers are visited after their members, through `visitStructs`.
template <typename Visit>
void ForEachArray(SceneView& s, Visit visit) {
  Classifier& c = s.classifier;
  for (int i = 0; i < c.proxyCount; ++i) {
    VolumeView& v = c.proxies[i];
    v.data = visit(static_cast<const uint8_t*>(v.data), VoxelBytes(v), SceneArrayKind::Voxels);
  }
  std::vector<TransferFunctionView> tfs(c.tfs, c.tfs + c.tfCount);
  for (TransferFunctionView& tf : tfs) {
    tf.keys = visit(tf.keys, KeyCount(tf), SceneArrayKind::Tables);
    tf.values = visit(tf.values, IsMaterialTF(tf.type) ? 0 : (size_t)tf.count * tf.channels, SceneArrayKind::Tables);
    tf.materials = visit(tf.materials, IsMaterialTF(tf.type) ? (size_t)tf.count : 0, SceneArrayKind::Tables);
    tf.denseIndex = visit(tf.denseIndex, (size_t)tf.denseCount, SceneArrayKind::Tables);
  }
  const size_t bindings = BindingCount(c);
  c.tfs = visit(static_cast<const TransferFunctionView*>(tfs.data()), tfs.size(), SceneArrayKind::Tables);
  c.materials = visit(c.materials, (size_t)c.materialCount, SceneArrayKind::Tables);
  c.bindings = visit(c.bindings, bindings, SceneArrayKind::Tables);
  c.selectors = visit(c.selectors, (size_t)c.selectorCount, SceneArrayKind::Tables);

  s.majorants.grid.majorants = visit(s.majorants.grid.majorants, MajorantCount(s.majorants), SceneArrayKind::Majorants);
  s.majorants.grid.minorants =
      visit(s.majorants.grid.minorants, s.majorants.grid.minorants ? MajorantCount(s.majorants) : 0,
            SceneArrayKind::Minorants);
  s.lights = visit(s.lights, (size_t)s.lightCount, SceneArrayKind::Tables);
  s.cameraRayMaxDistance =
      visit(s.cameraRayMaxDistance, (size_t)s.camera.width * s.camera.height, SceneArrayKind::Tables);

  EnvironmentView& e = s.environment;
  e.texels = visit(e.texels, (size_t)e.width * e.height, SceneArrayKind::Environment);
  Distribution2DView& d = e.distribution;
  std::vector<Distribution1DView> rows(d.conditional, d.conditional + (d.conditional ? d.nv : 0));
  for (Distribution1DView& r : rows) {
    r.func = visit(r.func, (size_t)r.n, SceneArrayKind::Environment);
    r.cdf = visit(r.cdf, (size_t)r.n + 1, SceneArrayKind::Environment);
  }
  d.conditional = visit(static_cast<const Distribution1DView*>(rows.data()), rows.size(), SceneArrayKind::Environment);
  d.marginal.func = visit(d.marginal.func, (size_t)d.marginal.n, SceneArrayKind::Environment);
  d.marginal.cdf = visit(d.marginal.cdf, d.marginal.func ? (size_t)d.marginal.n + 1 : 0, SceneArrayKind::Environment);
}

}  // namespace

SceneView RelocateSceneView(const SceneView& scene, const SceneUploader& upload) {
  SceneView s = scene;
  ForEachArray(s, [&](auto* p, size_t count, SceneArrayKind kind) { return Move(p, count, kind, upload); });
  return s;
}

SceneFootprint MeasureSceneView(const SceneView& scene) {
  SceneView s = scene;
  SceneFootprint f;
  ForEachArray(s, [&](auto* p, size_t count, SceneArrayKind kind) {
    const size_t bytes = p ? count * sizeof(*p) : 0;
    switch (kind) {
      case SceneArrayKind::Voxels:
        f.voxels += bytes;
        break;
      case SceneArrayKind::Tables:
        f.tables += bytes;
        break;
      case SceneArrayKind::Majorants:
        f.majorants += bytes;
        break;
      case SceneArrayKind::Minorants:
        f.minorants += bytes;
        break;
      case SceneArrayKind::Environment:
        f.environment += bytes;
        break;
    }
    return p;
  });
  return f;
}

}  // namespace mmrtm
