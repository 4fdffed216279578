#include "scene_json.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <set>
#include <sstream>

#include "derived_proxies.h"
#include "label_alignment.h"

namespace mmrtm {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

[[noreturn]] void Fail(const std::string& where, const std::string& what) { throw InputError(where + ": " + what); }

// Rejects keys other than `allowed`: a typo in a scene must not pass silently.
void CheckKeys(const json& obj, const std::string& where, std::initializer_list<const char*> allowed) {
  if (!obj.is_object()) Fail(where, "expected an object");
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || it.key() == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      Fail(where, "unknown key '" + it.key() + "' (expected one of: " + list + ")");
    }
  }
}

float Number(const json& v, const std::string& where) {
  if (!v.is_number()) Fail(where, "expected a number");
  double d = v.get<double>();
  // A double beyond float's range would be infinite in the scene (a fuzz
  // finding: a light colour of 1e108 put NaN into the image).
  if (!(std::fabs(d) <= std::numeric_limits<float>::max())) Fail(where, "expected a finite number within float range");
  return (float)d;
}

// A light's radiance (colour x intensity): at most kMaxRadiance per channel.
RGB Radiance(const RGB& color, float intensity, const std::string& where) {
  const RGB L = color * intensity;
  for (int c = 0; c < 3; ++c)
    if (!(std::fabs(L[c]) <= kMaxRadiance))
      Fail(where, "colour x intensity must stay within 1e20 (the film would overflow)");
  return L;
}

float NumberOr(const json& obj, const char* key, float fallback, const std::string& where) {
  return obj.contains(key) ? Number(obj[key], where + "." + key) : fallback;
}

int IntegerOr(const json& obj, const char* key, int fallback, const std::string& where) {
  if (!obj.contains(key)) return fallback;
  const json& v = obj[key];
  if (!v.is_number_integer()) Fail(where + "." + key, "expected an integer");
  return v.get<int>();
}

std::string StringOr(const json& obj, const char* key, const std::string& fallback, const std::string& where) {
  if (!obj.contains(key)) return fallback;
  if (!obj[key].is_string()) Fail(where + "." + key, "expected a string");
  return obj[key].get<std::string>();
}

bool BoolOr(const json& obj, const char* key, bool fallback, const std::string& where) {
  if (!obj.contains(key)) return fallback;
  if (!obj[key].is_boolean()) Fail(where + "." + key, "expected true or false");
  return obj[key].get<bool>();
}

Vec3 Vector(const json& v, const std::string& where) {
  if (!v.is_array() || v.size() != 3) Fail(where, "expected [x, y, z]");
  return {Number(v[0], where + "[0]"), Number(v[1], where + "[1]"), Number(v[2], where + "[2]")};
}

// A colour: a number (grey) or [r, g, b].
RGB Color(const json& v, const std::string& where) {
  if (v.is_number()) return RGB(Number(v, where));
  if (!v.is_array() || v.size() != 3) Fail(where, "expected a number or [r, g, b]");
  return RGB(Number(v[0], where + "[0]"), Number(v[1], where + "[1]"), Number(v[2], where + "[2]"));
}

std::string SourceOf(const HostVolume& v) { return v.source.empty() ? v.name : v.source; }

std::string Resolve(const std::string& file, const std::string& base) {
  fs::path p(file);
  return p.is_absolute() ? file : (fs::path(base) / p).lexically_normal().string();
}

struct QuantityName {
  const char* name;
  Quantity quantity;
};
constexpr QuantityName kQuantities[] = {{"density", Quantity::Density},
                                        {"albedo", Quantity::Albedo},
                                        {"roughness", Quantity::Roughness},
                                        {"metallic", Quantity::Metallic},
                                        {"surface_probability", Quantity::SurfaceProbability},
                                        {"emission", Quantity::Emission},
                                        {"anisotropy", Quantity::Anisotropy}};

TFType ParseTFType(const json& tf, const std::string& where) {
  const std::string t = StringOr(tf, "type", "", where);
  if (t == "cctf") return TFType::CCTF;
  if (t == "cpctf") return TFType::CPCTF;
  if (t == "cdptf") return TFType::CDPTF;
  if (t == "mpctf") return TFType::MPCTF;
  if (t == "mdptf") return TFType::MDPTF;
  Fail(where + ".type", "expected cctf, cpctf, cdptf, mpctf or mdptf, got '" + t + "'");
}

// A volume computed from another when some TF reads it ("derived": ...).
struct DerivedSpec {
  std::string where;  // JSON path, for messages
  std::string kind;   // gradient_magnitude, smoothed or opacity
  std::string from;
  int fromIndex = -1;
  float sigmaMm = 0.f;
  std::vector<std::array<float, 2>> points;
};

class Parser {
 public:
  Parser(const json& doc, SceneInputs inputs) : doc_(doc), in_(std::move(inputs)) {}

  Scene Parse() {
    CheckKeys(doc_, "scene",
              {"volumes", "materials", "material_tfs", "default_material", "gradient_proxy", "lights", "camera",
               "render", "description", "label_materials", "label_table", "additive_materials"});
    ParseVolumes();
    ExpandDocument();
    ParseMaterialNames();
    for (auto it = Materials().begin(); it != Materials().end(); ++it) ParseMaterial(it.key(), it.value());
    ParseMaterialTFs();
    if (doc_.contains("additive_materials")) {
      if (!doc_["additive_materials"].is_boolean()) Fail("additive_materials", "expected true or false");
      scene_.additiveMaterials = doc_["additive_materials"].get<bool>();
    }
    if (doc_.contains("default_material")) {
      const json& d = doc_["default_material"];
      if (d.is_null()) {
        scene_.defaultMaterial = kNoMaterial;
      } else {
        if (!d.is_string()) Fail("default_material", "expected a material name or null");
        scene_.defaultMaterial = MaterialByName(d.get<std::string>(), "default_material");
      }
    } else {
      scene_.defaultMaterial = scene_.materials.size() == 1 ? 0 : kNoMaterial;
    }
    KeepReadProxies();
    ParseLights();
    ParseCamera();
    ParseRender();
    return std::move(scene_);
  }

 private:
  const json& Materials() const {
    static const json empty = json::object();
    return doc_.contains("materials") ? doc_["materials"] : empty;
  }

  void ParseVolumes() {
    // Volumes given by the caller first, then the scene's own files.
    for (auto& [name, volume] : in_.volumes) {
      volume.name = name;
      volumeNames_.push_back(name);
      volumes_.push_back(std::move(volume));
      derived_.emplace_back();
    }
    if (doc_.contains("volumes")) {
      const json& vols = doc_["volumes"];
      if (!vols.is_object()) Fail("volumes", "expected an object of named volumes");
      for (auto it = vols.begin(); it != vols.end(); ++it) {
        const std::string where = "volumes." + it.key();
        if (in_.volumes.count(it.key())) continue;  // given on the command line
        if (it.value().is_object() && it.value().contains("derived")) {
          // Computed later, and only if read (KeepReadProxies).
          derived_.push_back(ParseDerived(it.value(), where));
          volumes_.emplace_back();
          volumes_.back().name = it.key();
          volumeNames_.push_back(it.key());
          continue;
        }
        CheckKeys(it.value(), where, {"file", "interpolation"});
        const std::string file = StringOr(it.value(), "file", "", where);
        if (file.empty()) Fail(where + ".file", "a volume needs a file");
        const std::string interp = StringOr(it.value(), "interpolation", "trilinear", where);
        if (interp != "trilinear" && interp != "nearest")
          Fail(where + ".interpolation", "expected trilinear or nearest");
        if (!in_.loadVolume) Fail(where, "no volume reader available");
        volumes_.push_back(in_.loadVolume(Resolve(file, in_.baseDirectory), it.key(),
                                          interp == "nearest" ? Interpolation::Nearest : Interpolation::Trilinear));
        volumes_.back().name = it.key();
        volumeNames_.push_back(it.key());
        derived_.emplace_back();
      }
    }
    if (volumes_.empty()) Fail("volumes", "the scene has no volume (give an input file)");
    ResolveDerivedSources();
  }

  DerivedSpec ParseDerived(const json& vj, const std::string& where) {
    DerivedSpec d;
    d.where = where;
    if (!vj["derived"].is_string()) Fail(where + ".derived", "expected gradient_magnitude, smoothed or opacity");
    d.kind = vj["derived"].get<std::string>();
    if (d.kind == "gradient_magnitude") {
      CheckKeys(vj, where, {"derived", "from"});
    } else if (d.kind == "smoothed") {
      CheckKeys(vj, where, {"derived", "from", "sigma_mm"});
      if (!vj.contains("sigma_mm")) Fail(where, "a smoothed volume needs sigma_mm");
      d.sigmaMm = Number(vj["sigma_mm"], where + ".sigma_mm");
      if (!(d.sigmaMm > 0.f)) Fail(where + ".sigma_mm", "must be a positive number of mm");
    } else if (d.kind == "opacity") {
      CheckKeys(vj, where, {"derived", "from", "points"});
      const json& pts = vj.contains("points") ? vj["points"] : json();
      if (!pts.is_array() || pts.empty()) Fail(where + ".points", "an opacity volume needs [[value, opacity], ...]");
      for (size_t i = 0; i < pts.size(); ++i) {
        const std::string w = where + ".points[" + std::to_string(i) + "]";
        if (!pts[i].is_array() || pts[i].size() != 2) Fail(w, "expected [value, opacity]");
        const float x = Number(pts[i][0], w), o = Number(pts[i][1], w);
        if (i > 0 && x < d.points.back()[0]) Fail(w, "values must be in ascending order");
        if (o < 0.f || o > 1.f) Fail(w, "opacity must be in 0..1");
        d.points.push_back({x, o});
      }
    } else {
      Fail(where + ".derived", "expected gradient_magnitude, smoothed or opacity, got '" + d.kind + "'");
    }
    d.from = StringOr(vj, "from", "", where);
    if (d.from.empty()) Fail(where + ".from", "a derived volume needs 'from', the volume it is computed from");
    return d;
  }

  // `from` may name a volume listed after the derived one, so this runs once
  // all volumes are known.
  void ResolveDerivedSources() {
    for (std::optional<DerivedSpec>& d : derived_) {
      if (!d) continue;
      for (size_t i = 0; i < volumeNames_.size(); ++i)
        if (volumeNames_[i] == d->from) d->fromIndex = (int)i;
      if (d->fromIndex < 0) {
        std::string list;
        for (size_t i = 0; i < volumeNames_.size(); ++i)
          if (!derived_[i]) list += (list.empty() ? "" : ", ") + volumeNames_[i];
        Fail(d->where + ".from", "no volume named '" + d->from + "' (the scene has: " + list + ")");
      }
      if (derived_[d->fromIndex])
        Fail(d->where + ".from", "'" + d->from + "' is itself derived; derive from a volume read from a file");
    }
  }

  // Computes derived volume i from its source (which is still in volumes_).
  HostVolume ComputeDerived(int i) {
    const DerivedSpec& d = *derived_[i];
    const HostVolume& source = volumes_[d.fromIndex];
    const std::string& name = volumeNames_[i];
    if (d.kind == "gradient_magnitude") return GradientMagnitudeProxy(source, name);
    if (d.kind == "smoothed") return SmoothedProxy(source, d.sigmaMm, name);
    return OpacityProxy(source, d.points, name);
  }

  // Blocks a front end's library expands once the volumes are read (the
  // labels library's "label_materials" and "label_table").
  void ExpandDocument() {
    if (!in_.expandDocument) {
      for (const char* key : {"label_materials", "label_table"})
        if (doc_.contains(key))
          Fail(key, "label classes are expanded by the labels library (mmrtm::ExpandLabelMaterialsOnLoad)");
      return;
    }
    doc_ = in_.expandDocument(
        doc_,
        [&](const std::string& name) -> const HostVolume* {
          for (size_t i = 0; i < volumeNames_.size(); ++i)
            if (volumeNames_[i] == name && !derived_[i]) return &volumes_[i];
          return nullptr;
        },
        in_.baseDirectory);
  }

  int ProxyByName(const std::string& name, const std::string& where) {
    for (size_t i = 0; i < volumeNames_.size(); ++i)
      if (volumeNames_[i] == name) {
        readProxies_.insert((int)i);
        return (int)i;
      }
    std::string list;
    for (const std::string& n : volumeNames_) list += (list.empty() ? "" : ", ") + n;
    Fail(where, "no proxy volume named '" + name + "' (the scene has: " + list + ")");
  }

  int MaterialByName(const std::string& name, const std::string& where) const {
    int m = scene_.MaterialIndex(name);
    if (m < 0) Fail(where, "no material named '" + name + "'");
    return m;
  }

  void ParseMaterialNames() {
    const json& mats = Materials();
    if (!mats.is_object()) Fail("materials", "expected an object of named materials");
    if (mats.empty()) Fail("materials", "the scene defines no material");
    for (auto it = mats.begin(); it != mats.end(); ++it) {
      MaterialDesc m;
      m.name = it.key();
      scene_.materials.push_back(m);
    }
  }

  void ParseMaterial(const std::string& name, const json& mj) {
    const std::string where = "materials." + name;
    CheckKeys(mj, where,
              {"density", "albedo", "roughness", "metallic", "surface_probability", "emission", "anisotropy", "tfs"});
    MaterialDesc& m = scene_.materials[scene_.MaterialIndex(name)];
    for (const QuantityName& q : kQuantities) {
      if (!mj.contains(q.name)) continue;
      const int offset = QuantityOffset(q.quantity);
      if (QuantityChannels(q.quantity) == 3) {
        RGB c = Color(mj[q.name], where + "." + q.name);
        for (int ch = 0; ch < 3; ++ch) m.base[offset + ch] = c[ch];
      } else {
        m.base[offset] = Number(mj[q.name], where + "." + q.name);
      }
    }
    if (m.base[0] < 0.f) Fail(where + ".density", "must not be negative");
    if (!mj.contains("tfs")) return;
    const json& tfs = mj["tfs"];
    for (auto it = tfs.begin(); it != tfs.end(); ++it) {
      const QuantityName* q = nullptr;
      for (const QuantityName& cand : kQuantities)
        if (it.key() == cand.name) q = &cand;
      if (!q) Fail(where + ".tfs", "unknown coefficient '" + it.key() + "'");
      const json& list = it.value().is_array() ? it.value() : json::array({it.value()});
      for (size_t i = 0; i < list.size(); ++i) {
        const std::string w = where + ".tfs." + it.key() + "[" + std::to_string(i) + "]";
        int tf = ParseTF(list[i], w, QuantityChannels(q->quantity));
        if (IsMaterialTF(scene_.tfs[tf].type)) Fail(w, "a coefficient needs a cctf, cpctf or cdptf");
        m.bindings.push_back({tf, q->quantity});
      }
    }
  }

  // Parses a TF of any type; returns its index in scene_.tfs.
  int ParseTF(const json& tj, const std::string& where, int maxChannels) {
    TransferFunctionDesc tf;
    tf.where = where;
    tf.type = ParseTFType(tj, where);
    const bool range = IsRangeTF(tf.type), material = IsMaterialTF(tf.type);
    const char* listKey = range ? "ranges" : "points";
    CheckKeys(tj, where, {"type", "proxy", listKey});
    tf.proxy = ProxyByName(StringOr(tj, "proxy", "scalars", where), where + ".proxy");
    if (!tj.contains(listKey) || !tj[listKey].is_array() || tj[listKey].empty())
      Fail(where, std::string("a transfer function needs at least one ") + (range ? "range" : "point"));
    const json& list = tj[listKey];
    const size_t keyCount = range ? 2 : 1;
    tf.channels = 0;
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string w = where + "." + listKey + "[" + std::to_string(i) + "]";
      const json& e = list[i];
      if (!e.is_array() || e.size() < keyCount + 1)
        Fail(w, range ? "expected [low, high, value...]" : "expected [value, coefficient...]");
      for (size_t k = 0; k < keyCount; ++k) tf.keys.push_back(Number(e[k], w));
      if (material) {
        if (e.size() != keyCount + 1 || !e[keyCount].is_string()) Fail(w, "expected a material name after the key");
        tf.materials.push_back(MaterialByName(e[keyCount].get<std::string>(), w));
        continue;
      }
      const int channels = (int)(e.size() - keyCount);
      if (tf.channels == 0) tf.channels = channels;
      if (channels != tf.channels) Fail(w, "every entry needs the same number of values");
      if (channels != 1 && channels != maxChannels)
        Fail(w, "this coefficient takes " + std::to_string(maxChannels) + " value(s) per entry, or 1");
      for (size_t k = keyCount; k < e.size(); ++k) tf.values.push_back(Number(e[k], w));
    }
    if (material) tf.channels = 1;
    scene_.tfs.push_back(std::move(tf));
    return (int)scene_.tfs.size() - 1;
  }

  void ParseMaterialTFs() {
    if (!doc_.contains("material_tfs")) return;
    const json& list = doc_["material_tfs"];
    if (!list.is_array()) Fail("material_tfs", "expected a list, highest priority first");
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string w = "material_tfs[" + std::to_string(i) + "]";
      int tf = ParseTF(list[i], w, 1);
      if (!IsMaterialTF(scene_.tfs[tf].type)) Fail(w, "a material TF is an mpctf or mdptf");
      scene_.selectors.push_back(tf);
    }
  }

  // Keeps only the proxies some TF reads (DESIGN.md rule 3), the primary
  // ("scalars", or the first volume) first: it defines the tracked box.
  void KeepReadProxies() {
    int primary = 0;
    for (size_t i = 0; i < volumeNames_.size(); ++i)
      if (volumeNames_[i] == "scalars") primary = (int)i;
    std::string gradient = volumeNames_[primary];
    if (doc_.contains("gradient_proxy")) {
      if (!doc_["gradient_proxy"].is_string()) Fail("gradient_proxy", "expected a proxy name");
      gradient = doc_["gradient_proxy"].get<std::string>();
    }
    int gradientIndex = ProxyByName(gradient, "gradient_proxy");
    std::vector<int> order{primary};
    for (int i : readProxies_)
      if (i != primary) order.push_back(i);
    // Derived volumes are computed here, once the read set is known, so an
    // unread one costs nothing; all before any volume is moved, since their
    // sources may be read too.
    std::vector<HostVolume> computed(volumes_.size());
    for (int i : order)
      if (derived_[i]) computed[i] = ComputeDerived(i);
    for (int i : order)
      if (derived_[i]) volumes_[i] = std::move(computed[i]);
    // Label maps are looked up nearest: one on a grid other than the primary
    // volume's would shift label boundaries by up to half a label voxel
    // against the anatomy, so it is put on the primary's grid (continuous
    // proxies interpolate, and the tracer handles them on any grid).
    for (int i : order) {
      if (i == primary || derived_[i] || volumes_[i].interpolation != Interpolation::Nearest) continue;
      bool resampled = false;
      volumes_[i] = AlignLabelsToVolume(std::move(volumes_[i]), volumes_[primary], &resampled);
      if (resampled)
        std::cerr << "warning: label map " << SourceOf(volumes_[i]) << " was resampled (nearest neighbour) onto the "
                  << "voxel grid of " << SourceOf(volumes_[primary]) << "\n";
    }
    std::vector<int> remap(volumes_.size(), -1);
    for (size_t k = 0; k < order.size(); ++k) {
      remap[order[k]] = (int)k;
      scene_.proxies.push_back(std::move(volumes_[order[k]]));
    }
    for (TransferFunctionDesc& tf : scene_.tfs) tf.proxy = remap[tf.proxy];
    scene_.gradientProxy = remap[gradientIndex];
  }

  void ParseLights() {
    if (!doc_.contains("lights")) {
      scene_.environment = EnvironmentMap::DefaultSky();
      return;
    }
    const json& list = doc_["lights"];
    if (!list.is_array()) Fail("lights", "expected a list of lights");
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string w = "lights[" + std::to_string(i) + "]";
      const json& lj = list[i];
      const std::string type = StringOr(lj, "type", "", w);
      const float intensity = NumberOr(lj, "intensity", 1.f, w);
      const RGB color = lj.contains("color") ? Color(lj["color"], w + ".color") : RGB(1.f);
      if (type == "directional") {
        CheckKeys(lj, w, {"type", "direction", "camera_azimuth", "camera_elevation", "color", "intensity"});
        Light l;
        l.type = LightType::Directional;
        l.L = Radiance(color, intensity, w);
        if (lj.contains("direction")) {
          Vec3 d = Vector(lj["direction"], w + ".direction");
          if (!(Length(d) > 0.f)) Fail(w + ".direction", "must not be zero");
          l.vector = -Normalize(d);  // stored toward the light
        } else {
          // Relative to the camera; Scene::Build resolves it.
          scene_.cameraLights.push_back({(int)scene_.lights.size(), NumberOr(lj, "camera_azimuth", 0.f, w),
                                         NumberOr(lj, "camera_elevation", 0.f, w)});
        }
        scene_.lights.push_back(l);
      } else if (type == "point") {
        CheckKeys(lj, w, {"type", "position", "color", "intensity"});
        if (!lj.contains("position")) Fail(w, "a point light needs a position");
        Light l;
        l.type = LightType::Point;
        l.vector = Vector(lj["position"], w + ".position");
        l.L = Radiance(color, intensity, w);
        scene_.lights.push_back(l);
      } else if (type == "environment") {
        CheckKeys(lj, w, {"type", "file", "sky", "color", "intensity"});
        if (scene_.environment) Fail(w, "only one environment light is supported");
        if (lj.contains("file")) {
          scene_.environment = EnvironmentMap::Load(Resolve(StringOr(lj, "file", "", w), in_.baseDirectory),
                                                    Radiance(RGB(1.f), intensity, w)[0]);
        } else if (lj.contains("color")) {
          scene_.environment = EnvironmentMap::Constant(Radiance(color, intensity, w));
        } else {
          const std::string sky = StringOr(lj, "sky", "default", w);
          if (sky != "default") Fail(w + ".sky", "the only built-in sky is 'default'");
          scene_.environment = EnvironmentMap::DefaultSky(Radiance(RGB(1.f), intensity, w)[0]);
        }
      } else {
        Fail(w + ".type", "expected directional, point or environment, got '" + type + "'");
      }
    }
  }

  void ParseCamera() {
    CameraDesc& c = scene_.camera;
    if (doc_.contains("camera")) {
      const json& cj = doc_["camera"];
      const std::string w = "camera";
      CheckKeys(cj, w,
                {"projection", "azimuth", "elevation", "zoom", "position", "look_at", "up", "fov", "ortho_height",
                 "lens_radius", "focus_distance"});
      const std::string proj = StringOr(cj, "projection", "perspective", w);
      if (proj != "perspective" && proj != "orthographic")
        Fail(w + ".projection", "expected perspective or orthographic");
      c.projection = proj == "orthographic" ? Projection::Orthographic : Projection::Perspective;
      c.azimuth = NumberOr(cj, "azimuth", c.azimuth, w);
      c.elevation = NumberOr(cj, "elevation", c.elevation, w);
      c.zoom = NumberOr(cj, "zoom", c.zoom, w);
      if (!(c.zoom > 0.f)) Fail(w + ".zoom", "must be positive");
      c.fovY = NumberOr(cj, "fov", c.fovY, w);
      if (!(c.fovY > 0.f && c.fovY < 180.f)) Fail(w + ".fov", "must be between 0 and 180 degrees");
      c.orthoHeight = NumberOr(cj, "ortho_height", c.orthoHeight, w);
      c.lensRadius = NumberOr(cj, "lens_radius", c.lensRadius, w);
      c.focusDistance = NumberOr(cj, "focus_distance", c.focusDistance, w);
      if (c.lensRadius < 0.f || c.focusDistance < 0.f || c.orthoHeight < 0.f)
        Fail(w, "lens radius, focus distance and ortho height must not be negative");
      if (cj.contains("position") || cj.contains("look_at")) {
        if (!cj.contains("position") || !cj.contains("look_at"))
          Fail(w, "an explicit camera needs both position and look_at");
        c.autoFrame = false;
        c.position = Vector(cj["position"], w + ".position");
        c.lookAt = Vector(cj["look_at"], w + ".look_at");
        if (cj.contains("up")) c.up = Vector(cj["up"], w + ".up");
      }
    }
  }

  void ParseRender() {
    RenderSettings& r = scene_.render;
    if (doc_.contains("render")) {
      const json& rj = doc_["render"];
      const std::string w = "render";
      CheckKeys(rj, w,
                {"width", "height", "spp", "seed", "threads", "estimator", "max_bounces", "russian_roulette_depth",
                 "shadow_extinction_scale", "ray_march_step", "exposure", "tone_mapper", "background", "accelerator",
                 "leaf_level", "light_sampling", "sampler"});
      r.width = IntegerOr(rj, "width", r.width, w);
      r.height = IntegerOr(rj, "height", r.height, w);
      r.samplesPerPixel = IntegerOr(rj, "spp", r.samplesPerPixel, w);
      r.threads = IntegerOr(rj, "threads", r.threads, w);
      if (rj.contains("seed")) {
        if (!rj["seed"].is_number_unsigned()) Fail(w + ".seed", "expected a non-negative integer");
        r.integrator.seed = rj["seed"].get<uint64_t>();
      }
      const std::string est = StringOr(rj, "estimator", "delta", w);
      if (est != "delta" && est != "raymarch") Fail(w + ".estimator", "expected delta or raymarch");
      r.integrator.estimator = est == "raymarch" ? Estimator::RayMarching : Estimator::DeltaTracking;
      r.integrator.maxBounces = IntegerOr(rj, "max_bounces", r.integrator.maxBounces, w);
      r.integrator.russianRouletteDepth = IntegerOr(rj, "russian_roulette_depth", r.integrator.russianRouletteDepth, w);
      r.integrator.shadowExtinctionScale =
          NumberOr(rj, "shadow_extinction_scale", r.integrator.shadowExtinctionScale, w);
      r.integrator.rayMarchStep = NumberOr(rj, "ray_march_step", r.integrator.rayMarchStep, w);
      r.integrator.backgroundVisible = BoolOr(rj, "background", r.integrator.backgroundVisible, w);
      const std::string lights = StringOr(rj, "light_sampling", LightSamplingName(r.integrator.lightSampling), w);
      const std::optional<LightSampling> lightSampling = ParseLightSampling(lights);
      if (!lightSampling) Fail(w + ".light_sampling", "expected one, all or resampled, got '" + lights + "'");
      r.integrator.lightSampling = *lightSampling;
      const std::string sampler = StringOr(rj, "sampler", PixelSamplerName(r.integrator.sampler), w);
      const std::optional<PixelSampler> pixelSampler = ParsePixelSampler(sampler);
      if (!pixelSampler) Fail(w + ".sampler", "expected sobol or independent, got '" + sampler + "'");
      r.integrator.sampler = *pixelSampler;
      const std::string acc = StringOr(rj, "accelerator", "octree", w);
      AcceleratorSettings& a = r.accelerator;
      if (acc == "none")
        a.kind = MajorantKind::Global;
      else if (acc == "macrocell")
        a.kind = MajorantKind::Macrocell;
      else if (acc == "octree" || acc == "octree-voxelmax")
        a.kind = MajorantKind::Octree;
      else
        Fail(w + ".accelerator", "expected none, macrocell, octree or octree-voxelmax, got '" + acc + "'");
      a.grid.summary = acc == "octree-voxelmax" ? SummaryMode::VoxelValues : SummaryMode::CellRanges;
      a.grid.leafLevel = IntegerOr(rj, "leaf_level", a.grid.leafLevel, w);
      if (a.grid.leafLevel < -1 || a.grid.leafLevel >= kMaxGridLevels)
        Fail(w + ".leaf_level", "expected -1 (automatic) to " + std::to_string(kMaxGridLevels - 1));
      a.grid.threads = r.threads;
      r.exposure = NumberOr(rj, "exposure", r.exposure, w);
      const std::string tm = StringOr(rj, "tone_mapper", "filmic", w);
      if (tm != "filmic" && tm != "clamp" && tm != "off") Fail(w + ".tone_mapper", "expected filmic, clamp or off");
      r.toneMapper = tm == "clamp" ? ToneMapper::Clamp : tm == "off" ? ToneMapper::Off : ToneMapper::Filmic;
    }
  }

  json doc_;  // a copy: expanded in place (ExpandDocument)
  SceneInputs in_;
  Scene scene_;
  std::vector<HostVolume> volumes_;
  std::vector<std::string> volumeNames_;
  std::vector<std::optional<DerivedSpec>> derived_;  // per volume; empty for a volume read from a file
  std::set<int> readProxies_;
};

}  // namespace

namespace {

// The deepest nesting of arrays and objects in JSON text, outside strings
// and comments (an unbalanced text is the parser's to report).
int NestingDepth(const std::string& text) {
  int depth = 0, deepest = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"') {
      for (++i; i < text.size() && text[i] != '"'; ++i)
        if (text[i] == '\\') ++i;
    } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {
      i = text.find('\n', i);
      if (i == std::string::npos) break;
    } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
      i = text.find("*/", i + 2);
      if (i == std::string::npos) break;
      ++i;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

}  // namespace

json ParseJson(const std::string& text, const std::string& where) {
  if (const int depth = NestingDepth(text); depth > kMaxJsonDepth)
    throw InputError(where + ": JSON nested " + std::to_string(depth) + " levels deep (at most " +
                     std::to_string(kMaxJsonDepth) + ")");
  try {
    return json::parse(text, nullptr, true, /*ignore_comments=*/true);
  } catch (const json::exception& e) {  // a syntax error, or a number out of range ("1e999")
    throw InputError(where + ": not valid JSON (" + e.what() + ")");
  }
}

json ReadJsonFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  return ParseJson(text.str(), path);
}

Scene SceneFromJson(const json& doc, SceneInputs inputs) { return Parser(doc, std::move(inputs)).Parse(); }

std::string PresetPath(const std::string& presetDirectory, const std::string& name) {
  fs::path p = fs::path(presetDirectory) / (name + ".json");
  if (fs::exists(p)) return p.string();
  std::string list;
  if (fs::is_directory(presetDirectory))
    for (const auto& e : fs::directory_iterator(presetDirectory))
      if (e.path().extension() == ".json") list += (list.empty() ? "" : ", ") + e.path().stem().string();
  throw InputError("no preset named '" + name + "' (presets: " + (list.empty() ? "none found" : list) + ")");
}

std::optional<LightSampling> ParseLightSampling(const std::string& name) {
  if (name == "one") return LightSampling::One;
  if (name == "all") return LightSampling::All;
  if (name == "resampled") return LightSampling::Resampled;
  return std::nullopt;
}

const char* LightSamplingName(LightSampling mode) {
  switch (mode) {
    case LightSampling::One:
      return "one";
    case LightSampling::All:
      return "all";
    case LightSampling::Resampled:
      return "resampled";
  }
  return "one";
}

std::optional<PixelSampler> ParsePixelSampler(const std::string& name) {
  if (name == "sobol") return PixelSampler::Sobol;
  if (name == "independent") return PixelSampler::Independent;
  return std::nullopt;
}

const char* PixelSamplerName(PixelSampler sampler) {
  return sampler == PixelSampler::Independent ? "independent" : "sobol";
}

}  // namespace mmrtm
