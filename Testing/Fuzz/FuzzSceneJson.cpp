// libFuzzer target: the JSON scene format (ReadJsonFile + SceneFromJson,
// cuda/host/scene_json.cpp), the one parser behind mmrtm-render --scene,
// presets, vtkMultiMaterialProperty and the viewer's scenes. The volumes a
// scene names are small synthetic ones (the file readers have targets of
// their own). A scene that parses is built and rendered at 8 x 6 pixels,
// one sample, on one thread.
//
// Findings: anything but a scene or an InputError; a scene whose settings
// the parser should have refused (sizes, counts); a built scene with a
// non-finite majorant; a pixel that is not finite.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "FuzzScratch.h"
#include "cpu_renderer.h"
#include "film.h"
#include "label_materials.h"
#include "scene_json.h"

namespace {

// A 6 x 6 x 6 uint16 volume, values 0 to 3000 (Hounsfield-like ramps and,
// mod 8, label ids), unit spacing: whatever name and file the scene asks for.
mmrtm::HostVolume SyntheticVolume(const std::string& path, const std::string& name, mmrtm::Interpolation interp) {
  mmrtm::HostVolume v;
  v.name = name;
  v.source = path;
  v.interpolation = interp;
  v.type = mmrtm::VoxelType::UInt16;
  v.dims = {6, 6, 6};
  v.voxels.resize(6 * 6 * 6 * sizeof(uint16_t));
  auto* p = reinterpret_cast<uint16_t*>(v.voxels.MutableData());
  for (int i = 0; i < 216; ++i) p[i] = uint16_t(path.find("label") != std::string::npos ? i % 8 : i * 14);
  v.indexToWorld = mmrtm::IndexToWorld({0, 0, 0}, {1, 1, 1}, {1, 0, 0, 0, 1, 0, 0, 0, 1});
  return v;
}

void Require(bool condition) {
  if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mmrtm::fuzz::WriteScratchFile("scene.json", data, size);
  try {
    mmrtm::SceneInputs inputs;
    inputs.loadVolume = SyntheticVolume;
    inputs.baseDirectory = mmrtm::fuzz::ScratchFolder();
    // As mmrtm-render's INPUT and --labels: presets name these without files.
    inputs.volumes["scalars"] = SyntheticVolume("input.nrrd", "scalars", mmrtm::Interpolation::Trilinear);
    inputs.volumes["labels"] = SyntheticVolume("labels.nrrd", "labels", mmrtm::Interpolation::Nearest);
    mmrtm::ExpandLabelMaterialsOnLoad(inputs);  // as mmrtm-render: the label classes too
    mmrtm::Scene scene = mmrtm::SceneFromJson(mmrtm::ReadJsonFile(path), inputs);
    // Built as mmrtm-render builds it (one grid thread): Build validates the
    // settings (spp 0 is refused there, not by the parser).
    scene.render.accelerator.grid.threads = 1;
    scene.Build();
    // What the parser and Build promise of the settings they accept.
    const mmrtm::RenderSettings& r = scene.render;
    Require(r.width >= 1 && r.height >= 1 && r.samplesPerPixel >= 1 && r.threads >= 0);
    Require(std::isfinite(r.exposure) && r.integrator.maxBounces >= 0);

    scene.render.width = 8;
    scene.render.height = 6;
    scene.render.threads = 1;
    scene.render.integrator.maxBounces = std::min(scene.render.integrator.maxBounces, 4);
    scene.render.accelerator.grid.threads = 1;
    const mmrtm::SceneView view = scene.Build();
    Require(std::isfinite(view.majorants.globalMajorant) && view.majorants.globalMajorant >= 0);
    mmrtm::Film film(8, 6);
    mmrtm::CpuRenderer(1).Render(view, film, 1);
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 8; ++x) {
        const mmrtm::RGB c = film.Mean(x, y);
        Require(std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]));
      }
    mmrtm::fuzz::Outcome("a scene of " + std::to_string(scene.materials.size()) + " material(s), rendered");
  } catch (const mmrtm::InputError& e) {
    mmrtm::fuzz::Outcome(e.what());
  }
  return 0;
}
