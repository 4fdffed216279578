// mmrtm-bench-simd-lookups: density lookups and TF (a plain scene's
// extinction) per second, one at a time through Classifier::Classify against
// the SIMD lanes of cuda/simd on each instruction set this machine runs.
//
// The index points are where delta tracking looks up (the tentative
// collisions of the camera rays of the preset's view, up to each ray's first
// real collision), on the head CT with the ct-bone preset, in two orders:
//   coherent: row by row, the k-th lookup of each path of the row, then the
//             (k+1)-th: neighbouring paths in neighbouring lanes;
//   random:   the same points shuffled: lanes of unrelated paths.
// It also prints the lane occupancy that packets of 4, 8 and 16
// neighbouring camera paths would have without regrouping.
// Every mode runs on the same points in turns, `--rounds` times; the best
// round of each is reported, as points per second and as the ratio to the
// scalar path of the same process (the machine is shared: absolute times
// move, ratios less). The outputs of all modes must be the same bits.
//
// For instruction counts, one mode on one point set, run under
//   valgrind --tool=callgrind --toggle-collect='mmrtm::PlainExtinction*' \
//     mmrtm-bench-simd-lookups --only MODE --set SET --rounds 1
// (with --only the scalar reference is not computed, so what is counted is
// the one mode's pass; Valgrind has no AVX-512: under it the best target is
// AVX2).
//
//   mmrtm-bench-simd-lookups [VOLUME] [--size N] [--points N] [--rounds N]
//                            [--only scalar|AVX3|AVX2|SSE4|...] [--set coherent|random]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "mmrtm/tracking.h"
#include "mmrtmVolumeLoader.h"
#include "plain_ct_bone_scene.h"
#include "plain_extinction.h"
#include "scene_json.h"
#include "simd_targets.h"

namespace {

struct PointSet {
  std::string name;
  std::vector<float> x, y, z;
};

// Per camera ray: the index points of its tentative collisions, as delta
// tracking takes them (mmrtm/tracking.h, up to the first real collision),
// and its majorant segments.
struct CameraPaths {
  int width = 0, height = 0;
  std::vector<std::vector<mmrtm::Vec3>> lookups;  // per pixel, row by row
  std::vector<uint64_t> segments;
};

CameraPaths TrackCameraRays(const mmrtm::SceneView& view) {
  CameraPaths paths;
  paths.width = view.camera.width;
  paths.height = view.camera.height;
  const int n = paths.width * paths.height;
  paths.lookups.resize(n);
  paths.segments.resize(n);
  for (int pixel = 0; pixel < n; ++pixel) {
    const int col = pixel % paths.width, row = pixel / paths.width;
    const mmrtm::Ray world = view.camera.GenerateRay(col + 0.5f, row + 0.5f, 0.5f, 0.5f);
    mmrtm::Ray indexRay;
    float t0, t1;
    if (!view.DomainInterval(world, mmrtm::kInfinity, &indexRay, &t0, &t1)) continue;
    mmrtm::PCG32 rng(pixel, 7);
    mmrtm::TraceCounters counters;
    std::vector<mmrtm::Vec3>& points = paths.lookups[pixel];
    mmrtm::SampleTentativeCollisions(
        view, world, mmrtm::kInfinity, 1.f, rng, counters,
        [&](float t, const mmrtm::Classification& c, float sigma_maj) {
          points.push_back(indexRay(t));
          return rng.Uniform() >= c.sigma_t / sigma_maj;  // a null collision: go on
        },
        [](const mmrtm::RayMajorantSegment&) { return true; });
    paths.segments[pixel] = counters.majorantSegments;
  }
  return paths;
}

// The lookups of all paths in the order lanes of neighbouring paths would
// take them: row by row, the k-th lookup of every path of the row that has
// one, then the (k+1)-th (a queue refilled from the same tile).
PointSet CoherentPoints(const CameraPaths& paths, size_t limit) {
  PointSet p{"coherent", {}, {}, {}};
  for (int row = 0; row < paths.height && p.x.size() < limit; ++row)
    for (size_t k = 0;; ++k) {
      bool any = false;
      for (int col = 0; col < paths.width; ++col) {
        const std::vector<mmrtm::Vec3>& points = paths.lookups[row * paths.width + col];
        if (k >= points.size()) continue;
        any = true;
        p.x.push_back(points[k].x);
        p.y.push_back(points[k].y);
        p.z.push_back(points[k].z);
      }
      if (!any) break;
    }
  return p;
}

// The same points shuffled: lanes of unrelated paths.
PointSet ShuffledPoints(PointSet p) {
  p.name = "random";
  std::mt19937 rng(1);
  for (size_t i = p.x.size(); i > 1; --i) {
    const size_t j = std::uniform_int_distribution<size_t>(0, i - 1)(rng);
    std::swap(p.x[i - 1], p.x[j]);
    std::swap(p.y[i - 1], p.y[j]);
    std::swap(p.z[i - 1], p.z[j]);
  }
  return p;
}

// Lane occupancy of packets of `lanes` neighbouring pixels in a row (a lane
// per path, no regrouping): a packet steps until its longest path ends, so
// its occupancy is its lookups over lanes x its longest path's lookups.
// The same for majorant segments.
void PrintOccupancy(const CameraPaths& paths, int lanes) {
  double lookups = 0, lookupSlots = 0, segments = 0, segmentSlots = 0;
  for (int row = 0; row < paths.height; ++row)
    for (int col0 = 0; col0 < paths.width; col0 += lanes) {
      size_t longest = 0;
      uint64_t mostSegments = 0;
      for (int col = col0; col < std::min(col0 + lanes, paths.width); ++col) {
        const int pixel = row * paths.width + col;
        lookups += paths.lookups[pixel].size();
        segments += paths.segments[pixel];
        longest = std::max(longest, paths.lookups[pixel].size());
        mostSegments = std::max(mostSegments, paths.segments[pixel]);
      }
      lookupSlots += (double)lanes * longest;
      segmentSlots += (double)lanes * mostSegments;
    }
  std::printf("  {\"packet_lanes\": %d, \"lookup_occupancy\": %.3f, \"segment_occupancy\": %.3f}", lanes,
              lookups / std::max(lookupSlots, 1.0), segments / std::max(segmentSlots, 1.0));
}

struct Mode {
  std::string name;
  int64_t target = 0;  // 0: the scalar path
};

}  // namespace

int main(int argc, char** argv) {
  std::string volume = std::string(MMRTM_SHARED_DATA_DIR) + "/ct_head_cranium.nrrd";
  int size = 256, rounds = 5;
  size_t points = 2000000;
  std::string only, onlySet;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--size") && i + 1 < argc)
      size = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--points") && i + 1 < argc)
      points = (size_t)std::atoll(argv[++i]);
    else if (!std::strcmp(argv[i], "--rounds") && i + 1 < argc)
      rounds = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--only") && i + 1 < argc)
      only = argv[++i];
    else if (!std::strcmp(argv[i], "--set") && i + 1 < argc)
      onlySet = argv[++i];
    else if (!std::strcmp(argv[i], "--help")) {
      std::printf(
          "usage: mmrtm-bench-simd-lookups [VOLUME] [--size N] [--points N] [--rounds N] [--only MODE] [--set SET]\n"
          "  VOLUME      default: the head CT (ct_head_cranium.nrrd of the shared data)\n"
          "  --size N    camera image of N x N pixels whose rays are tracked (default 256)\n"
          "  --points N  points per set, at most (default 2000000)\n"
          "  --rounds N  turns of every mode (default 5); the best is reported\n"
          "  --only M    one mode: scalar or a target name (AVX3, AVX2, SSE4, ...)\n"
          "  --set S     one point set: coherent or random\n");
      return 0;
    } else
      volume = argv[i];
  }
  try {
    mmrtm::Scene scene = PlainCtBoneScene(volume, size);
    mmrtm::SceneView view = scene.Build();
    if (!view.classifier.plain) {
      std::fprintf(stderr, "mmrtm-bench-simd-lookups: the scene is not plain\n");
      return 1;
    }
    const CameraPaths paths = TrackCameraRays(view);
    std::vector<PointSet> sets;
    PointSet coherent = CoherentPoints(paths, points);
    if (onlySet.empty() || onlySet == "random") sets.push_back(ShuffledPoints(coherent));
    if (onlySet.empty() || onlySet == "coherent") sets.insert(sets.begin(), std::move(coherent));

    std::vector<Mode> modes{{"scalar", 0}};
    for (const mmrtm::SimdTarget& t : mmrtm::AvailableSimdTargets())
      if (t.name != "SCALAR" && t.name != "EMU128") modes.push_back({t.name, t.bits});  // Highway's one-lane targets
    if (!only.empty())
      modes.erase(std::remove_if(modes.begin(), modes.end(), [&](const Mode& m) { return m.name != only; }),
                  modes.end());
    if (modes.empty()) {
      std::fprintf(stderr, "mmrtm-bench-simd-lookups: no mode %s on this machine\n", only.c_str());
      return 1;
    }

    uint64_t pathsInVolume = 0, lookups = 0, segments = 0;
    for (size_t i = 0; i < paths.lookups.size(); ++i) {
      pathsInVolume += paths.segments[i] > 0;
      lookups += paths.lookups[i].size();
      segments += paths.segments[i];
    }
    std::printf(
        "{\"volume\": \"%s\", \"camera_paths\": %llu, \"lookups_per_path\": %.2f, "
        "\"segments_per_path\": %.2f, \"occupancy\": [\n",
        volume.c_str(), (unsigned long long)pathsInVolume, (double)lookups / std::max<uint64_t>(pathsInVolume, 1),
        (double)segments / std::max<uint64_t>(pathsInVolume, 1));
    for (int lanes : {4, 8, 16}) {
      PrintOccupancy(paths, lanes);
      std::printf(lanes == 16 ? "\n" : ",\n");
    }
    std::printf("], \"results\": [\n");
    bool firstLine = true, same = true;
    for (const PointSet& set : sets) {
      const size_t n = set.x.size();
      std::vector<float> reference(n), out(n);
      // (With --only, no reference: under callgrind the one mode's calls are all that is counted.)
      if (only.empty())
        mmrtm::PlainExtinctionScalar(view.classifier, set.x.data(), set.y.data(), set.z.data(), n, reference.data());
      std::vector<double> best(modes.size(), 1e30);
      for (int r = 0; r < rounds; ++r)
        for (size_t m = 0; m < modes.size(); ++m) {
          const auto start = std::chrono::steady_clock::now();
          if (modes[m].target == 0) {
            mmrtm::PlainExtinctionScalar(view.classifier, set.x.data(), set.y.data(), set.z.data(), n, out.data());
          } else {
            mmrtm::ForceSimdTarget(modes[m].target);
            mmrtm::PlainExtinctionSimd(view.classifier, set.x.data(), set.y.data(), set.z.data(), n, out.data());
          }
          best[m] = std::min(best[m], std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
          same = same && (!only.empty() || std::memcmp(out.data(), reference.data(), n * sizeof(float)) == 0);
        }
      mmrtm::ForceSimdTarget(0);
      size_t nonzero = 0;
      for (float s : out) nonzero += s > 0.f;
      for (size_t m = 0; m < modes.size(); ++m) {
        std::printf(
            "%s  {\"points\": \"%s\", \"count\": %zu, \"nonzero\": %.3f, \"mode\": \"%s\", \"seconds\": %.5f, "
            "\"per_second\": %.4g, \"speedup_over_scalar\": %.3f}",
            firstLine ? "" : ",\n", set.name.c_str(), n, (double)nonzero / n, modes[m].name.c_str(), best[m],
            n / best[m], best[0] / best[m]);
        firstLine = false;
      }
    }
    std::printf("\n], \"same_bits_as_scalar\": %s}\n", same ? "true" : "false");
    return same ? 0 : 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mmrtm-bench-simd-lookups: %s\n", e.what());
    return 1;
  }
}
