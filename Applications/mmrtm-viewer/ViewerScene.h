// What the viewer shows: a volume (and optionally a label map with its
// table) rendered by vtkMultiMaterialVolumeMapper from a scene description
// in the scene format of mmrtm-render (Documentation/scene-format.md), held
// as JSON and given to the mapper through vtkMultiMaterialProperty. The
// editors change that description (a material's density and albedo CCTFs, a
// label's material, the lights) and Apply() hands it to the mapper, which
// refits; SaveScene() writes it with the volumes, camera and render settings
// so that `mmrtm-render --scene` renders the same image.
//
// Every failing call throws std::runtime_error whose message names the file
// and the problem, and leaves the scene as it was.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <QPointF>
#include <QVector>
#include <nlohmann/json.hpp>
#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include "LabelTableWidget.h"
#include "RenderSettingsWidget.h"
#include "SeriesChooserDialog.h"
#include "TransferFunctionEditor.h"

class vtkCamera;
class vtkImageData;
class vtkMultiMaterialProperty;
class vtkMultiMaterialVolumeMapper;
class vtkVolume;

namespace mmrtm {
struct LabelLook;
}

namespace mmrtm::viewer {

class ViewerScene {
 public:
  ViewerScene();
  ~ViewerScene();

  vtkVolume* Volume() { return volume_; }
  vtkMultiMaterialVolumeMapper* Mapper() { return mapper_; }
  bool HasVolume() const { return image_ != nullptr; }
  const std::string& VolumePath() const { return volumePath_; }
  const std::string& PresetName() const { return preset_; }

  // The series of a DICOM folder (more than one: the viewer asks which).
  static QVector<SeriesInfo> ListSeries(const std::string& folder);
  // Opens a volume file or DICOM folder (`series`: a SeriesInstanceUID of
  // the folder, empty for its largest). Drops the label map. Without a
  // preset yet, picks `ct-bone` for CT-like values, else `mri`.
  void OpenVolume(const std::string& path, const std::string& series = "");
  // A label map for the open volume (any grid that overlaps it), and its
  // table of names and colours (`id name [r g b [a]]` or Slicer .ctbl).
  void OpenLabels(const std::string& path);
  void OpenLabelTable(const std::string& path);
  // A preset of Data/presets; the label classes and lights of the viewer are
  // made again from it.
  void SetPreset(const std::string& name);
  static std::vector<std::string> PresetNames();
  // A scene saved by SaveScene (or any scene file with "volumes": scalars
  // and optionally labels): opens its volumes and takes its description.
  void LoadScene(const std::string& path);
  // The explicit camera of the last scene loaded (position, look_at, up,
  // fov), or an empty object when it has none.
  const nlohmann::json& SceneCamera() const { return sceneCamera_; }
  void SaveScene(const std::string& path, vtkCamera* camera, int width, int height) const;

  // The materials of the description, and the density (0..1 curve) and
  // albedo (colour stops) CCTFs over `scalars` of one of them; setting makes
  // them when the material has none.
  std::vector<std::string> MaterialNames() const;
  QVector<QPointF> DensityPoints(const std::string& material) const;
  void SetDensityPoints(const std::string& material, const QVector<QPointF>& points);
  QVector<ColorStop> AlbedoStops(const std::string& material) const;
  void SetAlbedoStops(const std::string& material, const QVector<ColorStop>& stops);
  // The volume's scalar range and histogram (equal-width bins).
  QVector<double> Histogram(int bins, double& low, double& high) const;

  // The labels of the label map (those present in it), with the table's
  // names and colours and the viewer's per-label material.
  const QVector<LabelEntry>& Labels() const { return labels_; }
  void SetLabel(const LabelEntry& entry);

  // Samples, stop condition, bounces, shadow scale, accelerator, backend,
  // exposure on the mapper; the key light and the environment in the
  // description.
  const RenderSettings& Settings() const { return settings_; }
  void SetSettings(const RenderSettings& settings);

  // The description the mapper renders now (with the label classes and
  // lights of the viewer; the labels the user edited reach the mapper as
  // its label materials), the same with the edited labels as classes of
  // their own (what SaveScene writes, for mmrtm-render), and handing the
  // description and the edited labels to the mapper.
  nlohmann::json Description() const;
  nlohmann::json SavedDescription() const;
  void Apply();

 private:
  void AdoptVolume(vtkImageData* image, const std::string& path, const std::string& series);
  static QVector<LabelEntry> LabelsPresent(vtkImageData* labels, vtkImageData* volume, const std::string& path);
  void AdoptLabels(vtkImageData* labels, const std::string& path, const QVector<LabelEntry>& present);
  void ResetFromDescription();
  void RefreshLabelEntries();
  std::map<int, LabelLook> EditedLooks() const;  // the edited rows by the one label rule
  nlohmann::json& DensityTF(const std::string& material);
  nlohmann::json& AlbedoTF(const std::string& material);

  vtkNew<vtkVolume> volume_;
  vtkNew<vtkMultiMaterialVolumeMapper> mapper_;
  vtkNew<vtkMultiMaterialProperty> materials_;
  vtkSmartPointer<vtkImageData> image_, labelMap_;
  std::string volumePath_, series_, labelsPath_, labelTablePath_, preset_;
  nlohmann::json description_ = nlohmann::json::object();  // the preset or scene, as edited
  QVector<LabelEntry> labels_;
  std::vector<int> editedLabels_;  // labels with a class of their own in the description
  RenderSettings settings_;
  nlohmann::json sceneCamera_ = nlohmann::json::object();
};

}  // namespace mmrtm::viewer
