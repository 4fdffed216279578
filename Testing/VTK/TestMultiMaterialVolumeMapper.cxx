// VTK regression image tests of vtkMultiMaterialVolumeMapper, run headless
// (xvfb-run) like VTK's own: a fixed seed and sample count make the image
// deterministic, and vtkRegressionTestImage compares it with a baseline in
// Data/Baselines/VTK that was looked at.
//
//   TestMultiMaterialVolumeMapper CASE -D DATA_DIR -V BASELINE.png -T TEMP_DIR
//
// CASE: "ct-bone" (a head CT with a bone transfer function) or "oblique"
// (the same volume turned and stretched by the vtkVolume's matrix).
//
// Before the comparison, the same scene is rendered with VTK's own
// vtkFixedPointVolumeRayCastMapper: the pixels the volume covers must be
// nearly the same (intersection over union), which checks the camera, the
// volume's geometry and matrix, and the depth of the composited image
// against VTK itself, independently of the baseline.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>
#include <iostream>
#include <string>

#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkFixedPointVolumeRayCastMapper.h>
#include <vtkNrrdReader.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>
#include <vtkPointData.h>
#include <vtkPiecewiseFunction.h>
#include <vtkRegressionTestImage.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTesting.h>
#include <vtkTransform.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>

#include "vtkMultiMaterialVolumeMapper.h"

namespace
{
// Which pixels differ from the background colour.
std::vector<bool> Coverage(vtkRenderWindow* window, const double background[3])
{
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkUnsignedCharArray* pixels = vtkUnsignedCharArray::SafeDownCast(grab->GetOutput()->GetPointData()->GetScalars());
  std::vector<bool> covered(pixels->GetNumberOfTuples());
  const int n = pixels->GetNumberOfComponents();
  for (vtkIdType i = 0; i < pixels->GetNumberOfTuples(); ++i)
  {
    double d = 0;
    for (int c = 0; c < 3; ++c)
      d = std::max(d, std::abs(pixels->GetValue(i * n + c) / 255.0 - background[c]));
    covered[i] = d > 0.08;
  }
  return covered;
}
}

int main(int argc, char* argv[])
{
  if (argc < 2)
  {
    std::cerr << "usage: " << argv[0] << " ct-bone|oblique -D DATA -V BASELINE -T TEMP\n";
    return 2;
  }
  const std::string testCase = argv[1];
  vtkNew<vtkTesting> testing;
  testing->AddArguments(argc, const_cast<const char**>(argv));
  const std::string data = testing->GetDataRoot() ? testing->GetDataRoot() : ".";

  vtkNew<vtkNrrdReader> reader;
  reader->SetFileName((data + "/ct_head_headsq.nrrd").c_str());

  vtkNew<vtkMultiMaterialVolumeMapper> mapper;
  mapper->SetInputConnection(reader->GetOutputPort());
  mapper->SetSamplesPerRender(32);
  mapper->SetMaximumSamples(32);
  mapper->SetSeed(1);
  mapper->SetNumberOfThreads(2);
  mapper->SetBackendToCPU();

  // Bone: the headsq values run 0..3926 (no Hounsfield offset).
  vtkNew<vtkPiecewiseFunction> opacity;
  opacity->AddPoint(1100, 0.0);
  opacity->AddPoint(1500, 0.6);
  opacity->AddPoint(2500, 1.0);
  vtkNew<vtkColorTransferFunction> color;
  color->AddRGBPoint(1100, 0.85, 0.55, 0.45);
  color->AddRGBPoint(1800, 0.95, 0.88, 0.78);
  color->AddRGBPoint(2500, 1.0, 1.0, 0.95);
  vtkNew<vtkVolumeProperty> property;
  property->SetScalarOpacity(opacity);
  property->SetColor(color);
  property->ShadeOn();
  property->SetAmbient(0.3);

  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(property);
  if (testCase == "oblique")
  {
    // Turned 30 degrees about an oblique axis and stretched 1.5x along x.
    vtkNew<vtkTransform> t;
    t->RotateWXYZ(30, 1, 1, 0);
    t->Scale(1.5, 1.0, 1.0);
    volume->SetUserTransform(t);
  }
  else if (testCase != "ct-bone")
  {
    std::cerr << "unknown case " << testCase << "\n";
    return 2;
  }

  vtkNew<vtkRenderer> renderer;
  renderer->AddVolume(volume);
  renderer->SetBackground(0.1, 0.1, 0.15);
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->AddRenderer(renderer);
  window->SetSize(256, 256);
  renderer->ResetCamera();
  renderer->GetActiveCamera()->Elevation(-80);  // the face (the data's -z side) toward the camera
  renderer->GetActiveCamera()->OrthogonalizeViewUp();
  renderer->ResetCamera();
  const double background[3] = { 0.1, 0.1, 0.15 };

  // VTK's software ray caster on the same volume, property and camera.
  vtkNew<vtkFixedPointVolumeRayCastMapper> reference;
  reference->SetInputConnection(reader->GetOutputPort());
  volume->SetMapper(reference);
  window->Render();
  const std::vector<bool> expected = Coverage(window, background);
  volume->SetMapper(mapper);
  window->Render();
  const std::vector<bool> covered = Coverage(window, background);
  size_t both = 0, either = 0, ours = 0;
  for (size_t i = 0; i < covered.size(); ++i)
  {
    both += covered[i] && expected[i];
    either += covered[i] || expected[i];
    ours += covered[i];
  }
  const double iou = either ? static_cast<double>(both) / either : 0.0;
  std::cout << "coverage: " << ours << " pixels, intersection over union with vtkFixedPointVolumeRayCastMapper "
            << iou << "\n";
  if (ours < covered.size() / 20 || iou < 0.8)
  {
    std::cerr << "the volume does not cover the pixels VTK's own mapper covers\n";
    return 1;
  }

  if (mapper->GetAccumulatedSamples() != 32)
  {
    std::cerr << "expected 32 samples, got " << mapper->GetAccumulatedSamples() << "\n";
    return 1;
  }
  const int result = vtkRegressionTestImageThreshold(window, 0.05);
  return result == vtkRegressionTester::PASSED ? 0 : 1;
}
