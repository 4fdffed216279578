// mmrtm-bench-simd-camera-paths: the camera stage of a sample (the camera
// ray of every pixel sample delta-tracked to its first real collision, with
// the classification there), scalar (CameraSample + DeltaTrack, as
// RenderPixelSample runs it) against the SIMD lanes
// (cpu/wavefront_camera_paths.h) on each instruction set this machine runs,
// in one process, on the head CT with the ct-bone preset (a plain scene).
//
// Prints, per mode, the best of `--rounds` rounds as nanoseconds a path and
// as the ratio to the scalar round of the same process, and for the lanes
// their occupancy (the walk's actions and the lookups) and the walk's
// actions and refills per path. Every mode's free paths must be the scalar
// ones to the bit (checked: the benchmark fails otherwise).
//
// For instruction counts, one mode under
//   valgrind --tool=callgrind --toggle-collect='*RunLanes*' --toggle-collect='*RunScalar*' \
//     mmrtm-bench-simd-camera-paths --only MODE --rounds 1
// (AVX2 at best: Valgrind has no AVX-512).
//
//   mmrtm-bench-simd-camera-paths [VOLUME] [--size N] [--spp N] [--rounds N] [--only scalar|AVX3|AVX2|...]
//                                 [--accelerator octree|macrocell]
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "mmrtm/integrator.h"
#include "plain_ct_bone_scene.h"
#include "simd_targets.h"
#include "wavefront_camera_paths.h"

namespace {

struct FreePaths {
  std::vector<uint8_t> collided;
  std::vector<float> t, sigma_t;
  bool operator==(const FreePaths& o) const {
    return collided == o.collided && std::memcmp(t.data(), o.t.data(), t.size() * 4) == 0 &&
           std::memcmp(sigma_t.data(), o.sigma_t.data(), sigma_t.size() * 4) == 0;
  }
};

void Record(const mmrtm::FreePathResult& fp, size_t i, FreePaths* out) {
  out->collided[i] = fp.collided;
  out->t[i] = fp.t;
  out->sigma_t[i] = fp.c.sigma_t;
}

// Scalar: each pixel sample's camera ray and free path, as RenderPixelSample.
// RunScalar and RunLanes stay out of line for callgrind's --toggle-collect.
[[gnu::noinline]] void RunScalar(const mmrtm::SceneView& s, int spp, FreePaths* out, mmrtm::TraceCounters* ctr) {
  size_t i = 0;
  for (int y = 0; y < s.camera.height; ++y)
    for (int x = 0; x < s.camera.width; ++x)
      for (int index = 0; index < spp; ++index, ++i) {
        mmrtm::CameraSample cs(s, x, y, (uint32_t)index);
        float first[2];
        cs.FreePathPair(&first[0], &first[1]);
        Record(mmrtm::DeltaTrack(s, cs.ray, cs.tMax, cs.rng, *ctr, cs.sobol ? first : nullptr), i, out);
      }
}

// Lanes: the same samples in batches of a tile's size, as WavefrontTile.
[[gnu::noinline]] void RunLanes(const mmrtm::SceneView& s, int spp, FreePaths* out, mmrtm::TraceCounters* ctr,
                                mmrtm::LaneCounters* lanes) {
  mmrtm::WavefrontCameraPaths tracker;
  std::vector<mmrtm::PixelSampleId> samples;
  std::vector<mmrtm::CameraPath> paths;
  samples.reserve(1024);
  paths.reserve(1024);
  size_t first = 0;
  auto finish = [&] {
    tracker.Track(s, samples, paths, lanes);
    for (size_t k = 0; k < paths.size(); ++k) {
      Record(paths[k].freePath, first + k, out);
      *ctr += paths[k].ctr;
    }
    first += paths.size();
    samples.clear();
  };
  for (int y = 0; y < s.camera.height; ++y)
    for (int x = 0; x < s.camera.width; ++x)
      for (int index = 0; index < spp; ++index) {
        if (samples.size() == 1024) finish();
        samples.push_back({x, y, (uint32_t)index});
      }
  finish();
}

}  // namespace

int main(int argc, char** argv) {
  std::string volume = std::string(MMRTM_SHARED_DATA_DIR) + "/ct_head_cranium.nrrd", only, accelerator = "octree";
  int size = 256, spp = 4, rounds = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--size" && i + 1 < argc)
      size = std::atoi(argv[++i]);
    else if (a == "--spp" && i + 1 < argc)
      spp = std::atoi(argv[++i]);
    else if (a == "--rounds" && i + 1 < argc)
      rounds = std::atoi(argv[++i]);
    else if (a == "--only" && i + 1 < argc)
      only = argv[++i];
    else if (a == "--accelerator" && i + 1 < argc)
      accelerator = argv[++i];
    else if (a == "--help" || a == "-h") {
      std::printf(
          "mmrtm-bench-simd-camera-paths [VOLUME] [--size N] [--spp N] [--rounds N] [--only MODE] "
          "[--accelerator octree|macrocell]\n");
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "mmrtm-bench-simd-camera-paths: unknown option %s\n", a.c_str());
      return 2;
    } else
      volume = a;
  }
  try {
    if (accelerator != "octree" && accelerator != "macrocell") {
      std::fprintf(stderr, "mmrtm-bench-simd-camera-paths: --accelerator is octree or macrocell, not %s\n",
                   accelerator.c_str());
      return 2;
    }
    mmrtm::Scene scene = PlainCtBoneScene(volume, size, accelerator);
    mmrtm::SceneView view = scene.Build();
    view.camera.width = size;
    view.camera.height = size;
    if (!mmrtm::WavefrontCameraPaths::Runs(view)) {
      std::fprintf(stderr, "mmrtm-bench-simd-camera-paths: the lanes do not run this scene\n");
      return 1;
    }
    const size_t n = (size_t)size * size * spp;
    auto fresh = [&] { return FreePaths{std::vector<uint8_t>(n), std::vector<float>(n), std::vector<float>(n)}; };
    FreePaths reference = fresh();
    mmrtm::TraceCounters reference_ctr;
    auto seconds = [](auto&& run) {
      const auto start = std::chrono::steady_clock::now();
      run();
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    std::vector<mmrtm::SimdTarget> targets = mmrtm::AvailableSimdTargets();
    double best_scalar = 1e30;
    std::vector<double> best(targets.size(), 1e30);
    std::vector<mmrtm::LaneCounters> lanes(targets.size());
    bool same = true;
    for (int round = 0; round < rounds; ++round) {
      if (only.empty() || only == "scalar") {
        FreePaths out = fresh();
        mmrtm::TraceCounters ctr;
        best_scalar = std::min(best_scalar, seconds([&] { RunScalar(view, spp, &out, &ctr); }));
        reference = out;
        reference_ctr = ctr;
      }
      for (size_t k = 0; k < targets.size(); ++k) {
        if (!only.empty() && only != targets[k].name) continue;
        mmrtm::ForceSimdTarget(targets[k].bits);
        FreePaths out = fresh();
        mmrtm::TraceCounters ctr;
        mmrtm::LaneCounters counted;
        best[k] = std::min(best[k], seconds([&] { RunLanes(view, spp, &out, &ctr, &counted); }));
        if (round == 0) lanes[k] = counted;
        if (only.empty() && !(out == reference)) {
          std::fprintf(stderr, "%s: the lanes' free paths differ from the scalar ones\n", targets[k].name.c_str());
          same = false;
        }
      }
      mmrtm::ForceSimdTarget(0);
    }
    std::printf("{\"accelerator\": \"%s\", \"paths\": %zu, \"lookups_per_path\": %.3f, \"segments_per_path\": %.3f,\n",
                accelerator.c_str(), n, (double)reference_ctr.densityLookups / n,
                (double)reference_ctr.majorantSegments / n);
    const bool scalar_ran = best_scalar < 1e30;  // not with --only a target
    std::printf(" \"scalar_ns_per_path\": %.1f,\n \"lanes\": [\n", scalar_ran ? best_scalar * 1e9 / n : 0.0);
    for (size_t k = 0; k < targets.size(); ++k) {
      if (best[k] >= 1e30) continue;
      const mmrtm::LaneCounters& c = lanes[k];
      std::printf(
          "  {\"target\": \"%s\", \"lanes\": %llu, \"ns_per_path\": %.1f, \"speedup\": %.2f, "
          "\"walk_occupancy\": %.3f, \"lookup_occupancy\": %.3f, \"actions_per_path\": %.2f, "
          "\"refills_per_path\": %.3f}%s\n",
          targets[k].name.c_str(), (unsigned long long)c.lanes, best[k] * 1e9 / n,
          scalar_ran ? best_scalar / best[k] : 0.0, c.WalkOccupancy(), c.LookupOccupancy(), (double)c.actions / n,
          (double)c.refills / n, k + 1 < targets.size() ? "," : "");
    }
    std::printf(" ],\n \"same_bits\": %s}\n", same ? "true" : "false");
    return same ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mmrtm-bench-simd-camera-paths: %s\n", e.what());
    return 1;
  }
}
