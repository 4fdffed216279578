// VTK regression image tests of vtkMultiMaterialVolumeMapper, run headless
// (xvfb-run) like VTK's own: a fixed seed and sample count make the image
// deterministic, and vtkRegressionTestImage compares it with a baseline in
// Data/Baselines/VTK that was looked at.
//
//   TestMultiMaterialVolumeMapper CASE -D DATA_DIR -V BASELINE.png -T TEMP_DIR
//
// CASE: "ct-bone" (a head CT with a bone transfer function), "oblique"
// (the same volume turned and stretched by the vtkVolume's matrix) or
// "labels" (a CT angiography whose vessel label map gives per-label colours
// and opacities through SetMaskInput and the property's label functions) or
// "rgba" (a 4-component unsigned char volume, IndependentComponents off: RGB
// is the colour, the fourth component goes through the opacity function) or
// "mesh" (the head CT with an opaque sphere through it: the sphere hides the
// volume behind it, the bone in front hides the sphere, as camera rays stop
// at the depth buffer of the opaque geometry).
//
// VTK 9.1's vtkRegressionTestImage tolerates a difference of up to 105 of
// 255 in a channel (a whole background of another colour passes), so the
// test also compares the image with the baseline itself: the render is
// deterministic, so nearly every pixel must agree to 3 %.
//
// Before the comparison, the ct-bone, oblique and rgba scenes are rendered with VTK's own
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
#include <vtkSmartPointer.h>
#include <vtkNew.h>
#include <vtkFixedPointVolumeRayCastMapper.h>
#include <vtkActor.h>
#include <vtkNIFTIImageReader.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkSphereSource.h>
#include <vtkNrrdReader.h>
#include <vtkXMLImageDataReader.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>
#include <vtkPointData.h>
#include <vtkPNGReader.h>
#include <vtkPNGWriter.h>
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
vtkSmartPointer<vtkUnsignedCharArray> Pixels(vtkRenderWindow* window)
{
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->ReadFrontBufferOff();
  grab->Update();
  return vtkUnsignedCharArray::SafeDownCast(grab->GetOutput()->GetPointData()->GetScalars());
}

// The fraction of pixels whose colour differs from the baseline's by more
// than 3 % in a channel; 1 when the sizes differ or the baseline is missing.
double FractionDifferent(vtkRenderWindow* window, const std::string& baseline)
{
  vtkNew<vtkPNGReader> reader;
  if (!reader->CanReadFile(baseline.c_str()))
    return 1.0;
  reader->SetFileName(baseline.c_str());
  reader->Update();
  vtkDataArray* expected = reader->GetOutput()->GetPointData()->GetScalars();
  vtkSmartPointer<vtkUnsignedCharArray> actual = Pixels(window);
  if (!expected || expected->GetNumberOfTuples() != actual->GetNumberOfTuples())
    return 1.0;
  const int ne = expected->GetNumberOfComponents(), na = actual->GetNumberOfComponents();
  vtkIdType different = 0;
  for (vtkIdType i = 0; i < actual->GetNumberOfTuples(); ++i)
  {
    bool d = false;
    for (int c = 0; c < 3; ++c)
      d = d || std::abs(expected->GetComponent(i, std::min(c, ne - 1)) - actual->GetValue(i * na + c)) > 0.03 * 255;
    different += d;
  }
  return static_cast<double>(different) / actual->GetNumberOfTuples();
}

// Which pixels differ from the background colour.
std::vector<bool> Coverage(vtkRenderWindow* window, const double background[3])
{
  vtkSmartPointer<vtkUnsignedCharArray> pixels = Pixels(window);
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

  const bool labels = testCase == "labels";
  vtkNew<vtkNrrdReader> nrrd;
  nrrd->SetFileName((data + "/ct_head_headsq.nrrd").c_str());
  vtkNew<vtkNIFTIImageReader> angio, vessels;
  angio->SetFileName((data + "/cta_chest_aorta.nii.gz").c_str());
  vessels->SetFileName((data + "/cta_chest_aorta_labels.nii.gz").c_str());
  const bool rgba = testCase == "rgba";
  vtkNew<vtkXMLImageDataReader> vase;
  vase->SetFileName((data + "/vase_4comp.vti").c_str());
  vtkAlgorithm* reader = labels ? static_cast<vtkAlgorithm*>(angio) : rgba ? static_cast<vtkAlgorithm*>(vase) : nrrd;

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

  if (rgba)
  {
    opacity->RemoveAllPoints();
    opacity->AddPoint(80, 0.0);
    opacity->AddPoint(160, 1.0);
    property->IndependentComponentsOff();
  }
  if (labels)
  {
    // Hounsfield units: faint bone for context; labels 1-6 (arteries) red,
    // 7 (a vertebra) ivory, opaque wherever the label is.
    opacity->RemoveAllPoints();
    opacity->AddPoint(200, 0.0);
    opacity->AddPoint(600, 0.05);
    opacity->AddPoint(1500, 0.15);
    vessels->Update();
    mapper->SetMaskInput(vessels->GetOutput());
    mapper->SetMaskTypeToLabelMap();
    vtkNew<vtkPiecewiseFunction> solid;
    solid->AddPoint(-1000, 0.9);
    solid->AddPoint(3000, 0.9);
    vtkNew<vtkColorTransferFunction> red, ivory;
    red->AddRGBPoint(-1000, 0.85, 0.12, 0.1);
    ivory->AddRGBPoint(-1000, 0.93, 0.88, 0.78);
    for (int label = 1; label <= 7; ++label)
    {
      property->SetLabelScalarOpacity(label, solid);
      property->SetLabelColor(label, label == 7 ? ivory.Get() : red.Get());
    }
  }
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
  else if (testCase != "ct-bone" && !labels && !rgba && testCase != "mesh")
  {
    std::cerr << "unknown case " << testCase << "\n";
    return 2;
  }

  vtkNew<vtkRenderer> renderer;
  renderer->AddVolume(volume);
  vtkNew<vtkSphereSource> sphere;
  vtkNew<vtkPolyDataMapper> sphereMapper;
  vtkNew<vtkActor> sphereActor;
  if (testCase == "mesh")
  {
    // Through the middle of the head, reaching out of the skull.
    reader->Update();
    double center[3];
    vtkImageData::SafeDownCast(reader->GetOutputDataObject(0))->GetCenter(center);
    sphere->SetCenter(center[0] + 40, center[1], center[2] - 30);
    sphere->SetRadius(45);
    sphere->SetThetaResolution(48);
    sphere->SetPhiResolution(48);
    sphereMapper->SetInputConnection(sphere->GetOutputPort());
    sphereActor->SetMapper(sphereMapper);
    sphereActor->GetProperty()->SetColor(0.2, 0.8, 0.3);
    renderer->AddActor(sphereActor);
  }
  renderer->SetBackground(0.15, 0.25, 0.55);
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->AddRenderer(renderer);
  window->SetSize(256, 256);
  renderer->ResetCamera();
  if (labels)
  {
    // From the front, head up (VTK's NIfTI reader keeps the voxel axes:
    // anterior toward +y, superior toward +z).
    renderer->GetActiveCamera()->Elevation(90);
    renderer->GetActiveCamera()->SetViewUp(0, 0, 1);
  }
  else
  {
    renderer->GetActiveCamera()->Elevation(-80);  // the face (the data's -z side) toward the camera
  }
  renderer->GetActiveCamera()->OrthogonalizeViewUp();
  renderer->ResetCamera();
  const double background[3] = { 0.15, 0.25, 0.55 };  // unlike any grey, so dark shading still counts

  if (labels || testCase == "mesh")
  {
    window->Render();  // label maps; geometry: baseline only
  }
  else
  {
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
  }

  if (mapper->GetAccumulatedSamples() != 32)
  {
    std::cerr << "expected 32 samples, got " << mapper->GetAccumulatedSamples() << "\n";
    return 1;
  }
  const int result = vtkRegressionTestImageThreshold(window, 0.05);
  const char* baseline = testing->GetValidImageFileName();
  // The image itself, in the temporary folder, to look at (and to become
  // the baseline after that).
  if (testing->GetTempDirectory() && baseline)
  {
    const std::string name = std::string(baseline).substr(std::string(baseline).find_last_of('/') + 1);
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(window);
    grab->ReadFrontBufferOff();
    vtkNew<vtkPNGWriter> writer;
    writer->SetFileName((std::string(testing->GetTempDirectory()) + "/" + name).c_str());
    writer->SetInputConnection(grab->GetOutputPort());
    writer->Write();
  }
  const double different = FractionDifferent(window, baseline ? baseline : "");
  std::cout << "pixels different from the baseline by more than 3 %: " << 100.0 * different << " %\n";
  return result == vtkRegressionTester::PASSED && different < 0.01 ? 0 : 1;
}
