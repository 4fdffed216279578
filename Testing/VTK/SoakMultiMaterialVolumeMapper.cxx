// A soak of vtkMultiMaterialVolumeMapper as a long viewer session uses it:
// thousands of random transfer-function edits, camera moves, label toggles,
// input swaps and window resizes, with the resident memory sampled as it
// goes; then the cases that end sessions badly: two windows sharing one
// input, ReleaseGraphicsResources followed by rendering again, the input
// removed while a pass refines in the background, the window closed while
// it refines.
//
//   SoakMultiMaterialVolumeMapper [--iterations N] [--seed S] [--csv FILE]
//
// Prints the memory curve (iteration, resident MB) and a summary; exits 1
// when a check fails: an error from the mapper where none is due, an image
// with a value that is not finite or an empty image where the volume is in
// view, the two windows' images differing, no error when the input is
// removed. Resident memory is reported, not asserted (Documentation/
// reliability.md gives the figures); leaks are LeakSanitizer's to find: in
// an AddressSanitizer build the leak check runs before the program exits,
// while a window keeps the OpenGL driver loaded (at exit, or once the last
// window is gone, its allocations show as leaks of an unknown module that
// no suppression can name).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <unistd.h>
#include <vector>

#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkExecutive.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPointData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkShortArray.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>
#include <vtkWindowToImageFilter.h>

#include "vtkMultiMaterialVolumeMapper.h"

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MMRTM_SOAK_LSAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define MMRTM_SOAK_LSAN 1
#endif
#ifdef MMRTM_SOAK_LSAN
#include <sanitizer/lsan_interface.h>
#endif

namespace
{
int failures = 0;

void Check(bool ok, const std::string& what)
{
  if (!ok)
  {
    std::cerr << "FAILED: " << what << "\n";
    ++failures;
  }
}

double ResidentMB()
{
  long pages = 0, resident = 0;
  std::ifstream statm("/proc/self/statm");
  statm >> pages >> resident;
  return resident * (double)sysconf(_SC_PAGESIZE) / (1024.0 * 1024.0);
}

// Counts the error events of the objects it observes.
struct ErrorCounter
{
  int errors = 0;
  std::string last;
  vtkNew<vtkCallbackCommand> command;
  ErrorCounter()
  {
    command->SetClientData(this);
    command->SetCallback(
      [](vtkObject*, unsigned long, void* self, void* message)
      {
        auto* counter = static_cast<ErrorCounter*>(self);
        ++counter->errors;
        counter->last = message ? static_cast<const char*>(message) : "";
      });
  }
  void Observe(vtkObject* object) { object->AddObserver(vtkCommand::ErrorEvent, command); }
};

// A ball of values 0 to 1000 (highest at the centre) as shorts or floats,
// `n` voxels a side, and a label map of shells around it (labels 1 to 3).
vtkSmartPointer<vtkImageData> Ball(int n, bool floats, double spacing)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(n, n, n);
  image->SetSpacing(spacing, spacing, spacing);
  image->SetOrigin(-0.5 * n * spacing, -0.5 * n * spacing, -0.5 * n * spacing);
  vtkSmartPointer<vtkDataArray> values;
  if (floats)
    values = vtkSmartPointer<vtkFloatArray>::New();
  else
    values = vtkSmartPointer<vtkShortArray>::New();
  values->SetNumberOfTuples((vtkIdType)n * n * n);
  const double c = 0.5 * (n - 1);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
      {
        const double r = std::sqrt((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c)) / c;
        values->SetTuple1(i + (vtkIdType)n * (j + (vtkIdType)n * k), std::max(0.0, 1000.0 * (1.0 - r)));
      }
  image->GetPointData()->SetScalars(values);
  return image;
}

vtkSmartPointer<vtkImageData> Shells(vtkImageData* like)
{
  int dims[3];
  like->GetDimensions(dims);
  auto labels = vtkSmartPointer<vtkImageData>::New();
  labels->CopyStructure(like);
  vtkNew<vtkUnsignedCharArray> values;
  values->SetNumberOfTuples(like->GetNumberOfPoints());
  vtkDataArray* scalars = like->GetPointData()->GetScalars();
  for (vtkIdType p = 0; p < like->GetNumberOfPoints(); ++p)
  {
    const double v = scalars->GetTuple1(p);
    values->SetValue(p, v > 700 ? 3 : v > 400 ? 2 : v > 100 ? 1 : 0);
  }
  labels->GetPointData()->SetScalars(values);
  return labels;
}

// One window, renderer, volume and mapper.
struct View
{
  vtkNew<vtkRenderWindow> window;
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkVolume> volume;
  vtkNew<vtkMultiMaterialVolumeMapper> mapper;
  vtkNew<vtkVolumeProperty> property;
  vtkNew<vtkPiecewiseFunction> opacity;
  vtkNew<vtkColorTransferFunction> color;
  vtkNew<vtkPiecewiseFunction> labelOpacity[4];
  vtkNew<vtkColorTransferFunction> labelColor[4];
  ErrorCounter errors;

  View(int width, int height)
  {
    this->mapper->SetBackendToCPU();
    this->mapper->SetSeed(7);
    this->mapper->SetSamplesPerRender(1);
    this->mapper->SetMaximumSamples(4);
    this->opacity->AddPoint(0, 0.0);
    this->opacity->AddPoint(1000, 0.5);
    this->color->AddRGBPoint(0, 0.9, 0.6, 0.5);
    this->color->AddRGBPoint(1000, 1.0, 1.0, 0.9);
    this->property->SetScalarOpacity(this->opacity);
    this->property->SetColor(this->color);
    this->property->ShadeOn();
    for (int label = 1; label <= 3; ++label)
    {
      this->labelOpacity[label]->AddPoint(0, 0.0);
      this->labelOpacity[label]->AddPoint(1000, 0.8);
      this->labelColor[label]->AddRGBPoint(0, label == 1, label == 2, label == 3);
    }
    this->volume->SetMapper(this->mapper);
    this->volume->SetProperty(this->property);
    this->renderer->AddVolume(this->volume);
    this->window->SetOffScreenRendering(1);
    this->window->AddRenderer(this->renderer);
    this->window->SetSize(width, height);
    this->errors.Observe(this->mapper);
    this->errors.Observe(this->mapper->GetExecutive()); // a missing input is the pipeline's error
  }

  void SetLabelVisible(int label, bool visible)
  {
    if (visible)
    {
      this->property->SetLabelScalarOpacity(label, this->labelOpacity[label]);
      this->property->SetLabelColor(label, this->labelColor[label]);
    }
    else
    {
      // As Slicer hides a segment: its opacity function is zero.
      vtkNew<vtkPiecewiseFunction> none;
      none->AddPoint(0, 0.0);
      this->property->SetLabelScalarOpacity(label, none);
    }
  }

  // The accumulated image: false when it holds a value that is not finite;
  // `covered` is the fraction of pixels with alpha above 0.05.
  bool Film(double& covered, std::vector<float>* copy = nullptr)
  {
    vtkNew<vtkImageData> film;
    this->mapper->GetAccumulatedImage(film);
    vtkDataArray* rgba = film->GetPointData()->GetScalars();
    covered = 0;
    if (!rgba)
      return true;
    const vtkIdType n = rgba->GetNumberOfTuples();
    bool finite = true;
    for (vtkIdType p = 0; p < n; ++p)
    {
      for (int c = 0; c < 4; ++c)
      {
        const double v = rgba->GetComponent(p, c);
        finite = finite && std::isfinite(v);
        if (copy)
          copy->push_back((float)v);
      }
      covered += rgba->GetComponent(p, 3) > 0.05;
    }
    covered /= std::max<vtkIdType>(n, 1);
    return finite;
  }
};

struct Options
{
  int iterations = 2000;
  unsigned seed = 1;
  std::string csv;
};

// The random session: returns the resident-memory curve.
void Soak(const Options& options, std::vector<std::pair<int, double>>& curve)
{
  std::mt19937 random(options.seed);
  auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
  auto pick = [&](int n) { return std::uniform_int_distribution<int>(0, n - 1)(random); };

  const vtkSmartPointer<vtkImageData> inputs[3] = { Ball(40, false, 1.0), Ball(28, true, 1.5), Ball(48, false, 0.8) };
  vtkSmartPointer<vtkImageData> labels[3];
  for (int i = 0; i < 3; ++i)
    labels[i] = Shells(inputs[i]);

  View view(96, 96);
  int current = 0;
  view.mapper->SetInputData(inputs[current]);
  view.mapper->SetMaskInput(labels[current]);
  view.mapper->SetMaskTypeToLabelMap();
  for (int label = 1; label <= 3; ++label)
    view.SetLabelVisible(label, true);
  view.renderer->ResetCamera();

  const char* actions[] = { "tf", "camera", "label", "input", "resize", "async" };
  int counts[6] = { 0 };
  int emptyImages = 0, nonFinite = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int it = 0; it <= options.iterations; ++it)
  {
    if (it % 100 == 0)
    {
      curve.emplace_back(it, ResidentMB());
      std::cout << "iteration " << it << ": resident " << curve.back().second << " MB" << std::endl;
    }
    if (it == options.iterations)
      break;
    const int action = pick(6);
    ++counts[action];
    switch (action)
    {
      case 0: // a transfer-function edit: move, add or remove a point
      {
        vtkPiecewiseFunction* f = view.opacity;
        const int what = pick(3);
        if (what == 0 || f->GetSize() < 3)
          f->AddPoint(uniform(0, 1000), uniform(0, 0.8));
        else if (what == 1)
        {
          double node[4];
          f->GetNodeValue(1 + pick(f->GetSize() - 2), node); // an inner point
          f->RemovePoint(node[0]);
        }
        else
        {
          double node[4];
          const int i = pick(f->GetSize());
          f->GetNodeValue(i, node);
          node[1] = uniform(0, 0.8);
          f->SetNodeValue(i, node);
        }
        if (f->GetSize() > 12)
        {
          f->RemoveAllPoints();
          f->AddPoint(0, 0.0);
          f->AddPoint(1000, 0.5);
        }
        if (pick(2))
          view.color->AddRGBPoint(uniform(0, 1000), uniform(0, 1), uniform(0, 1), uniform(0, 1));
        if (view.color->GetSize() > 12)
        {
          view.color->RemoveAllPoints();
          view.color->AddRGBPoint(0, 0.9, 0.6, 0.5);
          view.color->AddRGBPoint(1000, 1.0, 1.0, 0.9);
        }
        break;
      }
      case 1: // a camera move
      {
        vtkCamera* camera = view.renderer->GetActiveCamera();
        camera->Azimuth(uniform(-30, 30));
        camera->Elevation(uniform(-20, 20));
        camera->OrthogonalizeViewUp();
        if (pick(4) == 0)
          view.renderer->ResetCamera();
        break;
      }
      case 2: // a label shown or hidden
        view.SetLabelVisible(1 + pick(3), pick(2) != 0);
        break;
      case 3: // another input (and its labels)
        current = (current + 1 + pick(2)) % 3;
        view.mapper->SetInputData(inputs[current]);
        view.mapper->SetMaskInput(labels[current]);
        view.renderer->ResetCamera();
        break;
      case 4: // a window resize
        view.window->SetSize(48 + pick(112), 48 + pick(112));
        break;
      case 5: // refinement on or off its own thread
        view.mapper->SetAsynchronousRefinement(!view.mapper->GetAsynchronousRefinement());
        break;
    }
    view.window->Render();
    if (pick(3) == 0)
      view.window->Render(); // a second pass, as an idle viewer does
    double covered = 0;
    if (!view.Film(covered))
      ++nonFinite;
    // After a camera reset the ball is in view; with every label hidden and
    // a TF edit it may legitimately be nearly transparent, so only count.
    if (covered == 0)
      ++emptyImages;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "soak: " << options.iterations << " iterations in " << seconds << " s ("
            << 1000.0 * seconds / std::max(options.iterations, 1) << " ms each); actions";
  for (int a = 0; a < 6; ++a)
    std::cout << " " << actions[a] << " " << counts[a];
  std::cout << "; empty images " << emptyImages << "; renders " << view.mapper->GetNumberOfSceneBuilds()
            << " scene builds, " << view.mapper->GetNumberOfRefits() << " refits, "
            << view.mapper->GetNumberOfRestarts() << " restarts" << std::endl;
  Check(view.errors.errors == 0, "no mapper error during the soak (last: " + view.errors.last + ")");
  Check(nonFinite == 0, "every image finite during the soak (" + std::to_string(nonFinite) + " were not)");
  Check(emptyImages <= options.iterations / 2, "the volume visible in most images");
  // Finishes with a pass in flight: the view is destroyed while it refines.
  view.mapper->AsynchronousRefinementOn();
  view.mapper->SetMaximumSamples(64);
  view.mapper->Modified();
  view.window->Render();
}

// Two windows whose mappers share one input: same settings, same images;
// an edit of the shared input reaches both.
void TwoWindowsShareAnInput()
{
  const vtkSmartPointer<vtkImageData> input = Ball(32, false, 1.0);
  View a(80, 60), b(80, 60);
  for (View* v : { &a, &b })
  {
    v->mapper->SetInputData(input);
    v->renderer->ResetCamera();
  }
  std::vector<float> filmA, filmB;
  double coveredA = 0, coveredB = 0;
  for (int round = 0; round < 2; ++round)
  {
    for (int pass = 0; pass < 4; ++pass)
    {
      a.window->Render();
      b.window->Render();
    }
    filmA.clear();
    filmB.clear();
    Check(a.Film(coveredA, &filmA) && b.Film(coveredB, &filmB), "two windows: finite images");
    Check(coveredA > 0.1, "two windows: the first shows the volume");
    Check(filmA == filmB, "two windows: the same image from the same input and settings");
    // Edit the shared input: both see the change.
    vtkDataArray* values = input->GetPointData()->GetScalars();
    for (vtkIdType p = 0; p < values->GetNumberOfTuples(); p += 2)
      values->SetTuple1(p, 0.0);
    input->Modified();
  }
  Check(a.errors.errors == 0 && b.errors.errors == 0, "two windows: no error");
  std::cout << "two windows sharing an input: equal images, " << coveredA << " of the pixels covered" << std::endl;
}

// The window's pixels: how many differ from black.
int Lit(vtkRenderWindow* window)
{
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkDataArray* rgb = grab->GetOutput()->GetPointData()->GetScalars();
  int lit = 0;
  for (vtkIdType p = 0; p < rgb->GetNumberOfTuples(); ++p)
    lit += rgb->GetComponent(p, 0) + rgb->GetComponent(p, 1) + rgb->GetComponent(p, 2) > 0;
  return lit;
}

// Graphics released, then rendering again, as applications do it: the
// mapper's resources (a view dropping the volume, vtkVolume's
// ReleaseGraphicsResources) or the whole window's (Finalize, as when a view
// is rebuilt; it makes a new OpenGL context). The first frame after it
// shows the volume, and the film and the window's pixels equal those before.
void ReleaseThenRender(bool wholeWindow)
{
  const std::string what = wholeWindow ? "window Finalize" : "mapper ReleaseGraphicsResources";
  const vtkSmartPointer<vtkImageData> input = Ball(32, true, 1.0);
  View view(80, 60);
  view.mapper->SetInputData(input);
  view.renderer->ResetCamera();
  for (int pass = 0; pass < 4; ++pass)
    view.window->Render();
  std::vector<float> before, after;
  double covered = 0, firstCovered = 0;
  view.Film(covered, &before);
  const int litBefore = Lit(view.window);
  if (wholeWindow)
    view.window->Finalize();
  else
    view.mapper->ReleaseGraphicsResources(view.window);
  view.mapper->ResetAccumulation();
  for (int pass = 0; pass < 4; ++pass)
  {
    view.window->Render();
    if (pass == 0)
      view.Film(firstCovered);
  }
  view.Film(covered, &after);
  const int litAfter = Lit(view.window);
  size_t differing = before.size() == after.size() ? 0 : std::max(before.size(), after.size());
  for (size_t i = 0; i < std::min(before.size(), after.size()); ++i)
    differing += before[i] != after[i];
  Check(firstCovered > 0.1, what + " then Render: the first frame shows the volume");
  Check(covered > 0.1 && differing == 0,
    what + " then Render: the same film (" + std::to_string(differing) + " values differ)");
  Check(litBefore > 100 && litAfter == litBefore,
    what + " then Render: the same pixels lit (" + std::to_string(litBefore) + ", then " + std::to_string(litAfter) +
      ")");
  Check(view.errors.errors == 0, what + " then Render: no error");
  std::cout << what << " then render: " << differing << " film values differ, " << litAfter << " of " << litBefore
            << " pixels lit" << std::endl;
}

// The input removed while a pass refines on its thread: an error on the
// next render (no input), no crash; a new input renders again.
void InputRemovedWhileRefining()
{
  const vtkSmartPointer<vtkImageData> input = Ball(48, false, 1.0);
  View view(128, 128);
  view.mapper->SetInputData(input);
  view.mapper->AsynchronousRefinementOn();
  view.mapper->SetMaximumSamples(256);
  view.renderer->ResetCamera();
  view.window->Render();
  view.window->Render(); // starts a background pass
  const bool wasRefining = view.mapper->IsRefining();
  view.mapper->RemoveAllInputConnections(0);
  view.window->Render();
  Check(view.errors.errors > 0, "input removed: an error names the missing input");
  std::cout << "input removed while refining (a pass was " << (wasRefining ? "" : "not ") << "in flight): error \""
            << view.errors.last.substr(0, 120) << "\"" << std::endl;
  const int errorsBefore = view.errors.errors;
  view.mapper->SetInputData(input);
  view.mapper->AsynchronousRefinementOff();
  view.mapper->SetMaximumSamples(2);
  view.window->Render();
  double covered = 0;
  Check(view.Film(covered) && covered > 0.1, "input given back: the volume renders again");
  Check(view.errors.errors == errorsBefore, "input given back: no new error");
}

// The window closed while a pass refines: nothing crashes, the pass stops.
void WindowClosedWhileRefining()
{
  const vtkSmartPointer<vtkImageData> input = Ball(48, false, 1.0);
  auto view = std::make_unique<View>(160, 160);
  view->mapper->SetInputData(input);
  view->mapper->AsynchronousRefinementOn();
  view->mapper->SetMaximumSamples(1024);
  view->renderer->ResetCamera();
  view->window->Render();
  view->window->Render();
  const bool wasRefining = view->mapper->IsRefining();
  view->window->Finalize(); // the user closes the window
  view.reset();             // and the application lets go of it all
  std::cout << "window closed while refining (a pass was " << (wasRefining ? "" : "not ") << "in flight): no crash"
            << std::endl;
}
} // namespace

int main(int argc, char* argv[])
{
  Options options;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "--iterations" && i + 1 < argc)
      options.iterations = std::atoi(argv[++i]);
    else if (arg == "--seed" && i + 1 < argc)
      options.seed = (unsigned)std::atoi(argv[++i]);
    else if (arg == "--csv" && i + 1 < argc)
      options.csv = argv[++i];
    else
    {
      std::cerr << "usage: " << argv[0] << " [--iterations N] [--seed S] [--csv FILE]\n";
      return 2;
    }
  }
#ifdef MMRTM_SOAK_LSAN
  // A window that outlives the leak check: Mesa unloads its driver when the
  // last window closes, and the driver's allocations would then show as
  // leaks of an unknown module that no suppression can name.
  vtkNew<vtkRenderWindow> keepDriverLoaded;
  keepDriverLoaded->SetOffScreenRendering(1);
  keepDriverLoaded->SetSize(8, 8);
  keepDriverLoaded->Render();
#endif
  std::vector<std::pair<int, double>> curve;
  Soak(options, curve);
  TwoWindowsShareAnInput();
  ReleaseThenRender(false);
  ReleaseThenRender(true);
  InputRemovedWhileRefining();
  WindowClosedWhileRefining();

  // The memory curve: growth from the first tenth (warm: every input, size
  // and cache seen) to the end.
  if (curve.size() >= 3)
  {
    const double warm = curve[std::max<size_t>(1, curve.size() / 10)].second, last = curve.back().second;
    const double peak =
      std::max_element(curve.begin(), curve.end(), [](auto& x, auto& y) { return x.second < y.second; })->second;
    std::printf("resident memory: %.1f MB at iteration %d, %.1f MB at the end (%+.1f MB), peak %.1f MB\n", warm,
      curve[std::max<size_t>(1, curve.size() / 10)].first, last, last - warm, peak);
  }
  if (!options.csv.empty())
  {
    std::ofstream out(options.csv);
    out << "iteration,resident_mb\n";
    for (const auto& [it, mb] : curve)
      out << it << "," << mb << "\n";
  }
#ifdef MMRTM_SOAK_LSAN
  // Every object of the soak is gone; leaks now are leaks (see the top).
  std::cout << "LeakSanitizer: checking now" << std::endl;
  __lsan_do_leak_check();
#endif
  std::cout << (failures ? "soak FAILED" : "soak passed") << std::endl;
  return failures ? 1 : 0;
}
