// The host-side scene: owning storage for proxies, TFs, materials, lights,
// camera and settings, and the flattening of all of it into the SceneView
// that the backends trace. Host-only set-up code.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "environment_map.h"
#include "host_volume.h"
#include "majorant_grid.h"
#include "mmrtm/scene_view.h"
#include "mmrtm/tonemap.h"

namespace mmrtm {

struct TransferFunctionDesc {
  std::string where;  // e.g. "materials[bone].density.tfs[0]", for messages
  TFType type = TFType::CCTF;
  int proxy = 0;
  int channels = 1;
  std::vector<float> keys;     // see TransferFunctionView for the layout
  std::vector<float> values;   // coefficient TFs
  std::vector<int> materials;  // material TFs
};

struct MaterialDesc {
  std::string name;
  float base[kCoefficientFloats] = {
      1.f,             // density
      1.f,  1.f, 1.f,  // albedo
      0.5f,            // roughness
      0.f,             // metallic
      0.f,             // surface probability
      0.f,  0.f, 0.f,  // emission
      0.f              // anisotropy g
  };
  struct Binding {
    int tf;
    Quantity quantity;
  };
  std::vector<Binding> bindings;  // tf indexes into Scene::tfs
};

struct CameraDesc {
  Projection projection = Projection::Perspective;
  // Auto framing (the default): look at the volume centre from the given
  // azimuth and elevation (degrees) about the world z axis, starting from
  // the anterior view (-y in LPS), at a distance that fits the volume.
  bool autoFrame = true;
  float azimuth = 0.f, elevation = 0.f, zoom = 1.f;
  // Explicit placement (autoFrame false).
  Vec3 position, lookAt, up{0.f, 0.f, 1.f};
  float fovY = 30.f;                   // degrees, perspective
  float orthoHeight = 0.f;             // world units, orthographic; 0 fits the volume
  float lensRadius = 0.f;              // world units; 0 is a pinhole
  float focusDistance = 0.f;           // world units; 0 focuses on the look-at point
  float windowCenter[2] = {0.f, 0.f};  // CameraView::windowCenterX/Y (VTK's camera sets it)
};

// Which majorants the trackers use (MajorantKind), and how the grid is laid
// out and summarised. "octree-voxelmax" is Octree with SummaryMode::VoxelValues.
struct AcceleratorSettings {
  MajorantKind kind = MajorantKind::Octree;
  MajorantGridOptions grid;
};

struct RenderSettings {
  int width = 512, height = 512;
  int samplesPerPixel = 64;
  int threads = 0;  // 0: all hardware threads
  IntegratorSettings integrator;
  AcceleratorSettings accelerator;
  float exposure = 1.f;
  ToneMapper toneMapper = ToneMapper::Filmic;
};

class Scene {
 public:
  std::vector<HostVolume> proxies;  // proxy 0 is the original volume; it defines the tracked box
  std::vector<TransferFunctionDesc> tfs;
  std::vector<MaterialDesc> materials;
  std::vector<int> selectors;  // material TFs (indexes into tfs), highest priority first
  int defaultMaterial = kNoMaterial;
  int gradientProxy = 0;
  // Every material present at once, extinctions added (Classifier::additive).
  bool additiveMaterials = false;
  std::vector<Light> lights;  // directional and point lights
  // Directional lights placed relative to the camera: from the direction
  // toward the camera, turned `azimuth` degrees to the camera's right and
  // `elevation` degrees up. Build() sets their direction.
  struct CameraLight {
    int light;
    float azimuth, elevation;
  };
  std::vector<CameraLight> cameraLights;
  std::shared_ptr<EnvironmentMap> environment;  // optional; null: no environment light
  CameraDesc camera;
  RenderSettings render;
  // Optional: render.width * render.height distances, row 0 at the top, at
  // which camera rays stop (opaque geometry drawn by the host application,
  // from its depth buffer; kInfinity where there is none). Empty: no limit.
  std::vector<float> cameraRayMaxDistance;
  // Half-spaces the volume is seen in (at most kMaxClipPlanes).
  std::vector<ClipPlane> clipPlanes;
  // VTK's cropping regions (Classifier::cropKeep): which of the 27 regions
  // between the planes [lo, hi] of the data's coordinates (worldToData
  // takes a world point there) are kept. A crop edit is a view change: no
  // refit (the majorants ignore it); while cropping, the minorants are not
  // used (a cropped cell's density falls below its minorant).
  struct Cropping {
    uint32_t keep = Classifier::kNoCropping;
    Affine3 worldToData;
    float lo[3] = {0.f, 0.f, 0.f}, hi[3] = {0.f, 0.f, 0.f};
  } cropping;

  // Receives the fraction of the majorant grid's summary build done, on
  // the thread that calls Build, when a Build reads every voxel (a new
  // volume); null reports nothing.
  std::function<void(double)> buildProgress;

  int ProxyIndex(const std::string& name) const;  // -1 if absent
  int MaterialIndex(const std::string& name) const;

  // Validates everything and flattens it. The returned view points into this
  // object's buffers: it stays valid until the next Build or destruction.
  // Throws InputError naming the problem.
  SceneView Build();

  // sigma_t bound over the whole volume (the "none" accelerator's majorant),
  // from the TFs as of the last Build, at most MaxExtinction().
  float GlobalMajorant() const;
  // The clamp on sigma_t (Classifier::maxExtinction): an optical depth of
  // kMaxOpticalDepthPerVoxel over the finest voxel spacing of proxy 0.
  float MaxExtinction() const;
  // After Build: a warning for the user when the materials reach past
  // MaxExtinction() and were clamped to it ("" otherwise).
  const std::string& ExtinctionWarning() const { return extinctionWarning_; }

  // After the voxels of a proxy change: the next Build rebuilds the grid's
  // summaries (a TF or material change only refits the majorants).
  void MarkDataModified() { dataModified_ = true; }
  // After the voxels in [lo, hi] (inclusive, proxy 0's index space) changed:
  // the next Build rebuilds the summaries of the leaves there only.
  void MarkRegionModified(std::array<int, 3> lo, std::array<int, 3> hi) { modifiedRegions_.push_back({lo, hi}); }
  // The majorant grid of the last Build (null with the global majorant).
  const MajorantGrid* Grid() const { return grid_.get(); }
  // Whether the last Build built the grid's summaries (not only a refit).
  bool GridSummariesBuiltByLastBuild() const { return gridBuilt_; }
  // Whether the last Build refitted the grid's majorants. It does only when
  // something a refit reads changed since the last refit (the density and
  // material TFs, the materials' densities, the selectors, the proxies'
  // buffers and geometry, the accelerator) or the summaries were built: an
  // unchanged Build, or one after a camera, settings or colour change,
  // keeps the majorants it has.
  bool GridRefittedByLastBuild() const { return gridRefitted_; }

  // When Build last changed each part of what it builds that a backend may
  // keep a copy of: the voxels (loaded anew or edited), the grid's summaries
  // (built or updated) and its majorants (refitted). The stamps come from one
  // process-wide clock, as vtkTimeStamp's do, so a copy made from one Scene
  // is never taken for current with another (the CUDA backend uploads only
  // what has a stamp newer than its copy's). 0: never built.
  struct BuildStamps {
    uint64_t voxels = 0, summaries = 0, majorants = 0;
  };
  const BuildStamps& Stamps() const { return stamps_; }

  // A scene built anew from a description over the same voxels (a TF or
  // material edit in a scene file, the proxies moved over from `previous`)
  // takes `previous`'s per-voxel work: the majorant grid's summaries and the
  // value ranges. Then its next Build is a refit, not a rebuild. Nothing is
  // taken unless every proxy is the very buffer `previous` last built from.
  // The voxel and summary stamps come with them. Returns whether it was taken.
  bool AdoptDataSummariesFrom(Scene& previous);

 private:
  void Validate() const;
  float UnclampedGlobalMajorant() const;
  CameraView BuildCamera() const;
  std::vector<uint8_t> MakeRefitKey() const;

  std::vector<float> floatPool_;
  std::vector<int> intPool_;
  std::vector<TransferFunctionView> tfViews_;
  std::vector<MaterialView> materialViews_;
  std::vector<CoefficientBinding> bindings_;
  std::vector<Light> lightViews_;
  std::unique_ptr<MajorantGrid> grid_;
  std::vector<std::array<float, 2>> valueRanges_;  // per proxy, at the last data load
  std::vector<const uint8_t*> summarisedVoxels_;   // per proxy, the buffers of the last data load
  bool dataModified_ = true;
  bool gridBuilt_ = false;
  bool gridRefitted_ = false;
  std::vector<uint8_t> refitKey_;  // MakeRefitKey() at the last refit
  std::string extinctionWarning_;
  std::vector<std::array<std::array<int, 3>, 2>> modifiedRegions_;
  BuildStamps stamps_;
};

}  // namespace mmrtm
