#include "vtkSampleParallelVolumeMapper.h"

#include "vtkCommunicator.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkStructuredPointsWriter.h"
#include "vtkMultiProcessController.h"
#include "vtkObjectFactory.h"

#include "film.h" // mmrtm::Film and its moments

#include <cmath>
#include <cstdlib>
#include <thread>
#include <vector>

vtkStandardNewMacro(vtkSampleParallelVolumeMapper);

vtkSampleParallelVolumeMapper::vtkSampleParallelVolumeMapper()
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
  // Renders must be the same on every process, in step: no background
  // passes, no interactive previews (they would skip the collective).
  this->SetAsynchronousRefinement(false);
  this->ApplyShares();
}

vtkSampleParallelVolumeMapper::~vtkSampleParallelVolumeMapper()
{
  this->SetController(nullptr);
  this->SetLinearImageFile(nullptr);
}

void vtkSampleParallelVolumeMapper::SetController(vtkMultiProcessController* controller)
{
  vtkSetObjectBodyMacro(Controller, vtkMultiProcessController, controller);
  this->ApplyShares();
}

vtkMultiProcessController* vtkSampleParallelVolumeMapper::GetController()
{
  return this->Controller;
}

int vtkSampleParallelVolumeMapper::Processes()
{
  return this->Controller ? std::max(1, this->Controller->GetNumberOfProcesses()) : 1;
}

int vtkSampleParallelVolumeMapper::Rank()
{
  return this->Controller ? this->Controller->GetLocalProcessId() : 0;
}

void vtkSampleParallelVolumeMapper::SetTotalSamplesPerRender(int samples)
{
  this->TotalSamplesPerRender = std::max(1, samples);
  this->ApplyShares();
}

void vtkSampleParallelVolumeMapper::SetTotalMaximumSamples(int maximum)
{
  this->TotalMaximumSamples = std::max(0, maximum);
  this->ApplyShares();
}

void vtkSampleParallelVolumeMapper::SetTotalNoiseTarget(double target)
{
  this->TotalNoiseTarget = std::max(0.0, target);
  this->ApplyShares();
}

void vtkSampleParallelVolumeMapper::SetBaseSeed(int seed)
{
  this->BaseSeed = seed;
  this->ApplyShares();
}

void vtkSampleParallelVolumeMapper::SetThreadsPerProcess(int threads)
{
  this->ThreadsPerProcess = std::max(0, threads);
  this->ApplyShares();
}

// Each process's share of the combined image's samples, and its seed.
void vtkSampleParallelVolumeMapper::ApplyShares()
{
  const int n = this->Processes();
  auto share = [n](int total) { return (total + n - 1) / n; };
  this->SetSamplesPerRender(share(this->TotalSamplesPerRender));
  this->SetMaximumSamples(this->TotalMaximumSamples > 0 ? share(this->TotalMaximumSamples) : 0);
  // Relative noise falls as 1 / sqrt(samples): N processes' combined image
  // reaches the target when each has sqrt(N) times it.
  this->SetNoiseTarget(std::min(1.0, this->TotalNoiseTarget * std::sqrt(static_cast<double>(n))));
  this->SetSeed(this->BaseSeed + this->Rank());
  if (n > 1)
    this->SetInteractiveAdjustResolution(false);
  int threads = this->ThreadsPerProcess; // 0: all cores
  if (threads == 0 && n > 1)
  {
    // The processes on this machine share its cores (Open MPI and MPICH say
    // how many there are; else one a machine is assumed).
    int local = 1;
    for (const char* name : { "OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS" })
      if (const char* value = std::getenv(name))
        local = std::max(local, std::atoi(value));
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    threads = std::max(1, cores / local);
  }
  this->SetNumberOfThreads(threads);
}

void vtkSampleParallelVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  const bool combine = this->CombineThisRender && this->Processes() > 1;
  this->Combined = false;
  if (!combine)
  {
    this->Superclass::Render(ren, vol); // draws its own samples (DrawFilm below)
    ++this->LocalRenders;
    return;
  }
  this->Superclass::Render(ren, vol); // DrawFilm runs the collective
  if (!this->Combined)
  {
    // This process had nothing to draw (an error, an empty viewport): it
    // still joins the collective, or the others would wait for it forever.
    this->Combine(nullptr);
  }
  ++this->CombinedRenders;
  this->CombineThisRender = false; // one render: the next is agreed on anew
}

void vtkSampleParallelVolumeMapper::DrawFilm(vtkRenderer* ren, vtkVolume* vol, const mmrtm::Film& film)
{
  if (!this->CombineThisRender || this->Processes() < 2 || this->Combined)
  {
    this->CombinedSamples = static_cast<int>(film.Samples());
    this->Superclass::DrawFilm(ren, vol, film);
    if (this->Rank() == 0)
      this->WriteLinearImage(film);
    return;
  }
  if (this->Combine(&film) && this->Rank() == 0)
  {
    this->Superclass::DrawFilm(ren, vol, *this->CombinedFilm);
    this->WriteLinearImage(*this->CombinedFilm);
  }
}

void vtkSampleParallelVolumeMapper::WriteLinearImage(const mmrtm::Film& film)
{
  if (!this->LinearImageFile || !*this->LinearImageFile)
    return;
  const int w = film.Width(), h = film.Height();
  vtkNew<vtkImageData> image;
  image->SetDimensions(w, h, 1);
  auto array = [&](const char* name, int components)
  {
    vtkNew<vtkFloatArray> a;
    a->SetName(name);
    a->SetNumberOfComponents(components);
    a->SetNumberOfTuples(static_cast<vtkIdType>(w) * h);
    image->GetPointData()->AddArray(a);
    return a.Get();
  };
  vtkFloatArray* radiance = array("radiance", 3);
  vtkFloatArray* alpha = array("alpha", 1);
  vtkFloatArray* variance = array("variance_of_mean", 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
    {
      const vtkIdType i = static_cast<vtkIdType>(y) * w + x;
      const mmrtm::RGB m = film.Mean(x, y), v = film.VarianceOfMean(x, y);
      const float mean[3] = { m.r, m.g, m.b }, var[3] = { v.r, v.g, v.b };
      radiance->SetTypedTuple(i, mean);
      alpha->SetValue(i, film.Alpha(x, y));
      variance->SetTypedTuple(i, var);
    }
  vtkNew<vtkIntArray> samples;
  samples->SetName("samples");
  samples->InsertNextValue(static_cast<int>(film.Samples()));
  image->GetFieldData()->AddArray(samples);
  // A legacy VTK file: ParaView 5.11's XML reader rejected the .vti that
  // its own XML writer made of this image ("not well-formed").
  vtkNew<vtkStructuredPointsWriter> writer;
  writer->SetFileName(this->LinearImageFile);
  writer->SetInputData(image);
  writer->SetFileTypeToBinary();
  if (!writer->Write())
    vtkErrorMacro("could not write the linear image " << this->LinearImageFile);
}

bool vtkSampleParallelVolumeMapper::Combine(const mmrtm::Film* local)
{
  this->Combined = true;
  vtkMultiProcessController* c = this->Controller;
  // 1. Do all films have one size? (the maximum of w, h, -w, -h)
  const double w = local ? local->Width() : 0, h = local ? local->Height() : 0;
  const double size[4] = { w, h, -w, -h };
  double extremes[4] = { 0, 0, 0, 0 };
  c->AllReduce(size, extremes, 4, vtkCommunicator::MAX_OP);
  const bool agree = extremes[0] == -extremes[2] && extremes[1] == -extremes[3] && extremes[0] > 0 && extremes[1] > 0;
  if (!agree)
  {
    if (local)
      vtkWarningMacro("the processes' images differ in size or some have none: not combined");
    this->CombinedSamples = 0;
    return false;
  }
  // 2. The sum of their moments and sample counts.
  const int width = static_cast<int>(extremes[0]), height = static_cast<int>(extremes[1]);
  std::vector<double> moments = local
    ? local->Moments()
    : std::vector<double>(static_cast<size_t>(width) * height * mmrtm::Film::kMomentsPerPixel, 0.0);
  moments.push_back(local ? local->Samples() : 0);
  std::vector<double> sum(moments.size());
  c->AllReduce(moments.data(), sum.data(), static_cast<vtkIdType>(moments.size()), vtkCommunicator::SUM_OP);
  const uint32_t samples = static_cast<uint32_t>(sum.back());
  sum.pop_back();
  this->CombinedFilm = std::make_unique<mmrtm::Film>(mmrtm::Film::FromMoments(width, height, samples, sum));
  this->CombinedSamples = static_cast<int>(samples);
  return true;
}

void vtkSampleParallelVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Processes: " << this->Processes() << " (this one " << this->Rank() << ")\n";
  os << indent << "TotalSamplesPerRender: " << this->TotalSamplesPerRender << "\n";
  os << indent << "TotalMaximumSamples: " << this->TotalMaximumSamples << "\n";
  os << indent << "TotalNoiseTarget: " << this->TotalNoiseTarget << "\n";
  os << indent << "BaseSeed: " << this->BaseSeed << "\n";
  os << indent << "CombinedSamples: " << this->CombinedSamples << "\n";
}
