// Adding samples to the film: on the calling thread, or on the
// refinement thread of its own (AsynchronousRefinement) while renders draw
// the last finished pass; and the denoised display of the film.
#include "vtkMultiMaterialVolumeMapperInternals.h"

#include <algorithm>
#include <chrono>
#include <exception>

#include <vtkDemandDrivenPipeline.h>

const mmrtm::Film* vtkMultiMaterialVolumeMapper::Internals::Refine(bool restart)
{
  // The scene's build refits only when what a refit reads changed, so a
  // render after a camera move keeps the majorants and takes microseconds.
  Internals& in = *this;
  const auto buildStart = std::chrono::steady_clock::now();
  const mmrtm::SceneView sceneView = this->BuildScene();
  if (in.Renderer) // a CUDA backend that fell back to the CPU says so
    in.BackendDescription = in.Renderer->Description();
  in.CountGridWork();
  if (in.Scene.ExtinctionWarning() != in.LastExtinctionWarning) // once per change, not per render
  {
    in.LastExtinctionWarning = in.Scene.ExtinctionWarning();
    if (!in.LastExtinctionWarning.empty())
      vtkWarningWithObjectMacro(Self, << in.LastExtinctionWarning);
  }
  if (restart && (in.Scene.GridRefittedByLastBuild() || !in.Scene.Grid()))
    in.LastBuildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - buildStart).count();
  const int accumulated = static_cast<int>(in.Film->Samples());
  // A tile of a magnified screenshot is drawn once: with as many samples
  // as the view it magnifies has. A projection needs one.
  const bool projecting = in.Scene.render.integrator.projection.mode != mmrtm::IntensityProjection::None;
  const int perRender = projecting        ? 1
    : in.Built.View.Tile && in.ParkedFilm ? std::max(Self->SamplesPerRender, static_cast<int>(in.ParkedFilm->Samples()))
                                          : Self->SamplesPerRender;
  const int samples = this->FilmConverged() ? 0
    : Self->MaximumSamples > 0              ? std::min(perRender, Self->MaximumSamples - accumulated)
                                            : perRender;
  const bool background = Self->AsynchronousRefinement && !restart && accumulated > 0 && in.Shown;
  if (background && this->DenoisingApplies() && in.Display.Due(in.FilmGeneration, in.Shown->Samples(), samples > 0) &&
    this->DenoiserReady())
  {
    // A denoise of the image shown, before more samples: on the thread of
    // the passes, so that this render returns at once.
    auto snapshot = std::make_shared<mmrtm::FilmSnapshot>(mmrtm::SnapshotFilm(*in.Shown, in.FilmGeneration));
    const bool estimate = in.Display.WantsEstimate(in.FilmGeneration, in.Shown->Samples());
    mmrtm::Denoiser* denoiser = in.Denoiser.get();
    in.Display.Started();
    this->StartPass(true,
      [snapshot, estimate, denoiser](Pass& p)
      { p.Denoised = mmrtm::DenoiseSnapshot(*snapshot, estimate, true, mmrtm::OidnDenoise(*denoiser), &p.Cancel); });
    return in.Shown.get();
  }
  if (samples > 0)
    ++in.TracedPasses;
  if (samples > 0 && background)
  {
    // The next pass on a thread of its own, under in.Built; this render
    // draws the last finished image.
    mmrtm::Renderer* renderer = in.Renderer.get();
    mmrtm::Film* film = in.Film.get();
    const mmrtm::Scene* scene = &in.Scene;
    this->StartPass(false, [renderer, film, scene, sceneView, samples](Pass& p)
      { p.Completed = renderer->Render(*scene, sceneView, *film, samples, nullptr, nullptr, &p.Cancel); });
    return in.Shown.get();
  }
  if (samples > 0)
    in.Renderer->Render(in.Scene, sceneView, *in.Film, samples, nullptr, nullptr);
  if (Self->AsynchronousRefinement)
    in.Shown = std::make_unique<mmrtm::Film>(*in.Film);
  else if (this->DenoisingApplies() && in.Display.Due(in.FilmGeneration, in.Film->Samples(), !this->FilmConverged()) &&
    this->DenoiserReady())
  {
    // Synchronous refinement: the denoise after the pass, in this render.
    in.Display.Started();
    std::optional<mmrtm::DenoisedFilm> denoised;
    try
    {
      denoised = mmrtm::DenoiseSnapshot(mmrtm::SnapshotFilm(*in.Film, in.FilmGeneration),
        in.Display.WantsEstimate(in.FilmGeneration, in.Film->Samples()), true, mmrtm::OidnDenoise(*in.Denoiser));
    }
    catch (const std::exception& e)
    {
      vtkErrorWithObjectMacro(Self, "Render: the denoiser failed: " << e.what());
    }
    in.Display.Finished(std::move(denoised));
  }
  return in.Film.get();
}

// `work` on a thread of its own, as the pass in flight (a denoise of Shown
// when `denoising`, else samples); what it throws is the pass's error, said
// when the pass is finished (FinishPass).
void vtkMultiMaterialVolumeMapper::Internals::StartPass(bool denoising, std::function<void(Pass&)> work)
{
  auto pass = std::make_unique<Pass>();
  Pass* p = pass.get();
  p->Denoising = denoising;
  p->Thread = std::thread(
    [p, work = std::move(work)]
    {
      try
      {
        work(*p);
      }
      catch (const std::exception& e)
      {
        p->Error = e.what();
      }
      p->Done = true;
    });
  this->InFlight = std::move(pass);
}

void vtkMultiMaterialVolumeMapper::Internals::FinishPass(bool cancel)
{
  Internals& in = *this;
  if (!in.InFlight)
    return;
  if (cancel)
    in.InFlight->Cancel = true;
  in.InFlight->Thread.join();
  if (!in.InFlight->Error.empty())
    vtkErrorWithObjectMacro(Self, "Render: " << in.InFlight->Error);
  if (in.InFlight->Denoising)
    in.Display.Finished(std::move(in.InFlight->Denoised)); // the film is untouched
  else if (in.InFlight->Completed)
    in.Shown = std::make_unique<mmrtm::Film>(*in.Film);
  else
    in.Film.reset(); // a partial pass: the next render restarts
  in.InFlight.reset();
}

// Whether bringing the input up to date will run its producer (the test
// vtkDemandDrivenPipeline makes: data older than the pipeline's MTime).
bool vtkMultiMaterialVolumeMapper::Internals::InputWillExecute()
{
  vtkAlgorithm* producer = Self->GetInputAlgorithm();
  vtkDataObject* data = Self->GetInputDataObject(0, 0);
  auto* executive = producer ? vtkDemandDrivenPipeline::SafeDownCast(producer->GetExecutive()) : nullptr;
  if (!executive || !data)
    return true;
  executive->UpdatePipelineMTime();
  return data->GetUpdateTime() < executive->GetPipelineMTime();
}

const mmrtm::Film* vtkMultiMaterialVolumeMapper::Internals::ImageFilm()
{
  Internals& in = *this;
  return in.InFlight ? in.Shown.get() : in.Film.get();
}

bool vtkMultiMaterialVolumeMapper::Internals::FilmConverged()
{
  const mmrtm::Film* film = this->ImageFilm();
  if (!film)
    return false;
  const int accumulated = static_cast<int>(film->Samples());
  if (Self->MaximumSamples > 0 && accumulated >= Self->MaximumSamples)
    return true;
  if (accumulated >= 1 && this->Scene.render.integrator.projection.mode != mmrtm::IntensityProjection::None)
    return true; // a projection's one sample is its image
  // The noise estimate needs two samples; it costs one pass over the film.
  return Self->NoiseTarget > 0 && accumulated >= 2 && film->Noise().relative <= Self->NoiseTarget;
}

bool vtkMultiMaterialVolumeMapper::Internals::DenoisingApplies()
{
  // A projection's one sample is its image: there is no noise to take out.
  return Self->DenoisingMode != DENOISING_OFF &&
    this->Scene.render.integrator.projection.mode == mmrtm::IntensityProjection::None;
}

bool vtkMultiMaterialVolumeMapper::Internals::DenoiserReady()
{
  Internals& in = *this;
  if (!in.Denoiser && !in.DenoiserLoadTried)
  {
    in.DenoiserLoadTried = true;
    try
    {
      in.Denoiser = mmrtm::Denoiser::Load(Self->NumberOfThreads);
    }
    catch (const mmrtm::DenoiserError& e)
    {
      // Said once in full; the status names it while a denoising mode is on.
      const std::string why = e.what();
      in.Display.SetUnavailable(why.substr(0, why.find(" (")));
      vtkWarningWithObjectMacro(Self, << why);
    }
  }
  return in.Denoiser != nullptr;
}
