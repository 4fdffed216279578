// mmrtm-bench-failure-cases: the curves behind the failure-case charts of
// Documentation/accuracy.md, as JSON on stdout (Testing/Accuracy/failure_charts.py
// draws them). The scenes are those of TestFailureCases (FailureCaseScenes.h);
// the tests assert, this program measures over a range of each parameter.
//
//   mmrtm-bench-failure-cases > failure_cases.json     # about a minute on 2 cores
#include <cstdio>
#include <string>
#include <vector>

#include "FailureCaseScenes.h"
#include <nlohmann/json.hpp>

using namespace mmrtm;
using failure::Estimate;
using failure::Method;
using nlohmann::json;

namespace {

json Row(const Estimate& e, double exact) {
  return {{"T", e.mean},
          {"se", e.standardError},
          {"exact", exact},
          {"lookups_per_ray", e.lookupsPerRay},
          {"violations", e.violations}};
}

using failure::Measure;

const char* Name(MajorantKind k) {
  return k == MajorantKind::Global ? "none" : k == MajorantKind::Macrocell ? "macrocell" : "octree";
}

json NarrowPeak() {
  json out = json::object();
  for (float step : {2.f, 1.f, 0.5f, 0.25f, 0.1f, 0.05f, 0.02f}) {
    failure::Case c = failure::NarrowPeak(0.1f, 8.f, MajorantKind::Octree, SummaryMode::CellRanges, step);
    json row = Row(Measure(c, Method::RayMarching, 20000), c.exact);
    row["step"] = step;
    out["ray_marching"].push_back(row);
  }
  failure::Case d = failure::NarrowPeak(0.1f, 8.f, MajorantKind::Octree, SummaryMode::CellRanges);
  out["delta_octree"] = Row(Measure(d, Method::DeltaTracking, 100000), d.exact);
  out["ratio_octree"] = Row(Measure(d, Method::RatioTracking, 100000), d.exact);
  failure::Case v = failure::NarrowPeak(0.1f, 8.f, MajorantKind::Octree, SummaryMode::VoxelValues);
  out["delta_voxelmax"] = Row(Measure(v, Method::DeltaTracking, 100000), v.exact);
  return out;
}

json Sparse() {
  json out = json::object();
  for (int n : {32, 64, 128, 256})
    for (MajorantKind k : {MajorantKind::Global, MajorantKind::Macrocell, MajorantKind::Octree}) {
      failure::Case c = failure::SparseBlock(n, 1.f, k);
      json row = Row(Measure(c, Method::RatioTracking, 20000), c.exact);
      row["n"] = n;
      out[Name(k)].push_back(row);
    }
  return out;
}

json Dense() {
  json out = json::object();
  for (float density : {1.f, 10.f, 100.f, 1000.f, 10000.f})
    for (int leafLevel : {-1, 4}) {
      failure::PathCost cost = failure::DensePathCost(density, RGB(0.8f), 32, leafLevel);
      out[leafLevel < 0 ? "auto_leaves" : "leaf_level_4"].push_back({{"density", density},
                                                                     {"lookups_per_path", cost.lookupsPerPath},
                                                                     {"real_per_path", cost.realPerPath},
                                                                     {"max_real_per_path", cost.maxRealPerPath}});
    }
  for (int bounces : {1, 2, 4, 8, 16, 32, 64}) {
    failure::PathCost cost = failure::DensePathCost(1e4f, RGB(1.f), bounces);
    out["albedo_one_bounce_limit"].push_back({{"max_bounces", bounces},
                                              {"real_per_path", cost.realPerPath},
                                              {"max_real_per_path", cost.maxRealPerPath},
                                              {"lookups_per_path", cost.lookupsPerPath}});
  }
  return out;
}

json Grazing() {
  json out = json::object();
  for (float dz : {-1.f, -0.5f, -1e-2f, -1e-5f, 0.f, 1e-5f, 1e-2f, 0.5f, 1.f})
    for (MajorantKind k : {MajorantKind::Macrocell, MajorantKind::Octree}) {
      failure::Case c = failure::SliceSheet(16.f + dz, 0.05f, k);
      json row = Row(Measure(c, Method::RatioTracking, 50000), c.exact);
      row["dz"] = dz;
      out[Name(k)].push_back(row);
    }
  return out;
}

json Degenerate() {
  json out = json::object();
  for (MajorantKind k : {MajorantKind::Global, MajorantKind::Macrocell, MajorantKind::Octree}) {
    failure::Case zero = failure::AllZeroTF(k);
    out["all_zero"][Name(k)] = Row(Measure(zero, Method::RatioTracking, 20000), zero.exact);
    failure::Case one = failure::AllOneTF(k);
    out["all_one"][Name(k)] = Row(Measure(one, Method::RatioTracking, 20000), one.exact);
    failure::Case step = failure::SaturatedBlock(0.4f, k);
    out["step_at_maximum"][Name(k)] = Row(Measure(step, Method::RatioTracking, 20000), step.exact);
  }
  return out;
}

}  // namespace

int main() {
  json out;
  std::fprintf(stderr, "narrow TF peak...\n");
  out["narrow_peak"] = NarrowPeak();
  std::fprintf(stderr, "sparse dense block...\n");
  out["sparse_block"] = Sparse();
  std::fprintf(stderr, "dense media...\n");
  out["dense_media"] = Dense();
  std::fprintf(stderr, "grazing rays...\n");
  out["grazing"] = Grazing();
  std::fprintf(stderr, "degenerate TFs...\n");
  out["degenerate_tf"] = Degenerate();
  std::printf("%s\n", out.dump(1).c_str());
  return 0;
}
