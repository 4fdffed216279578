#include "vtkMultiMaterialProperty.h"

#include <cstdlib>
#include <exception>

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

std::string vtkMultiMaterialProperty::GetPresetDirectory()
{
  if (const char* env = std::getenv("MMRTM_DATA_DIR"))
    return std::string(env) + "/presets";
  return std::string(MMRTM_DATA_DIR) + "/presets";
}

bool vtkMultiMaterialProperty::SetPreset(const char* name)
{
  try
  {
    this->Internal->Document =
      mmrtm::ReadJsonFile(mmrtm::PresetPath(GetPresetDirectory(), name ? name : ""));
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< e.what());
    return false;
  }
  this->Modified();
  return true;
}

bool vtkMultiMaterialProperty::SetSceneFile(const char* path)
{
  try
  {
    this->Internal->Document = mmrtm::ReadJsonFile(path ? path : "");
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< e.what());
    return false;
  }
  this->Modified();
  return true;
}

bool vtkMultiMaterialProperty::SetSceneJSON(const char* text)
{
  try
  {
    this->Internal->Document = nlohmann::json::parse(text ? text : "", nullptr, true, true);
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro("not JSON: " << e.what());
    return false;
  }
  this->Modified();
  return true;
}

bool vtkMultiMaterialProperty::MergeSceneJSON(const char* text)
{
  try
  {
    this->Internal->Document.merge_patch(nlohmann::json::parse(text ? text : "", nullptr, true, true));
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro("not JSON: " << e.what());
    return false;
  }
  this->Modified();
  return true;
}

std::string vtkMultiMaterialProperty::GetSceneJSON()
{
  return this->Internal->Document.dump(2);
}

void vtkMultiMaterialProperty::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Scene: " << this->Internal->Document.dump() << "\n";
}
