// mmrtm-bench-plain-scene: what the multi-material machinery (material TFs,
// several proxies, the additive merge) costs a scene that uses none of it.
// Since the classifier takes a plain scene's shortest path at run time
// (Classifier::plain), what remains is one branch per lookup.
//
// This file is compiled twice (Testing/Benchmarks/CMakeLists.txt): against
// the CPU renderer as shipped (mmrtm-bench-plain-scene) and against a copy
// compiled with MMRTM_PLAIN_SCENE_ONLY (mmrtm-bench-plain-scene-shortest),
// whose classifier hard-wires one proxy, one material and one density TF.
// Both render the same plain scene (a CT with the one-material ct-bone
// preset) and print the render time and a checksum of the image as JSON;
// Testing/Accuracy/plain_scene_overhead.py runs them in turn and reports the
// ratio. The images must be identical: the two paths compute the same thing.
//
//   mmrtm-bench-plain-scene [VOLUME] [--size N] [--spp N]
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>

#include "cpu_renderer.h"
#include "film.h"
#include "mmrtmVolumeLoader.h"
#include "plain_ct_bone_scene.h"
#include "scene_json.h"

int main(int argc, char** argv) {
  std::string volume = std::string(MMRTM_SHARED_DATA_DIR) + "/ct_head_cranium.nrrd";
  int size = 256, spp = 16;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--size") && i + 1 < argc)
      size = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--spp") && i + 1 < argc)
      spp = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      std::printf("mmrtm-bench-plain-scene [VOLUME] [--size N] [--spp N]\n");
      return 0;
    } else if (argv[i][0] == '-') {
      std::fprintf(stderr, "mmrtm-bench-plain-scene: unknown option %s\n", argv[i]);
      return 2;
    } else
      volume = argv[i];
  }
  try {
    mmrtm::Scene scene = PlainCtBoneScene(volume, size);
    mmrtm::SceneView view = scene.Build();
    if (!view.classifier.plain) {
      std::fprintf(stderr, "mmrtm-bench-plain-scene: the scene is not plain (one proxy, material and density TF)\n");
      return 1;
    }
    mmrtm::Film film(size, size);
    mmrtm::TraceCounters counters;
    const auto start = std::chrono::steady_clock::now();
    mmrtm::CpuRenderer().Render(view, film, spp, &counters);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    uint64_t checksum = 1469598103934665603ull;  // FNV-1a over the mean image's bits
    for (const mmrtm::RGB& p : film.Linear().pixels)
      for (float c : {p.r, p.g, p.b}) {
        uint32_t bits;
        std::memcpy(&bits, &c, 4);
        checksum = (checksum ^ bits) * 1099511628211ull;
      }
#ifdef MMRTM_PLAIN_SCENE_ONLY
    const char* build = "shortest path";
#else
    const char* build = "general";
#endif
    std::printf("{\"build\": \"%s\", \"seconds\": %.4f, \"density_lookups\": %llu, \"checksum\": \"%016llx\"}\n", build,
                seconds, (unsigned long long)counters.densityLookups, (unsigned long long)checksum);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mmrtm-bench-plain-scene: %s\n", e.what());
    return 1;
  }
  return 0;
}
