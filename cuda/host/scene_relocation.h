// Moves a SceneView into another address space: every array it points to
// (voxels, TFs and their tables, materials, bindings, selectors, lights,
// environment texels and distributions, majorants, minorants) goes through an upload
// function, and the returned view points at the copies. The CUDA backend
// uploads to device memory this way; tests relocate into host copies and
// render from them after poisoning the originals, which proves that no
// pointer is left behind. Host-only set-up code.
#pragma once

#include <cstddef>
#include <functional>

#include "mmrtm/scene_view.h"

namespace mmrtm {

// What is uploaded, so that an uploader can treat kinds differently (the
// CUDA backend keeps volumes across scene updates and counts bytes by kind).
enum class SceneArrayKind { Voxels, Tables, Majorants, Minorants, Environment };

// Copies `bytes` bytes from `host` and returns where the copy lives (never
// null for bytes > 0). May throw (out of memory, a failed copy).
using SceneUploader = std::function<const void*(const void* host, size_t bytes, SceneArrayKind kind)>;

// The view of the copies. Arrays of structures that hold pointers (TF views,
// the environment's row distributions) are rewritten on the host with the
// relocated pointers before they are uploaded.
SceneView RelocateSceneView(const SceneView& scene, const SceneUploader& upload);

// The bytes RelocateSceneView would upload, by kind (for a memory check
// before any allocation).
struct SceneFootprint {
  size_t voxels = 0, tables = 0, majorants = 0, minorants = 0, environment = 0;
  size_t Total() const { return voxels + tables + majorants + minorants + environment; }
};
SceneFootprint MeasureSceneView(const SceneView& scene);

}  // namespace mmrtm
