// Renders a head CT with vtkMultiMaterialVolumeMapper and the ct-bone preset
// from C++. Usage: RenderHeadCT VOLUME.nrrd [OUTPUT.png]  (no OUTPUT: a window
// that refines while it is idle). Built with the project; run by the tests.
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkNrrdReader.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>
#include <vtkWindowToImageFilter.h>

#include "vtkMultiMaterialProperty.h"
#include "vtkMultiMaterialVolumeMapper.h"

int main(int argc, char* argv[])
{
  if (argc < 2)
  {
    std::cerr << "usage: " << argv[0] << " VOLUME.nrrd [OUTPUT.png]\n";
    return 2;
  }
  vtkNew<vtkNrrdReader> reader;
  reader->SetFileName(argv[1]);
  vtkNew<vtkMultiMaterialVolumeMapper> mapper;
  mapper->SetInputConnection(reader->GetOutputPort());
  vtkNew<vtkMultiMaterialProperty> materials;
  if (!materials->SetPreset("ct-bone"))
    return 1;
  mapper->SetMultiMaterialProperty(materials);
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(vtkNew<vtkVolumeProperty>());
  vtkNew<vtkRenderer> renderer;
  renderer->AddVolume(volume);
  vtkNew<vtkRenderWindow> window;
  window->AddRenderer(renderer);
  window->SetSize(400, 400);
  renderer->ResetCamera();
  renderer->GetActiveCamera()->Elevation(-90); // this CT's face is at +y: look at it, head up
  renderer->GetActiveCamera()->SetViewUp(0, 0, 1);
  renderer->GetActiveCamera()->Azimuth(180);
  renderer->ResetCamera();

  if (argc > 2) // off screen: 32 samples per pixel, then the PNG
  {
    window->SetOffScreenRendering(1);
    mapper->SetSamplesPerRender(8);
    mapper->SetMaximumSamples(32);
    for (int i = 0; i < 4; ++i)
      window->Render();
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(window);
    vtkNew<vtkPNGWriter> writer;
    writer->SetFileName(argv[2]);
    writer->SetInputConnection(grab->GetOutputPort());
    writer->Write();
    return mapper->GetAccumulatedSamples() == 32 ? 0 : 1;
  }
  // On screen: a repeating timer renders again, and each render adds samples.
  vtkNew<vtkRenderWindowInteractor> interactor;
  interactor->SetRenderWindow(window);
  interactor->Initialize();
  vtkNew<vtkCallbackCommand> refine;
  refine->SetClientData(window.Get());
  refine->SetCallback([](vtkObject*, unsigned long, void* w, void*) { static_cast<vtkRenderWindow*>(w)->Render(); });
  interactor->AddObserver(vtkCommand::TimerEvent, refine);
  interactor->CreateRepeatingTimer(50);
  interactor->Start();
  return 0;
}
