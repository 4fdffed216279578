#include "ViewerScene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCommand.h>
#include <vtkIdList.h>
#include <vtkImageAccumulate.h>
#include <vtkImageData.h>
#include <vtkMatrix3x3.h>
#include <vtkPointData.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>

#include "label_materials.h"
#include "label_table.h"
#include "mmrtmVolumeLoader.h"
#include "scene_json.h"
#include "vtkMultiMaterialProperty.h"
#include "vtkMultiMaterialVolumeMapper.h"
#include "vtkMultiMaterialVolumeReader.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace mmrtm::viewer {
namespace {

// Reads `path` (a volume file or a DICOM folder) with the project's reader;
// throws with the reader's own message.
vtkSmartPointer<vtkImageData> Read(const std::string& path, const std::string& series = "") {
  vtkNew<vtkMultiMaterialVolumeReader> reader;
  reader->SetFileName(path.c_str());
  if (!series.empty()) reader->SetSeries(series.c_str());
  std::string error;
  vtkNew<vtkCallbackCommand> onError;
  onError->SetClientData(&error);
  onError->SetCallback([](vtkObject*, unsigned long, void* client, void* call) {
    // VTK's message: "ERROR: In FILE, line N\nCLASS (0x...): MESSAGE"; keep MESSAGE.
    std::string message = call ? static_cast<const char*>(call) : "";
    const auto colon = message.find("): ");
    if (colon != std::string::npos) message = message.substr(colon + 3);
    while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
    auto* e = static_cast<std::string*>(client);
    if (e->empty()) *e = message;
  });
  reader->AddObserver(vtkCommand::ErrorEvent, onError);
  reader->Update();
  if (!error.empty()) throw std::runtime_error(error);
  if (reader->GetOutput()->GetNumberOfPoints() == 0) throw std::runtime_error(path + ": no volume could be read");
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->ShallowCopy(reader->GetOutput());
  return image;
}

// The world box of an image (its corners through origin, spacing, direction).
std::array<double, 6> WorldBounds(vtkImageData* image) {
  std::array<double, 6> b{1e300, -1e300, 1e300, -1e300, 1e300, -1e300};
  int e[6];
  image->GetExtent(e);
  for (int c = 0; c < 8; ++c) {
    double ijk[3] = {double(e[c & 1 ? 1 : 0]), double(e[c & 2 ? 3 : 2]), double(e[c & 4 ? 5 : 4])}, w[3];
    image->TransformContinuousIndexToPhysicalPoint(ijk, w);
    for (int a = 0; a < 3; ++a) b[2 * a] = std::min(b[2 * a], w[a]), b[2 * a + 1] = std::max(b[2 * a + 1], w[a]);
  }
  return b;
}

// How labels look when the description does not say: as the ct-organs
// preset has them (vessels and bones by name, any other label at full
// opacity in its table colour).
json DefaultLabelMaterials() {
  return ReadJsonFile(PresetPath(vtkMultiMaterialProperty::GetPresetDirectory(), "ct-organs")).at("label_materials");
}

json DefaultLights() {
  return json::parse(R"([{"type": "environment", "sky": "default", "intensity": 0.6},
    {"type": "directional", "camera_azimuth": -35, "camera_elevation": 40, "color": [1.0, 0.96, 0.9], "intensity": 3.0}])");
}

// The first CCTF over `scalars` among `tfs` (a material's list for one
// quantity), or null.
json* FindScalarCCTF(json& tfs) {
  for (json& tf : tfs)
    if (tf.value("type", "") == "cctf" && tf.value("proxy", "scalars") == "scalars") return &tf;
  return nullptr;
}

// A row of the label list as the one label rule takes it.
LabelLook Look(const LabelEntry& l) {
  LabelLook look;
  look.color = {l.color.redF(), l.color.greenF(), l.color.blueF()};
  look.opacity = std::clamp(l.opacity, 0.0, 1.0);
  look.visible = l.visible;
  look.surface = {{"surface_probability", l.surfaceProbability}, {"roughness", l.roughness}};
  return look;
}

const char* const kAcceleratorNames[] = {"octree", "macrocell", "none"};
}  // namespace

ViewerScene::ViewerScene() {
  volume_->SetMapper(mapper_);
  vtkNew<vtkVolumeProperty> property;  // the description replaces its functions
  volume_->SetProperty(property);
  mapper_->SetMultiMaterialProperty(materials_);
  // Refinement passes run beside the event loop (the window stays responsive).
  mapper_->AsynchronousRefinementOn();
  mapper_->SetSamplesPerRender(settings_.samplesPerRender);
  SetSettings(settings_);
}

ViewerScene::~ViewerScene() = default;

QVector<SeriesInfo> ViewerScene::ListSeries(const std::string& folder) {
  QVector<SeriesInfo> list;
  try {
    for (const DicomSeriesSummary& s : ListDicomSeries(folder))
      list.push_back({QString::fromStdString(s.uid), QString::fromStdString(s.description),
                      QString::fromStdString(s.modality), s.slices, s.rows, s.columns});
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
  return list;
}

void ViewerScene::OpenVolume(const std::string& path, const std::string& series) {
  AdoptVolume(Read(path, series), path, series);
}

void ViewerScene::AdoptVolume(vtkImageData* image, const std::string& path, const std::string& series) {
  image_ = image;
  volumePath_ = fs::absolute(path).string();
  series_ = series;
  labelMap_ = nullptr;
  labelsPath_.clear();
  labels_.clear();
  editedLabels_.clear();
  mapper_->SetInputData(image_);
  mapper_->SetMaskInput(nullptr);
  if (preset_.empty()) {
    const double* range = image_->GetScalarRange();
    SetPreset(range[0] < -500 ? "ct-bone" : "mri");  // Hounsfield units have air at -1000
  } else {
    Apply();
  }
}

void ViewerScene::OpenLabels(const std::string& path) {
  if (!image_) throw std::runtime_error(path + ": open a volume before its label map");
  vtkSmartPointer<vtkImageData> labels = Read(path);
  AdoptLabels(labels, path, LabelsPresent(labels, image_, path));
}

QVector<LabelEntry> ViewerScene::LabelsPresent(vtkImageData* labels, vtkImageData* volume, const std::string& path) {
  const auto a = WorldBounds(volume), b = WorldBounds(labels);
  for (int axis = 0; axis < 3; ++axis)
    if (b[2 * axis] > a[2 * axis + 1] || b[2 * axis + 1] < a[2 * axis])
      throw std::runtime_error(path + ": the label map does not overlap the volume");
  const double* range = labels->GetScalarRange();
  if (range[0] < 0 || range[1] > 65535 || range[1] < 1)
    throw std::runtime_error(path + ": not a label map (values from " + std::to_string(range[0]) + " to " +
                             std::to_string(range[1]) + ")");
  vtkNew<vtkIdList> ids;
  if (!vtkMultiMaterialVolumeMapper::GetLabelsPresent(labels, ids))
    throw std::runtime_error(path + ": not a label map (its values are not whole numbers)");
  QVector<LabelEntry> present;
  for (vtkIdType i = 0; i < ids->GetNumberOfIds(); ++i) {
    const int id = static_cast<int>(ids->GetId(i));
    double c[3];
    vtkMultiMaterialVolumeMapper::GetDefaultLabelColor(id, c);
    present.push_back({id, QString("label_%1").arg(id), QColor::fromRgbF(c[0], c[1], c[2])});
  }
  return present;
}

void ViewerScene::AdoptLabels(vtkImageData* labels, const std::string& path, const QVector<LabelEntry>& present) {
  labelMap_ = labels;
  labelsPath_ = fs::absolute(path).string();
  labels_ = present;
  editedLabels_.clear();
  mapper_->SetMaskInput(labelMap_);
  mapper_->SetMaskTypeToLabelMap();
  if (!labelTablePath_.empty()) OpenLabelTable(labelTablePath_);  // names and colours for the new labels
  RefreshLabelEntries();
  Apply();
}

// The labels' entries as the description draws them (the classes of its
// label_materials, the table's names and colours), but for the labels the
// user edited.
void ViewerScene::RefreshLabelEntries() {
  if (!labelMap_ || labels_.isEmpty()) return;
  std::vector<int> ids;
  for (const LabelEntry& l : labels_) ids.push_back(l.id);
  LabelTable table;
  if (!labelTablePath_.empty()) table = ReadLabelTable(labelTablePath_);
  json doc = description_;
  if (!doc.contains("label_materials")) doc["label_materials"] = DefaultLabelMaterials();
  for (const auto& [id, look] : LabelLooksOf(doc, ids, labelTablePath_.empty() ? nullptr : &table)) {
    if (std::find(editedLabels_.begin(), editedLabels_.end(), id) != editedLabels_.end()) continue;
    for (LabelEntry& l : labels_)
      if (l.id == id) {
        if (const mmrtm::LabelEntry* entry = labelTablePath_.empty() ? nullptr : table.Find(id))
          l.name = QString::fromStdString(entry->name);
        l.color = QColor::fromRgbF(look.color[0], look.color[1], look.color[2]);
        l.surfaceProbability = look.surface.value("surface_probability", 0.0);
        l.roughness = look.surface.value("roughness", 0.5);
        l.opacity = look.opacity;
      }
  }
}

void ViewerScene::OpenLabelTable(const std::string& path) {
  LabelTable table;
  try {
    table = ReadLabelTable(path);
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
  labelTablePath_ = fs::absolute(path).string();
  for (LabelEntry& label : labels_)
    if (const mmrtm::LabelEntry* entry = table.Find(label.id)) {
      label.name = QString::fromStdString(entry->name);
      label.color = QColor::fromRgbF(entry->color[0], entry->color[1], entry->color[2]);
    }
  RefreshLabelEntries();
  Apply();
}

std::vector<std::string> ViewerScene::PresetNames() {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(vtkMultiMaterialProperty::GetPresetDirectory()))
    if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

void ViewerScene::SetPreset(const std::string& name) {
  json doc;
  try {
    doc = ReadJsonFile(PresetPath(vtkMultiMaterialProperty::GetPresetDirectory(), name));
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
  description_ = doc;
  preset_ = name;
  ResetFromDescription();
  RefreshLabelEntries();
  Apply();
}

// The viewer's lights and render settings from the description's, and no
// label edits.
void ViewerScene::ResetFromDescription() {
  editedLabels_.clear();
  description_.erase("volumes");
  const json lights = description_.value("lights", DefaultLights());
  settings_.environment = false;
  for (const json& light : lights) {
    if (light.value("type", "") == "environment") settings_.environment = true;
    if (light.value("type", "") == "directional" && light.contains("camera_azimuth")) {
      settings_.lightAzimuth = light.value("camera_azimuth", settings_.lightAzimuth);
      settings_.lightElevation = light.value("camera_elevation", settings_.lightElevation);
      settings_.lightIntensity = light.value("intensity", settings_.lightIntensity);
    }
  }
  const json render = description_.value("render", json::object());
  settings_.exposure = render.value("exposure", settings_.exposure);
  settings_.shadowScale = render.value("shadow_extinction_scale", settings_.shadowScale);
  settings_.bounces = render.value("max_bounces", settings_.bounces);
  SetSettings(settings_);
}

void ViewerScene::LoadScene(const std::string& path) {
  json doc;
  try {
    doc = ReadJsonFile(path);
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
  const fs::path base = fs::absolute(path).parent_path();
  auto file = [&](const json& entry, const std::string& what) {
    if (!entry.is_object() || !entry.contains("file") || !entry["file"].is_string())
      throw std::runtime_error(path + ": volumes." + what + " needs a \"file\"");
    const fs::path f = entry["file"].get<std::string>();
    return (f.is_absolute() ? f : base / f).string();
  };
  if (!doc.contains("volumes") || !doc["volumes"].contains("scalars"))
    throw std::runtime_error(path + ": the scene has no volumes.scalars to open");
  // Read everything first: a failure leaves the viewer as it was.
  const std::string volume = file(doc["volumes"]["scalars"], "scalars");
  std::string labels, table;
  if (doc["volumes"].contains("labels")) labels = file(doc["volumes"]["labels"], "labels");
  if (doc.contains("label_table")) table = (base / doc["label_table"].get<std::string>()).string();
  vtkSmartPointer<vtkImageData> image = Read(volume), labelImage;
  QVector<LabelEntry> present;
  if (!labels.empty()) {
    labelImage = Read(labels);
    present = LabelsPresent(labelImage, image, labels);
  }
  if (!table.empty()) {
    try {
      ReadLabelTable(table);
    } catch (const std::exception& e) {
      throw std::runtime_error(e.what());
    }
  }
  const json camera = doc.value("camera", json::object());
  const json savedCamera = camera.contains("position") && camera.contains("look_at") ? camera : json::object();
  for (const char* key : {"position", "look_at", "up"}) {
    if (!savedCamera.contains(key)) continue;
    const json& v = savedCamera[key];
    if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
      throw std::runtime_error(path + ": camera \"" + key + "\" must be three numbers");
  }
  for (const char* key : {"fov", "ortho_height"})
    if (savedCamera.contains(key) && !savedCamera[key].is_number())
      throw std::runtime_error(path + ": camera \"" + key + "\" must be a number");
  if (savedCamera.contains("projection") && !savedCamera["projection"].is_string())
    throw std::runtime_error(path + ": camera \"projection\" must be \"perspective\" or \"orthographic\"");
  description_ = doc;
  description_.erase("volumes");
  description_.erase("label_table");
  preset_ = fs::path(path).stem().string();  // the scene's description, not a preset chosen by the values
  sceneCamera_ = savedCamera;
  labelTablePath_.clear();
  AdoptVolume(image, volume, "");
  if (labelImage) AdoptLabels(labelImage, labels, present);
  if (!table.empty()) OpenLabelTable(table);
  ResetFromDescription();
  RefreshLabelEntries();
  const json render = doc.value("render", json::object());
  settings_.maximumSamples = render.value("spp", settings_.maximumSamples);
  mapper_->SetSeed(render.value("seed", 0));
  SetSettings(settings_);
  Apply();
}

void ViewerScene::SaveScene(const std::string& path, vtkCamera* camera, int width, int height) const {
  json doc = SavedDescription();
  doc["volumes"] = {{"scalars", {{"file", volumePath_}}}};
  if (labelMap_) doc["volumes"]["labels"] = {{"file", labelsPath_}, {"interpolation", "nearest"}};
  if (!series_.empty())
    doc["description"] =
        doc.value("description", "") + " DICOM series " + series_ + ": mmrtm-render --series " + series_;
  const double* p = camera->GetPosition();
  const double* f = camera->GetFocalPoint();
  const double* u = camera->GetViewUp();
  doc["camera"] = {{"position", {p[0], p[1], p[2]}},
                   {"look_at", {f[0], f[1], f[2]}},
                   {"up", {u[0], u[1], u[2]}},
                   {"fov", camera->GetViewAngle()}};
  if (camera->GetParallelProjection())
    doc["camera"].update({{"projection", "orthographic"}, {"ortho_height", 2 * camera->GetParallelScale()}});
  json& render = doc["render"];
  render["width"] = width;
  render["height"] = height;
  render["spp"] = std::max(1, mapper_->GetAccumulatedSamples());
  render["seed"] = mapper_->GetSeed();
  render["max_bounces"] = settings_.bounces;
  render["shadow_extinction_scale"] = settings_.shadowScale;
  render["accelerator"] = kAcceleratorNames[settings_.accelerator];
  render["exposure"] = settings_.exposure;
  render["background"] = false;  // the viewer shows its own background behind the volume
  // Nothing half-written: a temporary file, renamed into place.
  const std::string temporary = path + ".partial";
  {
    std::ofstream out(temporary);
    out << doc.dump(2) << "\n";
    if (!out) throw std::runtime_error(path + ": could not be written");
  }
  std::error_code ec;
  fs::rename(temporary, path, ec);
  if (ec) throw std::runtime_error(path + ": could not be written (" + ec.message() + ")");
}

std::vector<std::string> ViewerScene::MaterialNames() const {
  std::vector<std::string> names;
  if (description_.contains("materials"))
    for (auto it = description_["materials"].begin(); it != description_["materials"].end(); ++it)
      names.push_back(it.key());
  return names;
}

json& ViewerScene::DensityTF(const std::string& material) {
  json& m = description_["materials"][material];
  json& tfs = m["tfs"]["density"];
  if (!tfs.is_array()) tfs = json::array();
  if (json* tf = FindScalarCCTF(tfs)) return *tf;
  double low = 0, high = 1;
  Histogram(1, low, high);
  tfs.push_back({{"type", "cctf"}, {"proxy", "scalars"}, {"points", {{low, 1.0}, {high, 1.0}}}});
  return tfs.back();
}

json& ViewerScene::AlbedoTF(const std::string& material) {
  json& m = description_["materials"][material];
  json& tfs = m["tfs"]["albedo"];
  if (!tfs.is_array()) tfs = json::array();
  if (json* tf = FindScalarCCTF(tfs)) return *tf;
  double low = 0, high = 1;
  Histogram(1, low, high);
  tfs.push_back({{"type", "cctf"}, {"proxy", "scalars"}, {"points", {{low, 1.0, 1.0, 1.0}}}});
  return tfs.back();
}

QVector<QPointF> ViewerScene::DensityPoints(const std::string& material) const {
  QVector<QPointF> points;
  const json& m = description_["materials"][material];
  if (m.contains("tfs") && m["tfs"].contains("density")) {
    json tfs = m["tfs"]["density"];
    if (const json* tf = FindScalarCCTF(tfs))
      for (const json& p : (*tf)["points"]) points.push_back(QPointF(p[0].get<double>(), p[1].get<double>()));
  }
  if (points.isEmpty()) {  // a constant density: a flat curve at 1
    double low = 0, high = 1;
    Histogram(1, low, high);
    points = {{low, 1.0}, {high, 1.0}};
  }
  return points;
}

void ViewerScene::SetDensityPoints(const std::string& material, const QVector<QPointF>& points) {
  json list = json::array();
  for (const QPointF& p : points) list.push_back({p.x(), p.y()});
  DensityTF(material)["points"] = list;
}

// The colours shown are the effective albedo: the material's base albedo
// times its CCTF. Editing folds the base into the CCTF (base 1).
QVector<ColorStop> ViewerScene::AlbedoStops(const std::string& material) const {
  const json& m = description_["materials"][material];
  const json base = m.value("albedo", json({1.0, 1.0, 1.0}));
  auto channel = [&](int c) { return base.is_array() ? base[c].get<double>() : base.get<double>(); };
  QVector<ColorStop> stops;
  if (m.contains("tfs") && m["tfs"].contains("albedo")) {
    json tfs = m["tfs"]["albedo"];
    if (const json* tf = FindScalarCCTF(tfs))
      for (const json& p : (*tf)["points"]) {
        const bool grey = p.size() == 2;
        auto v = [&](int c) { return std::clamp(p[grey ? 1 : 1 + c].get<double>() * channel(c), 0.0, 1.0); };
        stops.push_back({p[0].get<double>(), QColor::fromRgbF(v(0), v(1), v(2))});
      }
  }
  if (stops.isEmpty()) {
    double low = 0, high = 1;
    Histogram(1, low, high);
    stops.push_back({low, QColor::fromRgbF(std::clamp(channel(0), 0.0, 1.0), std::clamp(channel(1), 0.0, 1.0),
                                           std::clamp(channel(2), 0.0, 1.0))});
  }
  return stops;
}

void ViewerScene::SetAlbedoStops(const std::string& material, const QVector<ColorStop>& stops) {
  json list = json::array();
  for (const ColorStop& s : stops) list.push_back({s.x, s.color.redF(), s.color.greenF(), s.color.blueF()});
  AlbedoTF(material)["points"] = list;
  description_["materials"][material]["albedo"] = {1.0, 1.0, 1.0};
}

QVector<double> ViewerScene::Histogram(int bins, double& low, double& high) const {
  QVector<double> counts;
  if (!image_) {
    low = 0, high = 1;
    return counts;
  }
  const double* range = image_->GetScalarRange();
  low = range[0];
  high = range[1] > range[0] ? range[1] : range[0] + 1;
  vtkNew<vtkImageAccumulate> accumulate;
  accumulate->SetInputData(image_);
  accumulate->SetComponentExtent(0, bins - 1, 0, 0, 0, 0);
  accumulate->SetComponentOrigin(low, 0, 0);
  accumulate->SetComponentSpacing((high - low) / bins, 1, 1);
  accumulate->Update();
  for (int i = 0; i < bins; ++i) counts.push_back(accumulate->GetOutput()->GetScalarComponentAsDouble(i, 0, 0, 0));
  return counts;
}

void ViewerScene::SetLabel(const LabelEntry& entry) {
  for (LabelEntry& label : labels_)
    if (label.id == entry.id) label = entry;
  if (std::find(editedLabels_.begin(), editedLabels_.end(), entry.id) == editedLabels_.end())
    editedLabels_.push_back(entry.id);
  Apply();
}

void ViewerScene::SetSettings(const RenderSettings& s) {
  settings_ = s;
  mapper_->SetSamplesPerRender(s.samplesPerRender);
  mapper_->SetMaximumSamples(s.stopAtNoise ? 0 : s.maximumSamples);
  mapper_->SetNoiseTarget(s.stopAtNoise ? s.noiseTarget : 0.0);
  mapper_->SetMaximumBounces(s.bounces);
  mapper_->SetShadowExtinctionScale(s.shadowScale);
  mapper_->SetAccelerator(s.accelerator);
  mapper_->SetBackend(s.backend);
  mapper_->SetExposure(s.exposure);
  mapper_->SetDenoisingMode(s.denoising);
  if (image_) Apply();
}

json ViewerScene::Description() const {
  json doc = description_;
  doc.erase("camera");
  doc.erase("volumes");
  if (labelMap_) {
    if (!doc.contains("label_materials")) doc["label_materials"] = DefaultLabelMaterials();
    if (!labelTablePath_.empty()) doc["label_table"] = labelTablePath_;
  } else {
    doc.erase("label_materials");
    doc.erase("label_table");
  }
  // The key light and the environment as the settings say.
  json lights = doc.value("lights", DefaultLights());
  json edited = json::array();
  bool key = false;
  for (json light : lights) {
    const std::string type = light.value("type", "");
    if (type == "environment") {
      if (settings_.environment) edited.push_back(light);
      continue;
    }
    if (type == "directional" && light.contains("camera_azimuth") && !key) {
      light["camera_azimuth"] = settings_.lightAzimuth;
      light["camera_elevation"] = settings_.lightElevation;
      light["intensity"] = settings_.lightIntensity;
      key = true;
    }
    edited.push_back(light);
  }
  if (!key)
    edited.push_back(json::object({{"type", "directional"},
                                   {"camera_azimuth", settings_.lightAzimuth},
                                   {"camera_elevation", settings_.lightElevation},
                                   {"intensity", settings_.lightIntensity}}));
  if (settings_.environment &&
      std::none_of(edited.begin(), edited.end(), [](const json& l) { return l.value("type", "") == "environment"; }))
    edited.insert(edited.begin(), json::object({{"type", "environment"}, {"sky", "default"}, {"intensity", 0.6}}));
  doc["lights"] = edited;
  return doc;
}

std::map<int, LabelLook> ViewerScene::EditedLooks() const {
  std::map<int, LabelLook> looks;
  for (int id : editedLabels_)
    for (const LabelEntry& l : labels_)
      if (l.id == id) looks[id] = Look(l);
  return looks;
}

json ViewerScene::SavedDescription() const {
  return labelMap_ ? WithLabelLooks(Description(), EditedLooks()) : Description();
}

void ViewerScene::Apply() {
  // The edited labels by the mapper's one label route, and the description.
  // Both are compared by value: what is set again as it was neither refits
  // nor restarts.
  mapper_->RemoveAllLabelMaterials();
  mapper_->RemoveAllLabelMaterialParameters();
  for (const auto& [id, look] : EditedLooks()) {
    mapper_->SetLabelMaterial(id, look.color[0], look.color[1], look.color[2], look.visible ? look.opacity : 0.0);
    mapper_->SetLabelMaterialParameters(id, look.surface.dump().c_str());
  }
  materials_->SetScene(Description());
}

}  // namespace mmrtm::viewer
