#include "scene_uploads.h"

#include <cstdint>

#include "scene_relocation.h"

namespace mmrtm {
namespace {

// The structures in the tables have no implicit padding (whose bytes would
// differ between equal values and make every table look changed).
static_assert(sizeof(TransferFunctionView) == 4 + 4 + 4 * sizeof(void*) + 4 * 4);
static_assert(sizeof(CoefficientBinding) == 8);
static_assert(sizeof(Light) == 4 + sizeof(Vec3) + sizeof(RGB) + sizeof(float));
static_assert(sizeof(MaterialView) == sizeof(float) * kCoefficientFloats + 3 * sizeof(int));

// The scene's tables as one byte string: every Tables array, with the
// pointers inside them (a TF view's keys) replaced by their offsets in the
// string, so that equal tables give equal strings whatever their addresses.
// The other arrays are summed up by their addresses and sizes.
struct ArrayDigest {
  std::vector<uint8_t> tables;
  std::vector<std::pair<const void*, size_t>> voxels;
  size_t majorantBytes = 0;
  std::pair<const void*, size_t> environment{nullptr, 0};
};

ArrayDigest Digest(const SceneView& view) {
  ArrayDigest d;
  RelocateSceneView(view, [&](const void* host, size_t bytes, SceneArrayKind kind) -> const void* {
    switch (kind) {
      case SceneArrayKind::Tables: {
        const size_t offset = d.tables.size();
        const auto* b = static_cast<const uint8_t*>(host);
        d.tables.insert(d.tables.end(), b, b + bytes);
        return reinterpret_cast<const void*>(static_cast<uintptr_t>(offset + 1));
      }
      case SceneArrayKind::Voxels:
        d.voxels.push_back({host, bytes});
        break;
      case SceneArrayKind::Majorants:
      case SceneArrayKind::Minorants:
        d.majorantBytes += bytes;
        break;
      case SceneArrayKind::Environment:
        if (!d.environment.first) d.environment = {host, bytes};  // the texels come first
        break;
    }
    return host;
  });
  return d;
}

}  // namespace

SceneUploads SceneUploadPlanner::Plan(const Scene& scene, const SceneView& view) {
  ArrayDigest d = Digest(view);
  const Scene::BuildStamps& s = scene.Stamps();
  SceneUploads u;
  if (planned_) {
    u.voxels = s.voxels != stamps_.voxels || d.voxels != voxelBuffers_;
    u.summaries = s.summaries != stamps_.summaries || u.voxels;
    u.majorants = s.majorants != stamps_.majorants || d.majorantBytes != majorantBytes_ || u.summaries;
    u.tables = d.tables != tableBytes_;
    u.environment = d.environment != environment_;
  }
  planned_ = true;
  stamps_ = s;
  voxelBuffers_ = std::move(d.voxels);
  majorantBytes_ = d.majorantBytes;
  if (u.tables) tableBytes_ = std::move(d.tables);
  environment_ = d.environment;
  counts_.voxels += u.voxels;
  counts_.summaries += u.summaries;
  counts_.majorants += u.majorants;
  counts_.tables += u.tables;
  counts_.environment += u.environment;
  return u;
}

}  // namespace mmrtm
