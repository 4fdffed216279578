// mmrtm-render: renders a volume with the MM-RTM path tracer to a PNG.
//
//   mmrtm-render [INPUT] [--scene FILE.json] [--preset NAME] [--labels FILE] ...
//
// With no INPUT it renders the head CT of Debian's invesalius-examples
// package with the ct-bone preset. Progress goes to stderr, the image to the
// named file; the exit code is 0 only on success. See --help.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <unistd.h>

#include "adaptive_sampling.h"
#include "denoised_display.h"
#include "denoiser.h"
#include "image_io.h"
#include "label_materials.h"
#include "mmrtmVolumeLoader.h"
#include "render_backend.h"
#include "scene_json.h"
#include "scene_relocation.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const char* kUsage = R"(usage: mmrtm-render [INPUT] [options]

Renders a volume with the MM-RTM volumetric path tracer.

INPUT                   volume file (.nrrd/.nhdr, .nii/.nii.gz, .mha/.mhd, .vti, .vtk,
                        .inv3) or a DICOM folder; the proxy named "scalars".
                        Default: the head CT of Debian's invesalius-examples
                        (%s)
options:
  --scene FILE.json     scene file (Documentation/scene-format.md); applied over the preset
  --preset NAME         scene preset from %s
                        (default: ct-bone when no --scene is given)
  --series ID           DICOM folder with several series: the SeriesInstanceUID or
                        SeriesDescription of the one to read (default: the largest)
  --list-series         list the series of the DICOM folder INPUT and exit
  --labels FILE         label map, the proxy named "labels" (nearest lookup); put on
                        INPUT's grid (nearest neighbour) when its grid differs
  --label-table FILE    label names and colours: "id name [r g b [a]]" lines, or a
                        3D Slicer colour table (.ctbl/.txt); used by presets with
                        "label_materials" (ct-organs), which make a material per label
  --width W             image width in pixels (default: scene, else 512)
  --height H            image height in pixels (default: scene, else 512)
  --spp N               samples per pixel (default: scene, else 64); with
                        --noise-target, the most it renders
  --noise-target R      stop once the image's relative noise (its estimated RMS
                        standard error over its mean luminance) is at most R, e.g.
                        0.01; checked after each pass: 4 spp first, then what
                        the measured noise says is missing (a pass at most
                        doubles the samples, and adds at most 64)
  --light-sampling L    next-event estimation with several lights: resampled (one
                        shadow ray, to a light chosen by its unshadowed contribution;
                        default), one (a light chosen uniformly) or all (a shadow ray
                        to every light)
  --sampling S          uniform (every pixel --spp samples; default) or adaptive
                        (a pilot pass, then each pixel's share of a mean of --spp
                        in proportion to its neighbours' noise; unbiased)
  --sampler S           sobol (Owen-scrambled Sobol' numbers for the pixel, lens and
                        first two scattering events; default) or independent (all
                        from PCG32)
  --seed S              random seed (default: scene, else 0)
  --threads T           CPU threads, 0 for all (default: 0)
  --backend B           auto (CUDA when a device is present, else the CPU; default),
                        cpu, or cuda (an error without a CUDA device)
  --estimator E         delta (unbiased, default) or raymarch (biased baseline)
  --accelerator A       majorants for delta tracking: none (one global majorant),
                        macrocell (uniform grid), octree (default: the hierarchical
                        grid), octree-voxelmax (the paper's voxel-value refit; not
                        conservative, for comparison only)
  --leaf-level L        octree leaf level, -1 chooses from the volume size (default: -1)
  --ray-march-step MM   step of --estimator raymarch, mm (default: 0.5)
  --shadow-scale A      shadow-ray extinction scale in (0, 1] (default: 0.8; 1 is unbiased)
  --max-bounces N       bounce limit (default: 32)
  --exposure X          exposure multiplier before tone mapping (default: 1)
  --output FILE.png     tone-mapped image (default: mmrtm-render.png)
  --output-linear FILE.pfm   linear radiance, float RGB
  --output-variance FILE.pfm  per-pixel variance of that mean (from the samples), float RGB
  --denoise MODE        what --output shows: off (the unbiased image; default), auto
                        (the image denoised by Intel Open Image Denoise where that is
                        estimated closer to the truth, from the image's two halves)
                        or always (denoised); a denoised image is biased, and
                        --stats-json says which was written
  --denoised-preview FILE     also the denoised image (.png tone mapped, .pfm linear),
                        whatever --denoise shows; --output-linear and
                        --output-variance are the unbiased image's either way
  --output-denoiser-inputs PREFIX  the denoiser's inputs as linear PFM images:
                        PREFIX_color_even.pfm and _odd (the means of the even and the
                        odd samples), PREFIX_albedo.pfm and _normal.pfm (where camera
                        rays first collide), and those of each half (_albedo_even ...)
  --stats-json FILE     timings, samples, collisions, density lookups and noise
  --quiet               no progress bars (loading, building, rendering)
  --help                this text
)";

// What the scene holds in memory while rendering, against the input volumes
// (DESIGN.md rule 3: no more than the scene needs). The majorant grid's
// value summaries stay on the host (refits read them); the rest is what a
// GPU backend uploads.
json MemoryJson(const mmrtm::Scene& scene, const mmrtm::SceneView& view, size_t inputVoxelBytes) {
  const mmrtm::SceneFootprint f = mmrtm::MeasureSceneView(view);
  const size_t summaries = scene.Grid() ? scene.Grid()->SummaryBytes() : 0;
  const auto& dims = scene.proxies.at(0).dims;
  const double voxels = (double)dims[0] * dims[1] * dims[2];
  const size_t held = f.voxels + f.tables + f.majorants + f.minorants + summaries;
  return {{"input_voxel_bytes", inputVoxelBytes},
          {"proxy_voxel_bytes", f.voxels},
          {"tf_table_bytes", f.tables},
          {"majorant_bytes", f.majorants},
          {"minorant_bytes", f.minorants},
          {"summary_bytes", summaries},
          {"environment_bytes", f.environment},
          {"grid_leaves", scene.Grid() ? scene.Grid()->LeafCount() : 0},
          {"distinct_leaf_summaries", scene.Grid() ? scene.Grid()->Summaries().Count() : 0},
          {"voxels", voxels},
          {"bytes_per_voxel", held / voxels},
          {"input_bytes_per_voxel", inputVoxelBytes / voxels}};
}

struct Options {
  std::string input, scene, preset, labels, labelTable, series,
      output = "mmrtm-render.png", outputLinear, outputVariance, statsJson, denoisedPreview, outputDenoiserInputs;
  mmrtm::DenoisingMode denoise = mmrtm::DenoisingMode::Off;
  json render = json::object();  // overrides of the scene's "render" block
  mmrtm::Backend backend = mmrtm::Backend::Auto;
  bool quiet = false, listSeries = false;
  double noiseTarget = 0;     // 0: render all --spp samples
  bool adaptive = false;      // --sampling adaptive
};

[[noreturn]] void UsageError(const std::string& msg) {
  std::fprintf(stderr, "mmrtm-render: %s\n(see mmrtm-render --help)\n", msg.c_str());
  std::exit(2);
}

std::string DataDirectory() {
  if (const char* env = std::getenv("MMRTM_DATA_DIR")) return env;
  return MMRTM_DATA_DIR;
}

long ParseInteger(const std::string& flag, const std::string& text, long lo, long hi) {
  char* end = nullptr;
  errno = 0;
  long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end || errno || v < lo || v > hi)
    UsageError(flag + " expects an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" + text +
               "'");
  return v;
}

double ParseReal(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end || !std::isfinite(v)) UsageError(flag + " expects a number, got '" + text + "'");
  return v;
}

// ".png" for "a/b.PNG".
std::string LowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return (char)std::tolower(c); });
  return ext;
}

Options ParseArguments(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) UsageError(a + " needs a value");
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::printf(kUsage, mmrtm::DefaultVolumePath().c_str(), (DataDirectory() + "/presets").c_str());
      std::exit(0);
    } else if (a == "--scene")
      o.scene = value();
    else if (a == "--preset")
      o.preset = value();
    else if (a == "--labels")
      o.labels = value();
    else if (a == "--label-table")
      o.labelTable = value();
    else if (a == "--series")
      o.series = value();
    else if (a == "--list-series")
      o.listSeries = true;
    else if (a == "--width")
      o.render["width"] = ParseInteger(a, value(), 1, 16384);
    else if (a == "--height")
      o.render["height"] = ParseInteger(a, value(), 1, 16384);
    else if (a == "--spp")
      o.render["spp"] = ParseInteger(a, value(), 1, 1 << 24);
    else if (a == "--seed")
      o.render["seed"] = (uint64_t)ParseInteger(a, value(), 0, 0x7fffffffL);
    else if (a == "--threads")
      o.render["threads"] = ParseInteger(a, value(), 0, 1024);
    else if (a == "--backend") {
      const std::string b = value();
      const auto backend = mmrtm::ParseBackend(b);
      if (!backend) UsageError("--backend expects auto, cpu or cuda, got '" + b + "'");
      o.backend = *backend;
    } else if (a == "--max-bounces")
      o.render["max_bounces"] = ParseInteger(a, value(), 0, 100000);
    else if (a == "--shadow-scale")
      o.render["shadow_extinction_scale"] = ParseReal(a, value());
    else if (a == "--exposure")
      o.render["exposure"] = ParseReal(a, value());
    else if (a == "--estimator") {
      std::string e = value();
      if (e != "delta" && e != "raymarch") UsageError("--estimator expects delta or raymarch, got '" + e + "'");
      o.render["estimator"] = e;
    } else if (a == "--accelerator") {
      std::string e = value();
      if (e != "none" && e != "macrocell" && e != "octree" && e != "octree-voxelmax")
        UsageError("--accelerator expects none, macrocell, octree or octree-voxelmax, got '" + e + "'");
      o.render["accelerator"] = e;
    } else if (a == "--leaf-level")
      o.render["leaf_level"] = ParseInteger(a, value(), -1, 11);
    else if (a == "--output")
      o.output = value();
    else if (a == "--output-linear")
      o.outputLinear = value();
    else if (a == "--denoised-preview") {
      o.denoisedPreview = value();
      const std::string ext = LowerExtension(o.denoisedPreview);
      if (ext != ".png" && ext != ".pfm")
        UsageError("--denoised-preview expects a .png or .pfm file, got '" + o.denoisedPreview + "'");
    } else if (a == "--denoise") {
      const std::string m = value();
      const auto mode = mmrtm::ParseDenoisingMode(m);
      if (!mode) UsageError("--denoise expects off, auto or always, got '" + m + "'");
      o.denoise = *mode;
    } else if (a == "--output-variance")
      o.outputVariance = value();
    else if (a == "--output-denoiser-inputs")
      o.outputDenoiserInputs = value();
    else if (a == "--ray-march-step")
      o.render["ray_march_step"] = ParseReal(a, value());
    else if (a == "--stats-json")
      o.statsJson = value();
    else if (a == "--noise-target") {
      o.noiseTarget = ParseReal(a, value());
      if (!(o.noiseTarget > 0 && o.noiseTarget < 1))
        UsageError("--noise-target expects a relative noise in (0, 1), e.g. 0.01");
    } else if (a == "--light-sampling") {
      const std::string v = value();
      if (!mmrtm::ParseLightSampling(v)) UsageError("--light-sampling expects one, all or resampled, got '" + v + "'");
      o.render["light_sampling"] = v;
    } else if (a == "--sampling") {
      const std::string v = value();
      if (v != "uniform" && v != "adaptive") UsageError("--sampling expects uniform or adaptive, got '" + v + "'");
      o.adaptive = v == "adaptive";
    } else if (a == "--sampler") {
      const std::string v = value();
      if (!mmrtm::ParsePixelSampler(v)) UsageError("--sampler expects sobol or independent, got '" + v + "'");
      o.render["sampler"] = v;
    } else if (a == "--quiet")
      o.quiet = true;
    else if (a.size() > 1 && a[0] == '-')
      UsageError("unknown option " + a);
    else if (o.input.empty())
      o.input = a;
    else
      UsageError("more than one INPUT given ('" + o.input + "' and '" + a + "')");
  }
  return o;
}

// Fails early, before a long render, if an output cannot be written.
void CheckWritable(const std::string& path) {
  if (path.empty()) return;
  fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent))
    throw mmrtm::InputError(path + ": the folder " + parent.string() + " does not exist");
  if (fs::is_directory(path)) throw mmrtm::InputError(path + ": is a folder");
}

// Loading and building bars appear only for steps longer than this.
constexpr double kQuietStepSeconds = 0.5;

// A bar redrawn in place on a terminal; on a log (not a terminal) one line
// every 10 %.
class ProgressBar {
 public:
  // A bar with a `delay` shows only once that many seconds have passed, so
  // that a step that takes a moment (a small volume's loading) says nothing.
  explicit ProgressBar(bool enabled, std::string what = "Rendering", double delay = 0.0)
      : enabled_(enabled),
        terminal_(isatty(fileno(stderr))),
        what_(std::move(what)),
        delay_(delay),
        start_(std::chrono::steady_clock::now()) {}
  // A fraction of 1 (loading, building).
  void operator()(double fraction) { (*this)((int)(1000 * std::clamp(fraction, 0.0, 1.0)), 1000); }
  void operator()(int done, int total) {
    if (!enabled_) return;
    const double elapsed = Seconds();
    if ((elapsed < delay_ && lastPercent_ < 0) || lastPercent_ == 100) return;  // not yet shown, or finished
    const int percent = (int)(100.0 * done / total);
    const int step = terminal_ ? 1 : 10;
    if (percent / step == lastPercent_ / step && done != total) return;
    lastPercent_ = percent;
    const int width = 30, filled = width * done / total;
    const double eta = done > 0 ? elapsed * (total - done) / done : 0.0;
    std::fprintf(stderr, "%s%s [%s%s] %3d%%  %.1f s, %.0f s left%s", terminal_ ? "\r" : "", what_.c_str(),
                 std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), percent, elapsed, eta,
                 terminal_ && done != total ? " " : "\n");
    std::fflush(stderr);
  }
  double Seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

 private:
  bool enabled_, terminal_;
  std::string what_;
  double delay_;
  std::chrono::steady_clock::time_point start_;
  int lastPercent_ = -1;
};

// A loaded volume, after its warning (on stderr) when NaN voxels were
// replaced (HostVolume::ReplaceNanVoxels): rendered, and said once.
mmrtm::HostVolume WarnAboutNanVoxels(mmrtm::HostVolume volume) {
  if (volume.nanVoxelsReplaced > 0)
    std::fprintf(stderr, "warning: %s: %lld NaN voxel(s), rendered as the volume's least value\n",
                 volume.Where().c_str(), (long long)volume.nanVoxelsReplaced);
  return volume;
}

double SecondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// The size of the next pass towards a noise target, after `done` samples
// per pixel (the mean, with adaptive sampling) whose image has relative
// noise `noise`. The noise falls as 1 / sqrt(samples), so the target needs
// done (noise / target)^2 in all; 5 % more makes the check after the pass
// pass rather than ask for one more small pass. At least 4 samples, an even
// number (Film::Noise's two replicates stay the same size), at most twice
// what was done and 64: an estimate from few samples may be off (Sobol'
// samples converge faster than 1 / sqrt, which only makes it overshoot),
// and a pass is the step of the progress bar and of cancelling.
int NextPassTowards(double noiseTarget, double noise, double done) {
  const double ratio = noise / noiseTarget;
  const double missing = std::ceil(done * ratio * ratio * 1.05 - done);
  const int most = (int)std::min(2.0 * done, 64.0);
  const int pass = (int)std::clamp(missing, 4.0, (double)std::max(most, 4));
  return pass + (pass & 1);
}

// Uniform sampling. With a noise target the samples come in passes, 4 and
// then as many as the last noise says the target needs (NextPassTowards;
// a pass's cost is mostly its samples: each checks the noise once), and
// rendering stops after the first pass whose image meets the target. The
// passes continue one sample sequence, so the image equals the one
// rendered in one go with as many samples. Returns whether the target was
// reached.
bool RenderUniformly(mmrtm::Renderer& renderer, const mmrtm::Scene& scene, const mmrtm::SceneView& view,
                     mmrtm::Film& film, int spp, double noiseTarget, mmrtm::TraceCounters& counters, ProgressBar& bar) {
  int pass = noiseTarget > 0 ? 4 : spp;
  for (int done = 0; done < spp;) {
    pass = std::min(pass, spp - done);
    renderer.Render(scene, view, film, pass, &counters,
                    [&](int d, int t) { bar((int)(1000.0 * (done + pass * (double)d / t) / spp), 1000); });
    done += pass;
    if (noiseTarget > 0 && film.Samples() >= 2) {
      const double noise = film.Noise().relative;
      if (noise <= noiseTarget) return true;
      pass = NextPassTowards(noiseTarget, noise, done);
    }
  }
  return false;
}

// Adaptive sampling (adaptive_sampling.h): a uniform pilot pass (4 spp with
// a noise target, else spp / 8 up to 8), then passes that bring the mean to
// spp, or with a noise target to the mean that the last noise says the
// target needs (NextPassTowards), until the target is met. Every pass
// splits its mean by the pilot's weights, so a pixel's count never depends
// on its own samples. A pixel gets at most 16 times the mean.
bool RenderAdaptively(mmrtm::Renderer& renderer, const mmrtm::Scene& scene, const mmrtm::SceneView& view,
                      mmrtm::Film& film, int spp, double noiseTarget, mmrtm::TraceCounters& counters,
                      ProgressBar& bar) {
  const int pilot = noiseTarget > 0 ? 4 : std::clamp(spp / 8, 2, 8);
  film.TrackWork();
  renderer.Render(scene, view, film, pilot, &counters,
                  [&](int d, int t) { bar((int)(1000.0 * pilot * d / t / spp), 1000); });
  double noise = noiseTarget > 0 ? film.Noise().relative : 0.0;
  if (noiseTarget > 0 && noise <= noiseTarget) return true;
  const std::vector<float> weights = mmrtm::AdaptiveSampleWeights(film);
  for (double mean = pilot; mean < spp;) {
    const double before = film.MeanSamples();
    mean = noiseTarget > 0 ? std::min<double>(spp, mean + NextPassTowards(noiseTarget, noise, mean)) : spp;
    const std::vector<uint32_t> counts =
        mmrtm::AdaptiveSampleCounts(film, weights, mean, (uint32_t)std::min(16.0 * mean, 1e9));
    renderer.RenderTo(scene, view, film, counts, &counters,
                      [&](int d, int t) { bar((int)(1000.0 * (before + (mean - before) * d / t) / spp), 1000); });
    if (noiseTarget > 0) {
      noise = film.Noise().relative;
      if (noise <= noiseTarget) return true;
    }
  }
  return false;
}

// The denoised image (Documentation/denoising.md): the film denoised as the
// views' display denoises it, guided by its first-hit albedo and normal,
// and estimated from its halves with --denoise auto. Returns what
// --stats-json reports of it; `shown` says whether --output shows it.
json DenoiseFilm(const Options& o, mmrtm::Denoiser& denoiser, const mmrtm::Film& film, const mmrtm::RenderSettings& rs,
                 std::optional<mmrtm::DenoisedFilm>* denoised, bool* shown) {
  mmrtm::DenoisedDisplay display;
  display.SetMode(o.denoise == mmrtm::DenoisingMode::Off ? mmrtm::DenoisingMode::Always : o.denoise);
  display.Started();
  const mmrtm::FilmSnapshot snapshot = mmrtm::SnapshotFilm(film, 0);
  *denoised =
      mmrtm::DenoiseSnapshot(snapshot, display.WantsEstimate(0, film.Samples()), true, mmrtm::OidnDenoise(denoiser));
  display.Finished(*denoised);
  *shown = o.denoise != mmrtm::DenoisingMode::Off && display.Shown(0, film.Samples()) != nullptr;
  if (!o.denoisedPreview.empty()) {
    const mmrtm::RGBImage& image = (*denoised)->image;
    if (LowerExtension(o.denoisedPreview) == ".pfm") {  // else .png (ParseArguments)
      mmrtm::WritePFM(o.denoisedPreview, image);
    } else {
      std::vector<uint8_t> png((size_t)image.width * image.height * 3);
      for (size_t i = 0; i < image.pixels.size(); ++i)
        mmrtm::ToneMapPixel(image.pixels[i], rs.exposure, rs.toneMapper, &png[3 * i]);
      mmrtm::WritePNG(o.denoisedPreview, image.width, image.height, 3, png);
    }
  }
  json estimate = nullptr;
  if (const mmrtm::DenoiseEstimate* e = display.Estimate(0))
    estimate = {{"denoised_relative_error", std::sqrt(e->denoised) / e->meanValue},
                {"film_relative_error", std::sqrt(e->film) / e->meanValue}};
  return {{"mode", mmrtm::DenoisingModeName(o.denoise)},
          {"shown", *shown},
          {"biased", *shown},
          {"file", o.denoisedPreview.empty() ? json(nullptr) : json(o.denoisedPreview)},
          {"denoiser", denoiser.Description()},
          {"guides", film.Samples() >= 2 ? "first-hit albedo and normal, denoised" : "none (one sample)"},
          {"estimate", estimate},
          {"seconds", display.LastSeconds()}};
}

int ListSeries(const Options& o) {
  if (o.input.empty()) throw mmrtm::InputError("--list-series needs a DICOM folder as INPUT");
  for (const mmrtm::DicomSeriesSummary& s : mmrtm::ListDicomSeries(o.input))
    std::printf("%s\t%d slices\t%d x %d\t%s\t%s\n", s.uid.c_str(), s.slices, s.columns, s.rows, s.modality.c_str(),
                s.description.c_str());
  return 0;
}

int Run(const Options& o) {
  if (o.listSeries) return ListSeries(o);
  const auto tStart = std::chrono::steady_clock::now();
  mmrtm::RequireBackend(o.backend);
  CheckWritable(o.output);
  CheckWritable(o.outputLinear);
  CheckWritable(o.outputVariance);
  CheckWritable(o.statsJson);
  CheckWritable(o.denoisedPreview);
  if (!o.outputDenoiserInputs.empty()) CheckWritable(o.outputDenoiserInputs + "_albedo.pfm");
  // Found before a long render, or the denoising fails at the end.
  std::unique_ptr<mmrtm::Denoiser> denoiser;
  if (!o.denoisedPreview.empty() || o.denoise != mmrtm::DenoisingMode::Off)
    denoiser = mmrtm::Denoiser::Load(o.render.value("threads", 0));

  // The scene document: preset, then the scene file over it, then the options.
  json doc = json::object();
  std::string baseDirectory = ".";
  std::string preset = o.preset.empty() && o.scene.empty() ? "ct-bone" : o.preset;
  if (!preset.empty()) doc = mmrtm::ReadJsonFile(mmrtm::PresetPath(DataDirectory() + "/presets", preset));
  if (!o.scene.empty()) {
    doc.merge_patch(mmrtm::ReadJsonFile(o.scene));
    baseDirectory = fs::path(o.scene).parent_path().string();
    if (baseDirectory.empty()) baseDirectory = ".";
  }
  if (!o.render.empty()) doc["render"].merge_patch(o.render);

  mmrtm::SceneInputs inputs;
  inputs.baseDirectory = baseDirectory;
  inputs.loadVolume = [](const std::string& path, const std::string& name, mmrtm::Interpolation interp) {
    return WarnAboutNanVoxels(mmrtm::LoadVolume(path, name, interp));
  };
  const bool sceneHasScalars = doc.contains("volumes") && doc["volumes"].contains("scalars");
  const std::string input = !o.input.empty() ? o.input : (sceneHasScalars ? "" : mmrtm::DefaultVolumePath());
  if (!input.empty()) {
    if (!o.quiet) std::fprintf(stderr, "Loading %s\n", input.c_str());
    mmrtm::VolumeLoadOptions load;
    load.series = o.series;
    ProgressBar loading(!o.quiet, "Loading", kQuietStepSeconds);
    load.progress = [&](double fraction) { loading(fraction); };
    inputs.volumes["scalars"] = WarnAboutNanVoxels(mmrtm::LoadVolume(input, "scalars", load));
  } else if (!o.series.empty()) {
    throw mmrtm::InputError("--series needs a DICOM folder as INPUT");
  }
  std::optional<mmrtm::LabelTable> labelTable;
  if (!o.labelTable.empty()) {
    if (!doc.contains("label_materials"))
      std::fprintf(
          stderr,
          "warning: --label-table %s is not used: the scene has no \"label_materials\" (try --preset ct-organs)\n",
          o.labelTable.c_str());
    labelTable = mmrtm::ReadLabelTable(o.labelTable);
  }
  mmrtm::ExpandLabelMaterialsOnLoad(inputs, std::move(labelTable));
  if (!o.labels.empty()) {
    if (!o.quiet) std::fprintf(stderr, "Loading labels %s\n", o.labels.c_str());
    inputs.volumes["labels"] = WarnAboutNanVoxels(mmrtm::LoadVolume(o.labels, "labels", mmrtm::Interpolation::Nearest));
  }
  const double loadSeconds = SecondsSince(tStart);
  size_t inputVoxelBytes = 0;  // the volumes as read, in their own voxel types
  for (const auto& [name, volume] : inputs.volumes) inputVoxelBytes += volume.voxels.size();

  const auto tBuild = std::chrono::steady_clock::now();
  mmrtm::Scene scene = mmrtm::SceneFromJson(doc, std::move(inputs));
  ProgressBar building(!o.quiet, "Building the majorant grid", kQuietStepSeconds);
  scene.buildProgress = [&](double fraction) { building(fraction); };
  mmrtm::SceneView view = scene.Build();
  if (!scene.ExtinctionWarning().empty()) std::fprintf(stderr, "warning: %s\n", scene.ExtinctionWarning().c_str());
  const double buildSeconds = SecondsSince(tBuild);

  const mmrtm::RenderSettings& rs = scene.render;
  const auto note = [&](const std::string& text) {
    if (!o.quiet) std::fprintf(stderr, "note: %s\n", text.c_str());
  };
  if (!o.outputDenoiserInputs.empty() && rs.samplesPerPixel < 2)
    throw mmrtm::InputError("--output-denoiser-inputs needs 2 or more samples per pixel (the even and odd halves)");
  std::unique_ptr<mmrtm::Renderer> renderer = mmrtm::MakeRenderer(o.backend, rs.threads, note);
  mmrtm::Film film(rs.width, rs.height);
  if (denoiser || !o.outputDenoiserInputs.empty()) film.TrackDenoiserInputs();
  mmrtm::TraceCounters counters;
  if (!o.quiet)
    std::fprintf(stderr, "%d x %d, %d spp, %s, %s, majorant %.4g /mm\n", rs.width, rs.height, rs.samplesPerPixel,
                 renderer->Description().c_str(),
                 rs.integrator.estimator == mmrtm::Estimator::RayMarching ? "ray marching" : "delta tracking",
                 view.majorants.globalMajorant);
  ProgressBar bar(!o.quiet);
  const int spp = rs.samplesPerPixel;
  const bool reachedTarget = o.adaptive && spp >= 4
                                 ? RenderAdaptively(*renderer, scene, view, film, spp, o.noiseTarget, counters, bar)
                                 : RenderUniformly(*renderer, scene, view, film, spp, o.noiseTarget, counters, bar);
  if (reachedTarget) bar(1000, 1000);
  const double renderSeconds = bar.Seconds();

  json denoising = nullptr;
  std::optional<mmrtm::DenoisedFilm> denoised;
  bool showDenoised = false;
  // A projection's one sample is its image: there is no noise to take out.
  if (denoiser && rs.integrator.projection.mode == mmrtm::IntensityProjection::None)
    denoising = DenoiseFilm(o, *denoiser, film, rs, &denoised, &showDenoised);
  if (showDenoised) {
    std::vector<uint8_t> png((size_t)film.Width() * film.Height() * 3);
    for (size_t i = 0; i < denoised->image.pixels.size(); ++i)
      mmrtm::ToneMapPixel(denoised->image.pixels[i], rs.exposure, rs.toneMapper, &png[3 * i]);
    mmrtm::WritePNG(o.output, film.Width(), film.Height(), 3, png);
  } else {
    mmrtm::WritePNG(o.output, film.Width(), film.Height(), 3, film.ToneMapped(rs.exposure, rs.toneMapper));
  }
  if (!o.outputLinear.empty()) mmrtm::WritePFM(o.outputLinear, film.Linear());
  if (!o.outputVariance.empty()) mmrtm::WritePFM(o.outputVariance, film.VarianceOfMeanImage());
  if (!o.outputDenoiserInputs.empty()) {
    const mmrtm::FilmHalves h = film.DenoiserImages();
    const std::string& p = o.outputDenoiserInputs;
    for (int half = 0; half < 2; ++half) {
      const std::string suffix = half == 0 ? "_even" : "_odd";
      mmrtm::WritePFM(p + "_color" + suffix + ".pfm", h.color[half]);
      mmrtm::WritePFM(p + "_albedo" + suffix + ".pfm", h.albedo[half]);
      mmrtm::WritePFM(p + "_normal" + suffix + ".pfm", h.normal[half]);
    }
    mmrtm::WritePFM(p + "_albedo.pfm", h.albedoWhole);
    mmrtm::WritePFM(p + "_normal.pfm", h.normalWhole);
  }

  const mmrtm::NoiseEstimate noise = film.Noise();
  const double samples = (double)film.Width() * film.Height() * film.MeanSamples();
  if (!o.quiet)
    std::fprintf(stderr, "Wrote %s: %.4g spp%s%s, %.2f s render, %.3g samples/s, relative noise %.3g\n",
                 o.output.c_str(), film.MeanSamples(), film.Adaptive() ? " (mean, adaptive)" : "",
                 reachedTarget ? " (noise target reached)" : "", renderSeconds, samples / renderSeconds,
                 noise.relative);
  if (denoiser && denoising.is_null() && !o.quiet)
    std::fprintf(stderr, "note: a projection is not denoised (its one sample is its image)\n");
  if (!denoising.is_null() && !o.quiet) {
    std::string estimate;
    if (!denoising["estimate"].is_null()) {
      char text[128];
      std::snprintf(text, sizeof text, "; estimated relative error %.3g denoised, %.3g unbiased",
                    denoising["estimate"]["denoised_relative_error"].get<double>(),
                    denoising["estimate"]["film_relative_error"].get<double>());
      estimate = text;
    }
    std::fprintf(stderr, "Denoised in %.2f s%s%s%s%s\n", denoising["seconds"].get<double>(), estimate.c_str(),
                 o.denoise == mmrtm::DenoisingMode::Off ? ""
                 : showDenoised                         ? "; --output shows it (biased)"
                                                        : "; --output shows the unbiased image",
                 o.denoisedPreview.empty() ? "" : "; wrote ", o.denoisedPreview.c_str());
  }
  if (!o.statsJson.empty()) {
    json stats = {
        {"input", input},
        {"width", film.Width()},
        {"height", film.Height()},
        {"spp", film.Adaptive() ? json(film.MeanSamples()) : json(film.Samples())},
        {"sampling", film.Adaptive() ? "adaptive" : "uniform"},
        {"sampler", mmrtm::PixelSamplerName(rs.integrator.sampler)},
        {"spp_min", film.Samples()},
        {"spp_max", film.MaxSamples()},
        {"noise_target", o.noiseTarget > 0 ? json(o.noiseTarget) : json(nullptr)},
        {"stopped_on", reachedTarget ? "noise_target" : "spp"},
        {"threads", rs.threads > 0 ? rs.threads : (int)std::thread::hardware_concurrency()},
        {"backend", renderer->Description()},
        {"seed", rs.integrator.seed},
        {"estimator", rs.integrator.estimator == mmrtm::Estimator::RayMarching ? "raymarch" : "delta"},
        {"shadow_extinction_scale", rs.integrator.shadowExtinctionScale},
        {"global_majorant", view.majorants.globalMajorant},
        {"seconds",
         {{"load", loadSeconds}, {"build", buildSeconds}, {"render", renderSeconds}, {"total", SecondsSince(tStart)}}},
        {"samples", samples},
        {"samples_per_second", samples / renderSeconds},
        {"paths", counters.paths},
        {"real_collisions", counters.realCollisions},
        {"null_collisions", counters.nullCollisions},
        {"density_lookups", counters.densityLookups},
        {"shadow_rays", counters.shadowRays},
        {"majorant_segments", counters.majorantSegments},
        {"majorant_violations", counters.majorantViolations},
        {"density_lookups_per_real_collision",
         counters.realCollisions ? (double)counters.densityLookups / counters.realCollisions : 0.0},
        {"memory", MemoryJson(scene, view, inputVoxelBytes)},
        {"denoising", denoising},
        {"noise",
         {{"mean_luminance", noise.meanLuminance},
          {"rms_standard_error", noise.rmsStandardError},
          {"relative", noise.relative}}}};
    const std::string tmp = o.statsJson + ".partial";
    {
      std::ofstream out(tmp);
      out << stats.dump(2) << "\n";
      if (!out) throw std::runtime_error(o.statsJson + ": write failed");
    }
    fs::rename(tmp, o.statsJson);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options = ParseArguments(argc, argv);
  try {
    return Run(options);
  } catch (const mmrtm::InputError& e) {
    std::fprintf(stderr, "\nmmrtm-render: error: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\nmmrtm-render: error: %s\n", e.what());
  }
  return 1;
}
