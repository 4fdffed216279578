// The environment texture as the tracer's environment map, converted
// again only when the texture, its image or the intensity changed.
#include "vtkMultiMaterialVolumeMapperInternals.h"

#include <algorithm>
#include <cmath>

#include <vtkDataArray.h>
#include <vtkPointData.h>

void vtkMultiMaterialVolumeMapper::Internals::UpdateEnvironment()
{
  Internals& in = *this;
  vtkTexture* texture = in.EnvironmentTexture;
  vtkImageData* image = texture ? vtkImageData::SafeDownCast(texture->GetInput()) : nullptr;
  if (texture && texture->GetInputAlgorithm())
  {
    texture->GetInputAlgorithm()->Update();
    image = vtkImageData::SafeDownCast(texture->GetInput());
  }
  const vtkMTimeType time = image ? std::max(image->GetMTime(), texture->GetMTime()) : 0;
  if (time == in.EnvironmentTime && Self->EnvironmentIntensity == in.EnvironmentScale)
    return;
  in.EnvironmentTime = time;
  in.EnvironmentScale = Self->EnvironmentIntensity;
  in.Environment.reset();
  if (!image)
    return;
  vtkDataArray* a = image->GetPointData()->GetScalars();
  const int* d = image->GetDimensions();
  if (!a || a->GetNumberOfComponents() < 3 || d[2] != 1 || d[0] < 1 || d[1] < 1)
  {
    vtkErrorWithObjectMacro(Self, "the environment texture needs a 2D image with 3 or 4 components");
    return;
  }
  // sRGB bytes to linear; float data is radiance already. VTK's rows run
  // bottom up, the environment's from the zenith down.
  const bool bytes = a->GetDataType() == VTK_UNSIGNED_CHAR;
  auto linear = [bytes](double v)
  {
    if (!bytes)
      return static_cast<float>(std::max(v, 0.0));
    v /= 255.0;
    return static_cast<float>(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
  };
  std::vector<mmrtm::RGB> texels(static_cast<size_t>(d[0]) * d[1]);
  const float scale = static_cast<float>(Self->EnvironmentIntensity);
  for (int y = 0; y < d[1]; ++y)
    for (int x = 0; x < d[0]; ++x)
    {
      const vtkIdType i = x + static_cast<vtkIdType>(d[0]) * (d[1] - 1 - y);
      texels[static_cast<size_t>(y) * d[0] + x] = mmrtm::RGB(linear(a->GetComponent(i, 0)) * scale,
        linear(a->GetComponent(i, 1)) * scale, linear(a->GetComponent(i, 2)) * scale);
    }
  in.Environment = std::make_shared<mmrtm::EnvironmentMap>(d[0], d[1], std::move(texels));
}
