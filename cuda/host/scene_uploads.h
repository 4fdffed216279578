// What of a built scene a backend that keeps its own copy (the CUDA
// backend's device scene) must send again: only the parts that changed
// since its last upload. The decision is host code, so that it is tested,
// and its requests counted, on machines without a device. Host-only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "scene.h"

namespace mmrtm {

// One flag per part of a SceneView's arrays (SceneArrayKind); a part not
// asked for keeps the copy it has.
struct SceneUploads {
  bool voxels = true;       // the proxies' voxels
  bool summaries = true;    // the grid's per-leaf summaries (the device refit reads them)
  bool majorants = true;    // the grid's majorants and minorants (then refitted on the device)
  bool tables = true;       // TFs, materials, bindings, selectors, lights, camera ray limits
  bool environment = true;  // the environment map's texels and distributions
};

// How many times each part was asked for.
struct SceneUploadCounts {
  int voxels = 0, summaries = 0, majorants = 0, tables = 0, environment = 0;
};

class SceneUploadPlanner {
 public:
  // What of `view`, just built by `scene`, differs from the copy made at the
  // last Plan (everything the first time): voxels and grid by `scene`'s
  // build stamps and the buffers' addresses, tables by their bytes,
  // the environment by its texels' address.
  SceneUploads Plan(const Scene& scene, const SceneView& view);
  // The copy is gone or unknown (a failed upload): the next Plan asks for everything.
  void Forget() { planned_ = false; }
  const SceneUploadCounts& Counts() const { return counts_; }

 private:
  bool planned_ = false;
  Scene::BuildStamps stamps_;
  std::vector<std::pair<const void*, size_t>> voxelBuffers_;
  size_t majorantBytes_ = 0;
  std::vector<uint8_t> tableBytes_;
  std::pair<const void*, size_t> environment_{nullptr, 0};
  SceneUploadCounts counts_;
};

}  // namespace mmrtm
