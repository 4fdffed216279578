// What a progressive view shows of its film (Documentation/denoising.md):
// the film itself, the unbiased accumulation, or the film denoised. The
// denoised image is made from a copy of the film and never written into
// it, so the accumulation goes on to the bit as if nothing were shown.
//
// Auto shows the denoised image while it is estimated closer to the truth
// than the film, and the film after. The estimate comes from the film's
// two halves (Film::DenoiserImages): the even samples' half A and the odd
// samples' half B are independent, and B is unbiased, so for the half
// denoised, D(A),
//   E mean |D(A) - B|^2 = MSE(D(A)) + Var B,
// and Var B follows from the halves' difference (E |A - B|^2 = Var A +
// Var B); the estimate plus two of its standard errors is the bound used.
// The whole film's denoised image D(F) has twice A's samples: its error is
// taken to be at most D(A)'s (a denoiser whose error grew with samples
// would break this; TestDenoisedDisplay checks it on the reference
// scenes). The film's own error is its variance, from the same difference.
// As the film goes on, the denoised image is checked again against the
// samples that came after it (Recheck): they are independent of it, so
// the same reasoning holds with them in B's place. Host-only.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "denoiser.h"
#include "film.h"

namespace mmrtm {

enum class DenoisingMode { Off, Auto, Always };
std::optional<DenoisingMode> ParseDenoisingMode(const std::string& name);  // off, auto, always
const char* DenoisingModeName(DenoisingMode mode);

// A film as a denoise reads it: a copy, so that the film goes on
// accumulating (or is dropped) while the denoiser runs.
struct FilmSnapshot {
  uint64_t generation = 0;  // the owner's number for the film's accumulation: a restart changes it
  uint32_t samples = 0;
  RGBImage color;             // the film's mean
  std::vector<float> alpha;   // its coverage
  bool tracksInputs = false;  // the film kept its denoiser inputs
  bool hasHalves = false;     // and has 2 or more samples
  FilmHalves halves;
};
FilmSnapshot SnapshotFilm(const Film& film, uint64_t generation);

// The denoiser as the display calls it: colour images (linear, HDR) that
// share one pair of optional guides (albedo, normal), denoised each, and a
// flag that stops it (then it returns nothing). OidnDenoise gives Intel
// Open Image Denoise's; the tests plant others.
using DenoiseFunction =
    std::function<std::vector<RGBImage>(const std::vector<const RGBImage*>& colors, const RGBImage* albedo,
                                        const RGBImage* normal, const std::atomic<bool>* cancel)>;

// Intel Open Image Denoise as the display's denoiser: the guides denoised
// first, once, then each colour with them as clean guides (OIDN's advice
// for noisy guides; Documentation/denoising.md measures it against colour
// only).
DenoiseFunction OidnDenoise(Denoiser& denoiser);

// How far the film, when it had `samples` samples, and the denoised image
// shown are from the truth: means over pixels and channels of the squared
// difference, in linear radiance (relative figures divide their roots by
// meanValue).
struct DenoiseEstimate {
  uint32_t samples = 0;
  double denoised = 0;   // an estimate plus two standard errors: a bound of the denoised image's
  double film = 0;       // the film's (its variance)
  double meanValue = 0;  // the film's mean over pixels and channels
  // The film's error once it has `n` samples (variance goes as 1 / n).
  double FilmAt(uint32_t n) const { return n ? film * samples / n : 0.0; }
  // Whether the denoised image is the closer one once the film has `n`.
  bool DenoisedCloserAt(uint32_t n) const { return denoised < FilmAt(n); }
};

// A film denoised: the image, the film's coverage with it, and the
// estimate when one was made; and the film as it was denoised (its mean
// and the mean of its even samples), which Recheck subtracts from the film
// as it is later to find the samples that came after.
struct DenoisedFilm {
  uint64_t generation = 0;
  uint32_t samples = 0;
  RGBImage image;
  std::vector<float> alpha;
  std::optional<DenoiseEstimate> estimate;
  double seconds = 0;               // the denoiser's time, the estimate's included
  RGBImage filmMean, filmEvenMean;  // empty when the film kept no denoiser inputs
};

// Denoises the snapshot's colour; with `estimate` and halves also the half
// and the errors. Returns nullopt when `cancel` stopped it. Whatever the
// denoiser throws goes through.
std::optional<DenoisedFilm> DenoiseSnapshot(const FilmSnapshot& snapshot, bool estimate, bool useGuides,
                                            const DenoiseFunction& denoise, const std::atomic<bool>* cancel = nullptr);

// The display's state for one view: which denoise is due, what to show.
// Not thread-safe: its owner runs a denoise (DenoiseSnapshot) where it
// likes and hands the result back (Accept).
class DenoisedDisplay {
 public:
  using Clock = std::chrono::steady_clock;

  void SetMode(DenoisingMode mode) { mode_ = mode; }
  DenoisingMode Mode() const { return mode_; }

  // Whether a denoise of the film is due: not Off, samples the last denoise
  // of this accumulation did not have, Auto not settled on the film, and,
  // while the film is `accumulating`, the time budget: after a denoise of
  // d seconds the next starts 3 d later at the earliest, so that denoising
  // takes at most a quarter of the wall time (the first of a new
  // accumulation starts at once, and so does the last, once the film has
  // stopped accumulating).
  bool Due(uint64_t generation, uint32_t samples, bool accumulating, Clock::time_point now = Clock::now()) const;
  bool Busy() const { return busy_; }
  // Whether that denoise should also estimate (Auto, when no estimate of
  // this accumulation says the denoised image is closer at `samples`).
  bool WantsEstimate(uint64_t generation, uint32_t samples) const;
  // Call when a due denoise starts, and with its result (or nullopt when it
  // was stopped or failed) when it ends.
  void Started(Clock::time_point now = Clock::now()) {
    started_ = now;
    busy_ = true;
  }
  void Finished(std::optional<DenoisedFilm> result, Clock::time_point now = Clock::now());

  // Auto: the newest denoised image of `film` (the accumulation
  // `generation`) checked against the samples the film gained since it was
  // made (the header's reasoning), each time they have doubled, when there
  // are new samples in both halves; the latest estimate then holds the
  // film's error now and the tightest bound of the image's. Nothing for an
  // adaptive film or one without denoiser inputs.
  void Recheck(const Film& film, uint64_t generation);

  // The image to draw over the film of `generation` with `samples`: the
  // newest denoised one, or null for the film itself. Auto shows it while
  // the latest estimate says it is closer (a denoise of one sample needs
  // none: there are no halves to estimate by, and a one-sample film was the
  // farther on every reference scene: Documentation/denoising.md), and the
  // film once a denoise's own estimate finds the film closer.
  const DenoisedFilm* Shown(uint64_t generation, uint32_t samples) const;

  // "denoised, 8 samples", "unbiased, 64 samples, noise 2.1 %" (noise:
  // the film's relative noise, given by the caller), with why the film is
  // shown when a mode asks for more ("no denoiser: ...").
  std::string Status(uint64_t generation, uint32_t samples, double relativeNoise) const;
  // Why no denoiser runs (it could not be loaded), or empty.
  void SetUnavailable(std::string why) { unavailable_ = std::move(why); }
  const std::string& Unavailable() const { return unavailable_; }
  // Whether a denoise of the accumulation `generation` has ended.
  bool HasDenoised(uint64_t generation) const { return last_ && generation_ == generation; }
  // The latest estimate of the accumulation `generation`, if any.
  const DenoiseEstimate* Estimate(uint64_t generation) const;

  int Denoises() const { return denoises_; }
  double Seconds() const { return seconds_; }
  double LastSeconds() const { return lastSeconds_; }

 private:
  DenoisingMode mode_ = DenoisingMode::Off;
  uint64_t generation_ = 0;                  // the newest accumulation a denoise was of
  std::optional<DenoisedFilm> last_;         // its latest denoised image
  std::optional<DenoiseEstimate> estimate_;  // its latest estimate (of a denoise or a Recheck)
  bool settledOnFilm_ = false;               // Auto: a denoise's estimate found the film closer
  uint32_t rechecked_ = 0;                   // the sample count of the last Recheck
  bool busy_ = false;                        // between Started and Finished
  Clock::time_point finished_{};
  Clock::time_point started_{};
  double lastSeconds_ = 0, seconds_ = 0;
  int denoises_ = 0;
  std::string unavailable_;
};

}  // namespace mmrtm
