// mmrtm-bench-accelerators: the paper's Table 5 on this machine.
//
// For each dataset and accelerator (none, macrocell, octree at two leaf
// levels, octree-voxelmax, and the voxel-exact ideal: one majorant per voxel
// cell) it measures
//   - the summary build after a data load, the refit after a TF change,
//     and a Build with nothing changed (what every render after a camera
//     move pays: no refit, so the same with and without an accelerator);
//   - the time to locate the nearest and the farthest non-empty point along
//     the camera rays (walking the majorant segments);
//   - global illumination at N spp (default 10) at W x W (default 512);
//   - density lookups per real collision in that render, and its mean image
//     difference against the render without accelerator (which must agree
//     within noise: the accelerators only change the speed).
// It prints a table and writes JSON. Times are wall-clock seconds on this
// machine, measured in one process, so ratios against "none" are the
// figures to compare.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "cpu_renderer.h"
#include "mmrtmVolumeLoader.h"
#include "scene_json.h"

using namespace mmrtm;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

double Seconds(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Dataset {
  std::string name, file;
  std::string scene;  // a preset name or a scene file under Data/benchmarks
  int resample = 0;   // > 0: resample trilinearly to this many voxels per axis
};

struct Config {
  std::string name;
  MajorantKind kind;
  SummaryMode summary = SummaryMode::CellRanges;
  int leafLevelOffset = 0;  // relative to the automatic leaf level
  bool ideal = false;       // one majorant per voxel cell, no margin
};

// Trilinear resampling of a volume onto n^3 voxels over the same world box.
HostVolume Resample(const HostVolume& in, int n) {
  HostVolume out;
  out.name = in.name;
  out.source = in.source + " resampled to " + std::to_string(n) + "^3";
  out.type = in.type;
  out.dims = {n, n, n};
  out.voxels.resize((size_t)n * n * n * VoxelTypeSize(in.type));
  uint8_t* bytes = out.voxels.MutableData();
  const VolumeView v = in.View();
  Affine3 scale;  // new index -> old index
  for (int a = 0; a < 3; ++a) scale.m[a][a] = (float)(in.dims[a] - 1) / (float)(n - 1);
  out.indexToWorld = AffineCompose(in.indexToWorld, scale);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const float value = v.SampleIndex(scale.ApplyPoint({(float)x, (float)y, (float)z}));
        const size_t i = x + (size_t)n * (y + (size_t)n * z);
        if (in.type == VoxelType::Int16)
          reinterpret_cast<int16_t*>(bytes)[i] = (int16_t)std::lround(value);
        else if (in.type == VoxelType::UInt16)
          reinterpret_cast<uint16_t*>(bytes)[i] = (uint16_t)std::lround(value);
        else if (in.type == VoxelType::UInt8)
          bytes[i] = (uint8_t)std::lround(value);
        else
          reinterpret_cast<float*>(bytes)[i] = value;
      }
  return out;
}

json SceneDocument(const std::string& dataDir, const std::string& scene) {
  const std::string benchmark = dataDir + "/benchmarks/" + scene + ".json";
  std::ifstream probe(benchmark);
  return ReadJsonFile(probe ? benchmark : PresetPath(dataDir + "/presets", scene));
}

// The TF edit of the refit measurement: every density CCTF's points move by
// a tenth of their span (a user dragging the TF).
void ShiftDensityTFs(Scene& scene, float direction) {
  for (MaterialDesc& m : scene.materials)
    for (const MaterialDesc::Binding& b : m.bindings) {
      TransferFunctionDesc& tf = scene.tfs[b.tf];
      if (b.quantity != Quantity::Density || tf.type != TFType::CCTF) continue;
      const float shift = direction * 0.1f * (tf.keys.back() - tf.keys.front() + 1.f);
      for (float& k : tf.keys) k += shift;
    }
}

struct Result {
  std::string dataset, config;
  double build = 0, refit = 0, unchanged = 0, locate = 0, render = 0;
  double lookupsPerReal = 0, meanZ2 = 0;
  int leafLevel = -1;
  int64_t nodes = 0;
  uint64_t violations = 0;
};

// Nearest and farthest non-empty point along every camera ray (pixel
// centres): the majorant segments say where the volume may be non-empty; the
// first (last) of them is searched in steps of half the smallest voxel
// spacing for the first (last) point with sigma_t > 0. With no accelerator
// the one segment is the whole box, so the whole ray is searched.
double Locate(const SceneView& s, int width, float step) {
  CameraView cam = s.camera;
  cam.width = cam.height = width;
  auto nonEmpty = [&](const Ray& ray, float t) { return s.classifier.Classify(ray(t)).sigma_t > 0.f; };
  const auto start = Clock::now();
  double checksum = 0;
  for (int y = 0; y < width; ++y)
    for (int x = 0; x < width; ++x) {
      Ray ray = cam.GenerateRay(x + 0.5f, y + 0.5f, 0.5f, 0.5f);
      Ray indexRay;
      float t0, t1;
      if (!s.DomainInterval(ray, kInfinity, &indexRay, &t0, &t1)) continue;
      MajorantIterator it = s.majorants.Begin(indexRay, t0, t1, 1.f);
      RayMajorantSegment seg;
      float nearest = -1.f, farthest = -1.f;
      std::vector<RayMajorantSegment> segments;
      while (it.Next(&seg))
        if (seg.sigma_maj > 0.f) segments.push_back(seg);
      for (size_t i = 0; i < segments.size() && nearest < 0.f; ++i)
        for (float t = segments[i].tMin; t <= segments[i].tMax && nearest < 0.f; t += step)
          if (nonEmpty(ray, t)) nearest = t;
      for (size_t i = segments.size(); i-- > 0 && farthest < 0.f && nearest >= 0.f;)
        for (float t = segments[i].tMax; t >= segments[i].tMin && farthest < 0.f; t -= step)
          if (nonEmpty(ray, t)) farthest = t;
      checksum += nearest + farthest;
    }
  const double seconds = Seconds(start);
  if (checksum == 1234.5) std::printf(" ");  // keep the loop from being optimised away
  return seconds;
}

}  // namespace

int main(int argc, char** argv) {
  std::string dataDir = MMRTM_DATA_DIR, sharedDir = MMRTM_SHARED_DATA_DIR, jsonOut = "bench-accelerators.json";
  int width = 512, spp = 10, threads = 0;
  bool withIdeal = true, quick = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto next = [&]() { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (a == "--json")
      jsonOut = next();
    else if (a == "--width")
      width = std::atoi(next().c_str());
    else if (a == "--spp")
      spp = std::atoi(next().c_str());
    else if (a == "--threads")
      threads = std::atoi(next().c_str());
    else if (a == "--shared-data")
      sharedDir = next();
    else if (a == "--no-ideal")
      withIdeal = false;
    else if (a == "--quick")
      quick = true;
    else {
      std::printf(
          "usage: mmrtm-bench-accelerators [--width W (512)] [--spp N (10)] [--threads T (all)] [--json FILE]\n"
          "                                [--shared-data DIR] [--no-ideal] [--quick]\n"
          "--quick: small datasets only, 128 x 128, 4 spp (a smoke run)\n");
      return a == "--help" ? 0 : 2;
    }
  }
  if (quick) {
    width = 128;
    spp = 4;
  }
  std::vector<Dataset> datasets = {
      {"bonsai", sharedDir + "/bonsai.nii.gz", "bonsai"},
      {"ct_head_cranium", sharedDir + "/ct_head_cranium.nrrd", "ct-bone"},
      {"ct_chest_dicom", sharedDir + "/ct_chest_dicom", "ct-bone"},
      {"ct_head_cranium_512", sharedDir + "/ct_head_cranium.nrrd", "ct-bone", 512},
  };
  if (quick) datasets.resize(2);
  std::vector<Config> configs = {{"none", MajorantKind::Global},
                                 {"macrocell", MajorantKind::Macrocell},
                                 {"octree", MajorantKind::Octree},
                                 {"octree-finer", MajorantKind::Octree, SummaryMode::CellRanges, +1},
                                 {"octree-voxelmax", MajorantKind::Octree, SummaryMode::VoxelValues}};
  if (withIdeal) configs.push_back({"ideal (voxel-exact)", MajorantKind::Macrocell, SummaryMode::CellRanges, 0, true});

  std::vector<Result> results;
  std::printf("%-20s %-20s %5s %9s %9s %9s %9s %9s %8s %8s %7s\n", "dataset", "accelerator", "leaf", "build ms",
              "refit ms", "same us", "locate ms", "GI s", "GI x", "look/real", "z^2");
  for (const Dataset& d : datasets) {
    HostVolume volume = LoadVolume(d.file, "scalars");
    if (d.resample > 0) volume = Resample(volume, d.resample);
    json doc = SceneDocument(dataDir, d.scene);
    doc["render"].merge_patch({{"width", width}, {"height", width}, {"spp", spp}, {"threads", threads}});
    SceneInputs inputs;
    inputs.volumes["scalars"] = std::move(volume);
    Scene base = SceneFromJson(doc, std::move(inputs));
    int autoLeaf = -1;
    double noneRender = 0;
    Film noneFilm(width, width);
    for (const Config& c : configs) {
      Scene& scene = base;
      AcceleratorSettings& acc = scene.render.accelerator;
      acc.kind = c.kind;
      acc.grid = MajorantGridOptions{};
      acc.grid.summary = c.summary;
      acc.grid.threads = threads;
      if (c.leafLevelOffset != 0) acc.grid.leafLevel = autoLeaf + c.leafLevelOffset;
      if (c.ideal) {
        // Leaves one voxel cell wide, without margin.
        int maxCells = 1;
        for (int a = 0; a < 3; ++a) maxCells = std::max(maxCells, scene.proxies[0].dims[a] - 1);
        acc.grid.leafLevel = (int)std::ceil(std::log2((double)maxCells));
        acc.grid.margin = 0;
      }
      scene.MarkDataModified();
      Result r;
      r.dataset = d.name;
      r.config = c.name;
      SceneView view = scene.Build();
      if (scene.Grid()) {
        r.build = scene.Grid()->LastBuildSeconds();
        r.leafLevel = scene.Grid()->LeafLevel();
        r.nodes = scene.Grid()->NodeCount();
      }
      if (scene.Grid() && !c.ideal) {
        if (c.name == "octree") autoLeaf = r.leafLevel;
        // Refit after TF edits: the median of 5.
        std::vector<double> refits;
        for (int i = 0; i < 5; ++i) {
          ShiftDensityTFs(scene, i % 2 ? -1.f : 1.f);
          scene.Build();
          refits.push_back(scene.Grid()->LastRefitSeconds());
        }
        if (refits.size() % 2) ShiftDensityTFs(scene, -1.f);  // back to the preset's TF
        view = scene.Build();
        std::sort(refits.begin(), refits.end());
        r.refit = refits[refits.size() / 2];
      }
      // A Build with nothing changed: the median of 5.
      std::vector<double> unchanged;
      for (int i = 0; i < 5; ++i) {
        const auto start = Clock::now();
        view = scene.Build();
        unchanged.push_back(Seconds(start));
      }
      std::sort(unchanged.begin(), unchanged.end());
      r.unchanged = unchanged[unchanged.size() / 2];
      float minSpacing = kInfinity;
      for (int a = 0; a < 3; ++a)
        minSpacing = std::min(minSpacing,
                              Length(Vec3{scene.proxies[0].indexToWorld.m[0][a], scene.proxies[0].indexToWorld.m[1][a],
                                          scene.proxies[0].indexToWorld.m[2][a]}));
      r.locate = Locate(view, width, 0.5f * minSpacing);
      Film film(width, width);
      TraceCounters ctr;
      const auto start = Clock::now();
      CpuRenderer(threads).Render(view, film, spp, &ctr);
      r.render = Seconds(start);
      r.lookupsPerReal = ctr.realCollisions ? (double)ctr.densityLookups / ctr.realCollisions : 0.0;
      r.violations = ctr.majorantViolations;
      if (c.kind == MajorantKind::Global) {
        noneRender = r.render;
        noneFilm = film;
      }
      r.meanZ2 = MeanSquaredZScore(noneFilm, film);
      results.push_back(r);
      std::printf("%-20s %-20s %5d %9.2f %9.2f %9.2f %9.1f %9.2f %8.2f %8.2f %7.3f%s\n", d.name.c_str(), c.name.c_str(),
                  r.leafLevel, r.build * 1e3, r.refit * 1e3, r.unchanged * 1e6, r.locate * 1e3, r.render,
                  noneRender / r.render, r.lookupsPerReal, r.meanZ2, r.violations ? "  (majorant violations!)" : "");
      std::fflush(stdout);
    }
  }

  json out = json::array();
  for (const Result& r : results)
    out.push_back({{"dataset", r.dataset},
                   {"accelerator", r.config},
                   {"leaf_level", r.leafLevel},
                   {"nodes", r.nodes},
                   {"build_seconds", r.build},
                   {"refit_seconds", r.refit},
                   {"unchanged_build_seconds", r.unchanged},
                   {"locate_seconds", r.locate},
                   {"gi_seconds", r.render},
                   {"lookups_per_real_collision", r.lookupsPerReal},
                   {"mean_z2_vs_none", r.meanZ2},
                   {"majorant_violations", r.violations}});
  std::ofstream(jsonOut) << json({{"width", width}, {"spp", spp}, {"results", out}}).dump(2) << "\n";
  std::printf("wrote %s\n", jsonOut.c_str());
  return 0;
}
