// PRIVATE to MMRTM::Rendering: a vtkVolumeProperty's component functions,
// read without changing the property.
//
// vtkVolumeProperty::GetScalarOpacity, GetRGBTransferFunction,
// GetGrayTransferFunction and GetStoredGradientOpacity create a default
// function where the caller set none (the colour getters also call
// Modified()), so a mapper that asks them edits its input: VTK's own
// mappers do, and the application's property then holds functions it never
// made, with a new MTime after the first render. These return the function
// the property holds, or VTK's default for it as a function of their own
// (the same nodes the getter would create), and leave the property as it
// was.
#ifndef mmrtmVolumePropertyFunctions_h
#define mmrtmVolumePropertyFunctions_h

#include <vtkSmartPointer.h>

class vtkColorTransferFunction;
class vtkPiecewiseFunction;
class vtkVolumeProperty;

namespace mmrtm
{

// The function the property holds for `component`, or null where it holds
// none (where VTK's getter would create one).
vtkPiecewiseFunction* HeldScalarOpacity(vtkVolumeProperty* property, int component);
vtkColorTransferFunction* HeldRGBTransferFunction(vtkVolumeProperty* property, int component);
vtkPiecewiseFunction* HeldGrayTransferFunction(vtkVolumeProperty* property, int component);
vtkPiecewiseFunction* HeldGradientOpacity(vtkVolumeProperty* property, int component);

// VTK's defaults, as its getters create them: scalar opacity 1 over
// [0, 1024]; colour black at 0 to white at 1024 (RGB or grey).
vtkSmartPointer<vtkPiecewiseFunction> DefaultScalarOpacity();
vtkSmartPointer<vtkColorTransferFunction> DefaultRGBTransferFunction();
vtkSmartPointer<vtkPiecewiseFunction> DefaultGrayTransferFunction();

} // namespace mmrtm

#endif
