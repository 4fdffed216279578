/**
 * @class   vtkSampleParallelVolumeMapper
 * @brief   vtkMultiMaterialVolumeMapper whose processes render different
 *          samples of one image and average them
 *
 * Under MPI (ParaView's pvbatch or pvserver), every process holds the
 * whole volume and renders its own stream of samples of the whole image
 * (the seed plus its rank); at every still render the films of all
 * processes are combined by summing their moments (mmrtm::Film::Moments),
 * and the first process draws the combined image while the others draw
 * nothing, so that ParaView's compositing passes it on unchanged. The
 * combined image is that of a serial render with the sum of the samples:
 * exact for scattering and shadows, unlike splitting the data among the
 * processes.
 *
 * The sample counts (SetTotalSamplesPerRender, SetTotalMaximumSamples) and
 * the noise target are those of the combined image: each process renders
 * its share. The processes on one machine share its cores (each takes
 * cores / processes-on-the-machine threads, as Open MPI or MPICH report),
 * unless SetThreadsPerProcess says otherwise.
 *
 * Combining is a collective operation inside Render(). It happens only on
 * renders for which SetCombineThisRender(true) was called on every process
 * (vtkMultiMaterialVolumeRepresentation decides so, with all processes,
 * before each render); a render that fails on one process still joins the
 * collective, with no samples. Otherwise the mapper renders and draws its
 * own samples only.
 */
#ifndef vtkSampleParallelVolumeMapper_h
#define vtkSampleParallelVolumeMapper_h

#include "vtkMultiMaterialVolumeMapper.h"
#include "mmrtmParaViewRepresentationModule.h" // for export macro

#include <memory> // for std::unique_ptr

class vtkMultiProcessController;

class MMRTMPARAVIEWREPRESENTATION_EXPORT vtkSampleParallelVolumeMapper : public vtkMultiMaterialVolumeMapper
{
public:
  static vtkSampleParallelVolumeMapper* New();
  vtkTypeMacro(vtkSampleParallelVolumeMapper, vtkMultiMaterialVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * The processes that share the rendering (default: the global controller;
   * null or one process renders alone).
   */
  void SetController(vtkMultiProcessController* controller);
  vtkMultiProcessController* GetController();

  ///@{
  /**
   * Samples per pixel of the combined image: each of N processes adds
   * ceil(samples / N) per render, up to ceil(maximum / N) (0: no limit).
   * The noise target is the combined image's (each process aims at
   * sqrt(N) times it).
   */
  void SetTotalSamplesPerRender(int samples);
  void SetTotalMaximumSamples(int maximum);
  void SetTotalNoiseTarget(double target);
  ///@}

  /**
   * The seed of the first process; process r uses seed + r.
   */
  void SetBaseSeed(int seed);

  /**
   * CPU threads of each process; 0 (the default): all cores alone, and
   * under MPI the machine's cores shared among its processes.
   */
  void SetThreadsPerProcess(int threads);

  /**
   * Whether the next Render() combines the films of all processes: call it
   * with the same value on every process before a render (see the class
   * documentation). It holds for one render.
   */
  void SetCombineThisRender(bool combine) { this->CombineThisRender = combine; }

  /**
   * Samples per pixel of the last image drawn (combined: the sum over the
   * processes).
   */
  int GetCombinedSamples() { return this->CombinedSamples; }

  /**
   * How many renders combined the processes' films, and how many rendered
   * alone, since construction.
   */
  int GetNumberOfCombinedRenders() { return this->CombinedRenders; }
  int GetNumberOfLocalRenders() { return this->LocalRenders; }

  ///@{
  /**
   * A file (legacy VTK, .vtk) where the first process writes the image it draws after
   * every render: per pixel the mean linear radiance ("radiance", RGB), the
   * coverage ("alpha") and the variance of the radiance's mean
   * ("variance_of_mean", RGB), float, row 0 at the bottom; the field data
   * "samples" holds the samples per pixel. Empty (the default): none.
   * For HDR output and for tests of the combination.
   */
  vtkSetStringMacro(LinearImageFile);
  vtkGetStringMacro(LinearImageFile);
  ///@}

  void Render(vtkRenderer* ren, vtkVolume* vol) override;

protected:
  vtkSampleParallelVolumeMapper();
  ~vtkSampleParallelVolumeMapper() override;

  void DrawFilm(vtkRenderer* ren, vtkVolume* vol, const mmrtm::Film& film) override;

private:
  vtkSampleParallelVolumeMapper(const vtkSampleParallelVolumeMapper&) = delete;
  void operator=(const vtkSampleParallelVolumeMapper&) = delete;
  int Processes();
  int Rank();
  void ApplyShares();
  // The collective: the sum of every process's film (local: null when this
  // process has none); returns whether the sizes agreed and a film resulted.
  bool Combine(const mmrtm::Film* local);
  void WriteLinearImage(const mmrtm::Film& film);

  vtkMultiProcessController* Controller = nullptr;
  bool CombineThisRender = false;
  bool Combined = false; // during Render(): the collective has run
  int TotalSamplesPerRender = 4;
  int TotalMaximumSamples = 256;
  double TotalNoiseTarget = 0.0;
  int BaseSeed = 0;
  int ThreadsPerProcess = 0;
  int CombinedSamples = 0;
  int CombinedRenders = 0;
  int LocalRenders = 0;
  std::unique_ptr<mmrtm::Film> CombinedFilm;
  char* LinearImageFile = nullptr;
};

#endif
