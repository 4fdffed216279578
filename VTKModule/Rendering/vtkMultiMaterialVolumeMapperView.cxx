// Reading the view (camera, lights, viewport, clipping, the depth of the
// opaque geometry) by value, the film a change of it restarts, and the
// interactive previews.
#include "vtkMultiMaterialVolumeMapperInternals.h"

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>

#include <vtkCamera.h>
#include <vtkLight.h>
#include <vtkLightCollection.h>
#include <vtkPlane.h>
#include <vtkPlaneCollection.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>

namespace
{
// Global illumination off: the shadow rays' extinction scale. The tracer
// takes a scale above 0; at this one a shadow ray through the densest
// tissue the translation makes (an optical depth of 64 per voxel) over
// 1000 voxels transmits 0.94, everything lighter nearly 1.
constexpr float kLocalLightingShadowScale = 1e-6f;

// Camera, lights, the volume's matrix and the viewport, as values: a change
// restarts the accumulation. Values rather than modification times, because
// VTK swaps in near copies (vtkWindowToImageFilter renders with a copy of
// the camera whose view angle is off by 1e-8): a screenshot must not restart.
std::vector<double> ViewSignature(vtkRenderer* ren, vtkVolume* vol, int width, int height)
{
  std::vector<double> v{ static_cast<double>(width), static_cast<double>(height) };
  auto add = [&v](const double* p, int n) { v.insert(v.end(), p, p + n); };
  vtkCamera* cam = ren->GetActiveCamera();
  add(cam->GetPosition(), 3);
  add(cam->GetFocalPoint(), 3);
  add(cam->GetViewUp(), 3);
  add(cam->GetWindowCenter(), 2);
  v.push_back(cam->GetViewAngle());
  v.push_back(cam->GetParallelProjection());
  v.push_back(cam->GetParallelScale());
  vtkNew<vtkMatrix4x4> m;
  vol->GetMatrix(m);
  add(&m->Element[0][0], 16);
  vtkLightCollection* lights = ren->GetLights();
  lights->InitTraversal();
  while (vtkLight* l = lights->GetNextItem())
  {
    double p[3], f[3];
    l->GetTransformedPosition(p);
    l->GetTransformedFocalPoint(f);
    add(p, 3);
    add(f, 3);
    add(l->GetDiffuseColor(), 3);
    v.push_back(l->GetIntensity());
    v.push_back(l->GetSwitch());
    v.push_back(l->GetPositional());
  }
  return v;
}

// Equal to a relative 1e-6: vtkWindowToImageFilter renders with a camera
// whose view angle went through tan and atan.
bool SameView(const std::vector<double>& a, const std::vector<double>& b)
{
  if (a.size() != b.size())
    return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::abs(a[i] - b[i]) > 1e-6 * std::max({ 1.0, std::abs(a[i]), std::abs(b[i]) }))
      return false;
  return true;
}

// The depth buffer of the viewport (opaque geometry drawn before volumes),
// window depth in [0, 1], rows bottom first; empty without any geometry.
std::vector<float> ReadDepth(vtkRenderer* ren, int width, int height, int x0, int y0)
{
  std::vector<float> depth(static_cast<size_t>(width) * height, 1.f);
  ren->GetRenderWindow()->GetZbufferData(x0, y0, x0 + width - 1, y0 + height - 1, depth.data());
  for (float z : depth)
    if (z < 1.f)
      return depth;
  return {};
}

// Pixels of a film over `size` viewport pixels at an image sample distance.
int FilmSize(int size, double distance)
{
  return std::max(1, static_cast<int>(std::ceil(size / distance - 1e-9)));
}

// The viewport's depth buffer (width x height) at the pixel centres of a
// film of w x h stretched over it.
std::vector<float> DepthAtFilmPixels(const std::vector<float>& depth, int width, int height, int w, int h)
{
  if (w == width && h == height)
    return depth;
  std::vector<float> at(static_cast<size_t>(w) * h);
  for (int row = 0; row < h; ++row)
    for (int x = 0; x < w; ++x)
    {
      const int fx = std::min(width - 1, static_cast<int>((x + 0.5) * width / w));
      const int fy = std::min(height - 1, static_cast<int>((row + 0.5) * height / h));
      at[static_cast<size_t>(row) * w + x] = depth[static_cast<size_t>(fy) * width + fx];
    }
  return at;
}

// Per pixel (rows top first, as the film): the distance along the camera
// ray to the geometry in the depth buffer, kInfinity where there is none.
// Perspective rays start at the camera, orthographic ones in the plane
// through it.
std::vector<float> CameraRayMaxDistance(vtkRenderer* ren, const std::vector<float>& depth, int width, int height)
{
  vtkCamera* camera = ren->GetActiveCamera();
  vtkNew<vtkMatrix4x4> inverse;
  inverse->DeepCopy(camera->GetCompositeProjectionTransformMatrix(ren->GetTiledAspectRatio(), -1, 1));
  inverse->Invert();
  const double* eye = camera->GetPosition();
  double dir[3];
  camera->GetDirectionOfProjection(dir);
  const bool parallel = camera->GetParallelProjection() != 0;
  std::vector<float> t(depth.size(), mmrtm::kInfinity);
  for (int row = 0; row < height; ++row)
    for (int x = 0; x < width; ++x)
    {
      const float z = depth[static_cast<size_t>(row) * width + x];
      if (z >= 1.f)
        continue;
      const double ndc[4] = { 2.0 * (x + 0.5) / width - 1.0, 2.0 * (row + 0.5) / height - 1.0, 2.0 * z - 1.0, 1.0 };
      double p[4];
      inverse->MultiplyPoint(ndc, p);
      double d[3], len2 = 0, along = 0;
      for (int k = 0; k < 3; ++k)
      {
        d[k] = p[k] / p[3] - eye[k];
        len2 += d[k] * d[k];
        along += d[k] * dir[k];
      }
      t[static_cast<size_t>(height - 1 - row) * width + x] = static_cast<float>(parallel ? along : std::sqrt(len2));
    }
  return t;
}

mmrtm::Affine3 ToAffine(vtkMatrix4x4* m)
{
  mmrtm::Affine3 a;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      a.m[r][c] = static_cast<float>(m->GetElement(r, c));
  return a;
}

// The cropping regions of any flags but the subvolume's (ClipPlanes clips
// that one exactly), tested per point in the data's coordinates.
mmrtm::Scene::Cropping CroppingRegions(vtkVolumeMapper* mapper, vtkVolume* vol)
{
  mmrtm::Scene::Cropping cropping;
  if (!mapper->GetCropping() || mapper->GetCroppingRegionFlags() == VTK_CROP_SUBVOLUME)
    return cropping;
  vtkNew<vtkMatrix4x4> inverse;
  vol->GetMatrix(inverse);
  inverse->Invert();
  cropping.worldToData = ToAffine(inverse);
  cropping.keep = static_cast<uint32_t>(mapper->GetCroppingRegionFlags()) & mmrtm::Classifier::kNoCropping;
  const double* planes = mapper->GetCroppingRegionPlanes();
  for (int a = 0; a < 3; ++a)
  {
    cropping.lo[a] = static_cast<float>(planes[2 * a]);
    cropping.hi[a] = static_cast<float>(planes[2 * a + 1]);
  }
  return cropping;
}
}

void vtkMultiMaterialVolumeMapper::Internals::ReadView(
  vtkRenderer* ren, vtkVolume* vol, const int viewport[4], InputState::ViewInputs& view)
{
  // Camera, lights, matrix, viewport (by value), clipping, the environment,
  // the opaque geometry (its depth), and the mapper's own settings.
  view.Width = viewport[0];
  view.Height = viewport[1];
  // VTK's still image: at the least distance when the distances adapt,
  // else at ImageSampleDistance; below 1 is 1 (samples cover a pixel).
  const double distance = std::max(1.0,
    static_cast<double>(
      Self->AutoAdjustSampleDistances ? Self->MinimumImageSampleDistance : Self->ImageSampleDistance));
  view.FilmWidth = FilmSize(viewport[0], distance);
  view.FilmHeight = FilmSize(viewport[1], distance);
  view.Values = ViewSignature(ren, vol, view.FilmWidth, view.FilmHeight);
  view.Values.insert(
    view.Values.end(), { static_cast<double>(view.Width), static_cast<double>(view.Height) });
  view.Clip = this->ClipPlanes(vol);
  for (const mmrtm::ClipPlane& p : view.Clip)
    view.Values.insert(view.Values.end(), { p.normal.x, p.normal.y, p.normal.z, p.offset });
  this->UpdateEnvironment();
  view.Values.push_back(static_cast<double>(this->EnvironmentTime));
  view.Depth = ReadDepth(ren, viewport[0], viewport[1], viewport[2], viewport[3]);
  view.TracingTime = Self->GetTracingMTime();
  view.Renderer = ren;
  view.Volume = vol;
  const int* tiles = ren->GetRenderWindow()->GetTileScale();
  view.Tile = tiles[0] > 1 || tiles[1] > 1;
}

// The same camera, lights, matrix, viewport, clipping and environment (by
// value), the same opaque geometry, and no change of what the mapper traces.
bool vtkMultiMaterialVolumeMapper::Internals::SameViewInputs(
  const InputState::ViewInputs& a, const InputState::ViewInputs& b)
{
  return SameView(a.Values, b.Values) && a.Depth == b.Depth && a.TracingTime == b.TracingTime;
}

void vtkMultiMaterialVolumeMapper::Internals::UpdateView(vtkRenderer* ren, vtkVolume* vol, InputState& now)
{
  // A restart: a new film under the current camera, lights and settings.
  Internals& in = *this;
  vol->GetMatrix(in.Matrix);
  const mmrtm::Affine3 propMatrix = ToAffine(in.Matrix);
  for (size_t i = 0; i < in.Scene.proxies.size(); ++i)
    in.Scene.proxies[i].indexToWorld = mmrtm::AffineCompose(propMatrix, in.ImageIndexToWorld[i]);
  mmrtm::SetCameraFromVtk(ren->GetActiveCamera(), in.Scene);
  const int width = now.View.FilmWidth, height = now.View.FilmHeight;
  // Camera rays stop at opaque geometry: it hides the volume behind it,
  // and the volume in front of it hides it.
  in.Scene.cameraRayMaxDistance = now.View.Depth.empty()
    ? std::vector<float>()
    : CameraRayMaxDistance(
        ren, DepthAtFilmPixels(now.View.Depth, now.View.Width, now.View.Height, width, height), width, height);
  if (!in.LightsFromScene)
    mmrtm::SetLightsFromVtk(ren, now.Materials.Property, in.Scene);
  if (in.Environment)
    in.Scene.environment = in.Environment;
  in.Scene.clipPlanes = now.View.Clip;
  in.Scene.cropping = CroppingRegions(Self, vol);
  mmrtm::RenderSettings& rs = in.Scene.render;
  rs.width = width;
  rs.height = height;
  rs.threads = Self->NumberOfThreads;
  rs.exposure = static_cast<float>(Self->Exposure);
  rs.integrator.seed = static_cast<uint64_t>(Self->Seed);
  // Local lighting: shadow rays see (almost) nothing, and light scatters once.
  rs.integrator.shadowExtinctionScale =
    Self->GlobalIllumination ? static_cast<float>(Self->ShadowExtinctionScale) : kLocalLightingShadowScale;
  // Materials that only glow (unshaded, as VTK) need no light and no bounce.
  rs.integrator.maxBounces = !mmrtm::AnyMaterialScatters(in.Scene) ? 0
    : Self->GlobalIllumination                                     ? Self->MaximumBounces
                                                                   : 1;
  rs.integrator.sampler = Self->Sampler == INDEPENDENT ? mmrtm::PixelSampler::Independent : mmrtm::PixelSampler::Sobol;
  rs.accelerator.kind = Self->Accelerator == MACROCELL ? mmrtm::MajorantKind::Macrocell
    : Self->Accelerator == NO_ACCELERATOR              ? mmrtm::MajorantKind::Global
                                                       : mmrtm::MajorantKind::Octree;
  rs.integrator.backgroundVisible = false; // VTK's background shows through
  rs.integrator.projection = this->Projection(now.Materials.Property);
  this->TakeFilm(now);
  in.Built.View = std::move(now.View);
  in.HasScene = true;
}

std::vector<mmrtm::ClipPlane> vtkMultiMaterialVolumeMapper::Internals::ClipPlanes(vtkVolume* vol)
{
  std::vector<mmrtm::ClipPlane> planes;
  // Clipping planes, in world space: the side the normal points to is kept.
  if (Self->ClippingPlanes)
  {
    Self->ClippingPlanes->InitTraversal();
    while (vtkPlane* plane = Self->ClippingPlanes->GetNextItem())
    {
      const double* n = plane->GetNormal();
      const double* o = plane->GetOrigin();
      mmrtm::ClipPlane p;
      p.normal = { static_cast<float>(n[0]), static_cast<float>(n[1]), static_cast<float>(n[2]) };
      p.offset = static_cast<float>(-(n[0] * o[0] + n[1] * o[1] + n[2] * o[2]));
      planes.push_back(p);
    }
  }
  // Subvolume cropping, in the data's coordinates (before the volume's
  // matrix): six axis-aligned half-spaces, taken to world space through the
  // inverse transpose of the matrix.
  if (Self->Cropping && Self->CroppingRegionFlags == VTK_CROP_SUBVOLUME)
  {
    vtkNew<vtkMatrix4x4> inverse;
    vol->GetMatrix(inverse);
    inverse->Invert();
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side)
      {
        // Data space: sign * (x[axis] - bound) >= 0.
        const double sign = side == 0 ? 1.0 : -1.0, bound = Self->CroppingRegionPlanes[2 * axis + side];
        double n[3], d = -sign * bound;
        for (int c = 0; c < 3; ++c)
          n[c] = sign * inverse->GetElement(axis, c);
        d += sign * inverse->GetElement(axis, 3);
        mmrtm::ClipPlane p;
        p.normal = { static_cast<float>(n[0]), static_cast<float>(n[1]), static_cast<float>(n[2]) };
        p.offset = static_cast<float>(d);
        planes.push_back(p);
      }
  }
  const bool tooMany = static_cast<int>(planes.size()) > mmrtm::kMaxClipPlanes;
  if (this->Warn("clipping planes", tooMany))
    vtkWarningWithObjectMacro(Self, "only " << mmrtm::kMaxClipPlanes << " clipping and cropping planes are used");
  if (tooMany)
    planes.resize(mmrtm::kMaxClipPlanes);
  return planes;
}

mmrtm::ProjectionSettings vtkMultiMaterialVolumeMapper::Internals::Projection(vtkVolumeProperty* property)
{
  // VTK's projection blend modes (mmrtm/projection.h), sampled as VTK's GPU
  // mapper samples them: with AutoAdjustSampleDistances on (its default) at
  // the smallest spacing of the volume in world space, else SampleDistance.
  Internals& in = *this;
  mmrtm::ProjectionSettings p;
  switch (Self->BlendMode)
  {
    case vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND:
      p.mode = mmrtm::IntensityProjection::Maximum;
      break;
    case vtkVolumeMapper::MINIMUM_INTENSITY_BLEND:
      p.mode = mmrtm::IntensityProjection::Minimum;
      break;
    case vtkVolumeMapper::AVERAGE_INTENSITY_BLEND:
      p.mode = mmrtm::IntensityProjection::Average;
      break;
    case vtkVolumeMapper::ADDITIVE_BLEND:
      p.mode = mmrtm::IntensityProjection::Additive;
      break;
    default:
      return p; // composite (and isosurface, warned about): traced
  }
  const mmrtm::HostVolume& volume = in.Scene.proxies.at(0);
  float step = mmrtm::kInfinity;
  for (int axis = 0; axis < 3; ++axis)
  {
    const mmrtm::Affine3& m = volume.indexToWorld;
    step = std::min(
      step, std::sqrt(m.m[0][axis] * m.m[0][axis] + m.m[1][axis] * m.m[1][axis] + m.m[2][axis] * m.m[2][axis]));
  }
  p.step = step > 0.f ? step : 1.f;
  if (!Self->AutoAdjustSampleDistances && Self->SampleDistance > 0.f)
    p.step = Self->SampleDistance;
  const double unit = property->GetScalarOpacityUnitDistance(0);
  p.opacityUnitDistance = unit > 0.0 ? static_cast<float>(unit) : 1.f;
  p.valueRange[0] = in.Layout.scalarRange[0]; // the input's (BuildProxies), not scanned per restart
  p.valueRange[1] = in.Layout.scalarRange[1];
  p.averageRange[0] = static_cast<float>(std::max<double>(Self->AverageIPScalarRange[0], -FLT_MAX));
  p.averageRange[1] = static_cast<float>(std::min<double>(Self->AverageIPScalarRange[1], FLT_MAX));
  return p;
}

// The film for the view `now`: the parked one when it was made under this very
// view, else a new one (a restart). The film of the view before is parked
// when the view is a tile, or another renderer's or volume's view of this
// mapper, and the film before was neither a tile nor empty: after a
// magnified screenshot, and between the views of a mapper shared by two
// renderers, each view goes on accumulating.
void vtkMultiMaterialVolumeMapper::Internals::TakeFilm(const InputState& now)
{
  Internals& in = *this;
  const InputState::ViewInputs& view = now.View;
  const InputState::ViewInputs& before = in.Built.View;
  const bool otherView = view.Tile || view.Renderer != before.Renderer || view.Volume != before.Volume;
  std::unique_ptr<mmrtm::Film> previous = std::move(in.Film);
  const bool keepPrevious = otherView && previous && previous->Samples() > 0 && !before.Tile;
  const InputState::ViewInputs& parked = in.ParkedView;
  if (in.ParkedFilm && !view.Tile && SameViewInputs(view, parked) && view.Renderer == parked.Renderer &&
    view.Volume == parked.Volume)
  {
    in.Film = std::move(in.ParkedFilm);
  }
  else
  {
    in.Film = std::make_unique<mmrtm::Film>(view.FilmWidth, view.FilmHeight);
    in.Film->TrackDenoiserInputs();
    ++in.Restarts;
  }
  if (keepPrevious)
  {
    in.ParkedFilm = std::move(previous);
    in.ParkedView = before;
  }
  in.Shown.reset(); // the image of the view before
  ++in.FilmGeneration;
}

double vtkMultiMaterialVolumeMapper::Internals::RenderPreview(vtkRenderer* ren, int width, int height)
{
  Internals& in = *this;
  const double distance = Self->AutoAdjustSampleDistances
    ? in.PreviewDistance
    : std::max(1.0, static_cast<double>(Self->ImageSampleDistance));
  const int w = FilmSize(width, distance), h = FilmSize(height, distance);
  mmrtm::RenderSettings& rs = in.Scene.render;
  rs.width = w;
  rs.height = h;
  const std::vector<float>& fullDepth = in.Built.View.Depth;
  if (!fullDepth.empty())
    in.Scene.cameraRayMaxDistance = CameraRayMaxDistance(ren, DepthAtFilmPixels(fullDepth, width, height, w, h), w, h);
  const mmrtm::SceneView view = this->BuildScene();
  in.CountGridWork();
  in.Preview = std::make_unique<mmrtm::Film>(w, h);
  const auto start = std::chrono::steady_clock::now();
  in.Renderer->Render(in.Scene, view, *in.Preview, 1, nullptr, nullptr);
  ++in.TracedPasses;
  // Denoised on its colour alone, at OIDN's fast quality: one sample's
  // guides are as noisy as its colour, and the frame has a budget.
  in.PreviewDenoised.reset();
  if (this->DenoisingApplies() && this->DenoiserReady())
  {
    const auto denoiseStart = std::chrono::steady_clock::now();
    in.Denoiser->SetQuality(mmrtm::Denoiser::Quality::Fast);
    try
    {
      in.PreviewDenoised =
        mmrtm::DenoiseSnapshot(mmrtm::SnapshotFilm(*in.Preview, 0), false, false, mmrtm::OidnDenoise(*in.Denoiser));
    }
    catch (const mmrtm::DenoiserError& e)
    {
      vtkErrorWithObjectMacro(Self, "Render: the denoiser failed: " << e.what());
    }
    in.Denoiser->SetQuality(mmrtm::Denoiser::Quality::Balanced);
    in.PreviewDenoiseSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - denoiseStart).count();
    ++in.PreviewDenoises;
  }
  // The still render after the interaction starts again at full resolution.
  in.Film.reset();
  ++in.InteractiveRenders;
  // The denoise scales with the pixels as the tracing does (AdaptPreview).
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void vtkMultiMaterialVolumeMapper::Internals::AdaptPreview(double seconds, double tracedSeconds, double budgetSeconds)
{
  // The tracing time scales with the film's pixels, 1 / distance^2; the
  // rest of the frame (reading the inputs and the depth, drawing) is taken
  // as fixed. The distance that would have fit the budget, averaged
  // (geometrically) with the one used, so that one noisy frame does not
  // swing the next.
  Internals& in = *this;
  if (!Self->AutoAdjustSampleDistances)
    return;
  const double least = std::max(1.0, static_cast<double>(Self->MinimumImageSampleDistance));
  const double most = std::max(least, static_cast<double>(Self->MaximumImageSampleDistance));
  const double d = in.PreviewDistance;
  const double forTracing = std::max(0.1 * budgetSeconds, budgetSeconds - (seconds - tracedSeconds));
  const double fits = d * std::sqrt(std::max(tracedSeconds, 1e-6) / forTracing);
  in.PreviewDistance = std::min(most, std::max(least, std::sqrt(d * fits)));
}
