#include "vtkMultiMaterialProperty.h"

#include <cstdlib>
#include <exception>

#if defined(__unix__) || defined(__APPLE__)
#include <dlfcn.h>
#endif
#include <sys/stat.h>

#include <nlohmann/json.hpp>
#include <vtkObjectFactory.h>

#include "scene_json.h"

vtkStandardNewMacro(vtkMultiMaterialProperty);

struct vtkMultiMaterialProperty::Internals
{
  nlohmann::json Document = nlohmann::json::object();
};

vtkMultiMaterialProperty::vtkMultiMaterialProperty()
  : Internal(new Internals)
{
}

vtkMultiMaterialProperty::~vtkMultiMaterialProperty() = default;

namespace
{
// The folder of the shared library this code is in ("" if unknown).
std::string LibraryDirectory()
{
#if defined(__unix__) || defined(__APPLE__)
  Dl_info info;
  if (dladdr(reinterpret_cast<void*>(&LibraryDirectory), &info) && info.dli_fname)
  {
    std::string path = info.dli_fname;
    const auto slash = path.rfind('/');
    return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
  }
#endif
  return {};
}

bool IsDirectory(const std::string& path)
{
  struct stat s;
  return ::stat(path.c_str(), &s) == 0 && S_ISDIR(s.st_mode);
}
}

std::string vtkMultiMaterialProperty::GetPresetDirectory()
{
  if (const char* env = std::getenv("MMRTM_DATA_DIR"))
    return std::string(env) + "/presets";
  // Installed: beside the library (the wheel's package folder), or in
  // share/mmrtm of an install tree; else the source tree's Data folder.
  const std::string library = LibraryDirectory();
  if (!library.empty())
  {
    for (const char* relative : { "/presets", "/../share/mmrtm/presets" })
    {
      if (IsDirectory(library + relative))
        return library + relative;
    }
  }
  return std::string(MMRTM_DATA_DIR) + "/presets";
}

namespace
{
// As vtkSetMacro: an unchanged value leaves the modification time.
void SetDocument(vtkMultiMaterialProperty* self, nlohmann::json& document, nlohmann::json next)
{
  if (next == document)
    return;
  document = std::move(next);
  self->Modified();
}

// Runs `change` on a copy of the document; an exception (a missing file,
// bad JSON) becomes a VTK error naming the problem, and the document stays
// as it was.
template <typename Change>
bool ChangeDocument(vtkMultiMaterialProperty* self, nlohmann::json& document, Change change)
{
  nlohmann::json next = document;
  try
  {
    change(next);
  }
  catch (const std::exception& e)
  {
    vtkErrorWithObjectMacro(self, << e.what());
    return false;
  }
  SetDocument(self, document, std::move(next));
  return true;
}

nlohmann::json ParseJson(const char* text)
{
  return mmrtm::ParseJson(text ? text : "", "scene JSON");
}
}

bool vtkMultiMaterialProperty::SetPreset(const char* name)
{
  return ChangeDocument(this, this->Internal->Document,
    [name](nlohmann::json& doc)
    { doc = mmrtm::ReadJsonFile(mmrtm::PresetPath(GetPresetDirectory(), name ? name : "")); });
}

bool vtkMultiMaterialProperty::SetSceneFile(const char* path)
{
  return ChangeDocument(
    this, this->Internal->Document, [path](nlohmann::json& doc) { doc = mmrtm::ReadJsonFile(path ? path : ""); });
}

bool vtkMultiMaterialProperty::SetSceneJSON(const char* text)
{
  return ChangeDocument(this, this->Internal->Document, [text](nlohmann::json& doc) { doc = ParseJson(text); });
}

bool vtkMultiMaterialProperty::MergeSceneJSON(const char* text)
{
  return ChangeDocument(
    this, this->Internal->Document, [text](nlohmann::json& doc) { doc.merge_patch(ParseJson(text)); });
}

std::string vtkMultiMaterialProperty::GetSceneJSON()
{
  return this->Internal->Document.dump(2);
}

void vtkMultiMaterialProperty::SetScene(const nlohmann::json& scene)
{
  SetDocument(this, this->Internal->Document, scene);
}

const nlohmann::json& vtkMultiMaterialProperty::GetScene() const
{
  return this->Internal->Document;
}

void vtkMultiMaterialProperty::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Scene: " << this->Internal->Document.dump() << "\n";
}
