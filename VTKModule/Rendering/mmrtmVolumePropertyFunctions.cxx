#include "mmrtmVolumePropertyFunctions.h"

#include <vtkColorTransferFunction.h>
#include <vtkPiecewiseFunction.h>
#include <vtkVolumeProperty.h>

namespace mmrtm
{
namespace
{

// The property keeps its functions in protected arrays, and VTK 9.1 has no
// getter that does not create one. A pointer to member formed in a
// subclass reads them from any vtkVolumeProperty (the subclass is never
// instantiated); the arrays are alike from VTK 9.1 to 9.6.
struct HeldFunctions : vtkVolumeProperty
{
  template <class F>
  static F* Get(vtkVolumeProperty* property, F* (vtkVolumeProperty::*array)[VTK_MAX_VRCOMP], int component)
  {
    if (!property || component < 0 || component >= VTK_MAX_VRCOMP)
      return nullptr;
    return (property->*array)[component];
  }
  static vtkPiecewiseFunction* Opacity(vtkVolumeProperty* p, int c) { return Get(p, &HeldFunctions::ScalarOpacity, c); }
  static vtkColorTransferFunction* RGB(vtkVolumeProperty* p, int c)
  {
    return Get(p, &HeldFunctions::RGBTransferFunction, c);
  }
  static vtkPiecewiseFunction* Gray(vtkVolumeProperty* p, int c)
  {
    return Get(p, &HeldFunctions::GrayTransferFunction, c);
  }
  static vtkPiecewiseFunction* Gradient(vtkVolumeProperty* p, int c)
  {
    return Get(p, &HeldFunctions::GradientOpacity, c);
  }
};

} // namespace

vtkPiecewiseFunction* HeldScalarOpacity(vtkVolumeProperty* property, int component)
{
  return HeldFunctions::Opacity(property, component);
}

vtkColorTransferFunction* HeldRGBTransferFunction(vtkVolumeProperty* property, int component)
{
  return HeldFunctions::RGB(property, component);
}

vtkPiecewiseFunction* HeldGrayTransferFunction(vtkVolumeProperty* property, int component)
{
  return HeldFunctions::Gray(property, component);
}

vtkPiecewiseFunction* HeldGradientOpacity(vtkVolumeProperty* property, int component)
{
  return HeldFunctions::Gradient(property, component);
}

vtkSmartPointer<vtkPiecewiseFunction> DefaultScalarOpacity()
{
  auto f = vtkSmartPointer<vtkPiecewiseFunction>::New();
  f->AddPoint(0, 1.0);
  f->AddPoint(1024, 1.0);
  return f;
}

vtkSmartPointer<vtkColorTransferFunction> DefaultRGBTransferFunction()
{
  auto f = vtkSmartPointer<vtkColorTransferFunction>::New();
  f->AddRGBPoint(0, 0.0, 0.0, 0.0);
  f->AddRGBPoint(1024, 1.0, 1.0, 1.0);
  return f;
}

vtkSmartPointer<vtkPiecewiseFunction> DefaultGrayTransferFunction()
{
  auto f = vtkSmartPointer<vtkPiecewiseFunction>::New();
  f->AddPoint(0, 0.0);
  f->AddPoint(1024, 1.0);
  return f;
}

} // namespace mmrtm
