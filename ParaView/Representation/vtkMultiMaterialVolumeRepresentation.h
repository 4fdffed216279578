/**
 * @class   vtkMultiMaterialVolumeRepresentation
 * @brief   ParaView's volume representation of image data, path traced
 *          with MM-RTM
 *
 * The representation "Path Traced (MM-RTM)" of image data: ParaView's
 * UniformGridVolumeRepresentation (its colour and opacity transfer
 * functions, its volume property, its array selection) with the path
 * tracer's mapper in place of the smart volume mapper. The mapper
 * translates the vtkVolumeProperty itself (the one translation every
 * front end uses), or renders a preset or scene file's materials instead.
 *
 * Under MPI (pvbatch, pvserver) every process asks for the whole volume and
 * renders its own samples of the whole image; the films are averaged and
 * the first process draws (vtkSampleParallelVolumeMapper). Before each
 * render (the renderer's StartEvent, which every process that renders the
 * view reaches whether or not this representation is visible; ParaView
 * sends hidden representations no render request), the processes agree
 * whether all of them will render this representation's mapper; if any
 * will not (its actor hidden there, its outline drawn instead, no data
 * there), each renders alone this time, so no process waits for one that
 * never comes. (ParaView itself cannot render a view whose representations
 * are hidden on some processes only: its ordered compositing gathers from
 * the processes where they are visible.)
 *
 * A second point array may be named as a label map (SetLabelMapArray):
 * its labels become materials of their own, in the front ends' default
 * label colours (vtkMultiMaterialVolumeMapper::GetDefaultLabelColor)
 * with the representation's opacity function.
 */
#ifndef vtkMultiMaterialVolumeRepresentation_h
#define vtkMultiMaterialVolumeRepresentation_h

#include "mmrtmParaViewRepresentationModule.h" // for export macro
#include "vtkImageVolumeRepresentation.h"
#include "vtkMultiMaterialProperty.h" // for vtkNew<vtkMultiMaterialProperty>
#include "vtkNew.h"                   // for vtkNew
#include "vtkWeakPointer.h"           // for vtkWeakPointer

#include <string> // for std::string

class vtkRenderer;
class vtkSampleParallelVolumeMapper;
class vtkView;

class MMRTMPARAVIEWREPRESENTATION_EXPORT vtkMultiMaterialVolumeRepresentation : public vtkImageVolumeRepresentation
{
public:
  static vtkMultiMaterialVolumeRepresentation* New();
  vtkTypeMacro(vtkMultiMaterialVolumeRepresentation, vtkImageVolumeRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Samples per pixel of the image added by each still render, and the
   * samples after which renders only redraw (0: no limit); under MPI the
   * processes share them. Every render of an unchanged view adds samples,
   * pvbatch's SaveScreenshot included: GetAccumulatedSamples() tells how
   * many an image has.
   */
  void SetSamplesPerRender(int samples);
  void SetMaximumSamples(int samples);
  ///@}

  /**
   * Relative noise at which the accumulation stops (0: none).
   */
  void SetNoiseTarget(double target);

  /**
   * Real scattering events per path (0: emission and absorption only).
   */
  void SetMaximumBounces(int bounces);

  /**
   * Shadow-ray extinction scale in (0, 1] (1 is unbiased).
   */
  void SetShadowExtinctionScale(double scale);

  /**
   * The seed of the random numbers (process r under MPI uses seed + r).
   */
  void SetSeed(int seed);

  /**
   * 0 octree (the paper's hierarchical grid), 1 macrocells, 2 none.
   */
  void SetAccelerator(int accelerator);
  void SetSampler(int sampler);

  /**
   * 0 automatic, 1 CPU, 2 CUDA.
   */
  void SetBackend(int backend);

  /**
   * CPU threads of each process (0: automatic, the cores shared among the
   * processes on a machine).
   */
  void SetNumberOfThreads(int threads);

  /**
   * Exposure before tone mapping.
   */
  void SetExposure(double exposure);

  /**
   * What the view shows: 0 the accumulated image, 1 (the default) denoised
   * while that is estimated closer to the truth, 2 denoised
   * (vtkMultiMaterialVolumeMapper::SetDenoisingMode).
   */
  void SetDenoisingMode(int mode);

  ///@{
  /**
   * A preset of the project ("ct-bone", "mri", ...) or a scene file (JSON):
   * its materials and transfer functions replace the translation of
   * ParaView's transfer functions. Empty (the default): ParaView's.
   * The scene file wins when both are set.
   */
  void SetPreset(const char* name);
  void SetSceneFile(const char* path);
  ///@}

  /**
   * A file (legacy VTK, .vtk) for the image's linear radiance and its variance after
   * every render (see vtkSampleParallelVolumeMapper); empty: none.
   */
  void SetLinearImageFile(const char* path);

  /**
   * A point array of the input to use as a label map (empty: none).
   */
  void SetLabelMapArray(const char* name);

  ///@{
  /**
   * Samples per pixel of the last image drawn (all processes together),
   * and how many renders combined the processes' films or rendered alone.
   */
  int GetAccumulatedSamples();
  int GetNumberOfCombinedRenders();
  int GetNumberOfLocalRenders();
  ///@}

  ///@{
  /**
   * The mapper's counters (vtkMultiMaterialVolumeMapper): scene builds
   * after a data change, refits (translations of the property) after a
   * transfer-function change, restarts after any change, and the majorant
   * grid's builds and refits.
   */
  int GetNumberOfSceneBuilds();
  int GetNumberOfRefits();
  int GetNumberOfRestarts();
  int GetNumberOfMajorantGridBuilds();
  int GetNumberOfMajorantGridRefits();
  ///@}

protected:
  vtkMultiMaterialVolumeRepresentation();
  ~vtkMultiMaterialVolumeRepresentation() override;

  int RequestUpdateExtent(
    vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  bool AddToView(vtkView* view) override;
  bool RemoveFromView(vtkView* view) override;

private:
  vtkMultiMaterialVolumeRepresentation(const vtkMultiMaterialVolumeRepresentation&) = delete;
  void operator=(const vtkMultiMaterialVolumeRepresentation&) = delete;
  vtkSampleParallelVolumeMapper* Mapper();
  void UpdateMaterialSource();
  void UpdateLabelMap();
  // Before each render of the view, on every process that renders it.
  void OnStartRender();

  // Weak: the view and its renderer may go before this representation.
  vtkWeakPointer<vtkRenderer> ObservedRenderer;
  unsigned long StartRenderObserver = 0;
  vtkWeakPointer<vtkView> ObservedView;

  vtkNew<vtkMultiMaterialProperty> Materials;
  std::string Preset;
  std::string SceneFile;
  std::string LabelMapArray;
};

#endif
