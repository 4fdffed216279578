/**
 * @class   vtkMultiMaterialProperty
 * @brief   what vtkVolumeProperty cannot say: materials, BSDF parameters,
 *          material transfer functions, lights, presets
 *
 * A vtkMultiMaterialProperty holds an MM-RTM scene description (the JSON
 * scene format of Documentation/scene-format.md): materials with density,
 * albedo, roughness, metalness, surface probability, emission and phase
 * anisotropy, the five transfer-function types over proxy volumes, derived
 * proxies, label materials, lights and an environment. Given to
 * vtkMultiMaterialVolumeMapper::SetMultiMaterialProperty, it replaces the
 * translation of the vtkVolumeProperty. In it, the proxy "scalars" is the
 * mapper's input and "labels" its mask; the camera and the image size come
 * from VTK; the lights come from the description when it has "lights", else
 * from the renderer.
 *
 * The presets of Data/presets (ct-bone, ct-soft-tissue, ct-angio-labels,
 * ct-organs, mri) are applied with SetPreset; the folder is
 * MMRTM_DATA_DIR/presets when that environment variable is set, else the
 * installed presets (beside the library in the Python wheel, in
 * share/mmrtm/presets of an install tree), else the source tree's.
 *
 * As VTK's Set methods do, a setter that leaves the description as it was
 * (the same JSON value) does not modify the property: a mapper rendering
 * it goes on accumulating.
 */
#ifndef vtkMultiMaterialProperty_h
#define vtkMultiMaterialProperty_h

#include "mmrtmRenderingModule.h" // for export macro
#include "vtkObject.h"

#include <memory> // for std::unique_ptr
#include <string> // for std::string

#ifndef __VTK_WRAP__
#include <nlohmann/json_fwd.hpp> // for nlohmann::json
#endif

class MMRTMRENDERING_EXPORT vtkMultiMaterialProperty : public vtkObject
{
public:
  static vtkMultiMaterialProperty* New();
  vtkTypeMacro(vtkMultiMaterialProperty, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Loads preset `name` (Data/presets/NAME.json). Returns false, with an
   * error naming the presets there, when it does not exist.
   */
  bool SetPreset(const char* name);

  /**
   * Loads a scene file. Returns false, with an error naming the file and
   * the problem, when it cannot be read.
   */
  bool SetSceneFile(const char* path);

  /**
   * Sets the description from JSON text. Returns false, with an error, when
   * the text is not JSON.
   */
  bool SetSceneJSON(const char* json);

  /**
   * Merges JSON text over the description (RFC 7396 merge patch), e.g.
   * '{"materials": {"bone": {"roughness": 0.2}}}'.
   */
  bool MergeSceneJSON(const char* json);

  /**
   * The description as JSON text.
   */
  std::string GetSceneJSON();

#ifndef __VTK_WRAP__
  /**
   * The description as a JSON value, set and read without going through
   * text (C++: an editor that changes it on every drag, and the mapper).
   * SetScene, as the other setters, leaves the modification time when the
   * value is the one held.
   */
  void SetScene(const nlohmann::json& scene);
  const nlohmann::json& GetScene() const;
#endif

  /**
   * The folder presets are read from.
   */
  static std::string GetPresetDirectory();

protected:
  vtkMultiMaterialProperty();
  ~vtkMultiMaterialProperty() override;

private:
  vtkMultiMaterialProperty(const vtkMultiMaterialProperty&) = delete;
  void operator=(const vtkMultiMaterialProperty&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
