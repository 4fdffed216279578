// Surface scattering in a rendered scene, against an answer computed here:
// a convex opaque object made from a volume.
//
// The object: a sphere of radius R as a float signed-distance volume, a
// steep density step on it (a CCTF), surface probability 1 (every real
// collision scatters on the BSDF at the gradient normal), in a uniform
// environment L and no other light; an orthographic camera.
//
// What is analytic. An ideal sphere would return L A(wo) (A the BSDF's
// directional albedo) at every pixel. A volume-made one does not, at any
// steepness: a collision lies at an optical depth tau ~ Exp(1) along the
// camera ray inside the step, and every ray that leaves it (the shadow
// ray, the next path segment) must first get out through the same step.
// Locally the step is a half-space whose density varies along the normal
// only, so the collision lies at optical depth tau cos_o below the surface
// along the normal, and tau cos_o / cos_i along a direction at cos_i. What
// arrives from the environment after one scattering is then, in expectation
// over tau,
//   L R1(wo),  R1(wo) = integral of f(wo, wi) cos_i cos_i / (cos_i + cos_o) dwi,
// whatever the density's scale and profile (the "self-occlusion" of paper
// section 3.3 and Figure 2: R1 / A is 0.39 for a diffuse surface seen
// head-on). Light scattered more than once also bounces between surface
// particles inside the step, which has no closed form; Mitsuba checks that
// (Testing/Accuracy/mitsuba_surface_check.py). So these scenes render
// single scattering (max bounces 1: the camera ray's collision, next-event
// estimation and the BSDF-sampled ray to the environment, combined by MIS)
// and compare with L R1(wo), with R1 from the reference BSDF
// (ReferenceBSDF.h) by quadrature.
//
// How far the volume-made sphere departs from that half-space answer, and
// how the tolerance follows from it: see kDeparture below and
// DISABLED_DepartureAgainstSteepness, which measures it.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "ImageAgreement.h"
#include "ReferenceBSDF.h"
#include "ReplicateRenders.h"
#include "TestSceneHelpers.h"
#include "cpu_renderer.h"

namespace mmrtm {
namespace {

using namespace test;

constexpr double kFalseFailure = 1e-4;
constexpr double kRequiredPower = 0.03;  // a 3 % change of one lobe fails

// The sphere: radius 24 voxels of 1 mm in a 56^3 volume; the density
// sigma * clamp((d + w/2) / w, 0, 1) of the signed distance d (mm, positive
// inside). sigma = 64 / mm is the most the scene allows at 1 mm voxels
// (kMaxOpticalDepthPerVoxel), w = 0.25 mm a quarter of a voxel.
constexpr int kVolume = 56;
constexpr double kRadius = 24;
constexpr double kCentre = (kVolume - 1) / 2.0;
constexpr float kSteepDensity = 64.f, kSteepWidth = 0.25f;
const RGB kEnvironment(0.9f, 1.f, 1.1f);
// Pixels whose footprint sees the ideal sphere at cos_o >= this.
constexpr double kMinCosine = 0.5;

// Relative departure of the volume-made sphere from L R1 over the pixels
// at cos_o >= kMinCosine, at kSteepDensity and kSteepWidth: measured by
// DISABLED_DepartureAgainstSteepness (64^2 pixels, 1024 samples each) as
// -0.02 % +- 0.08 % for the dielectric and +0.03 % +- 0.08 % for the metal
// (and within 0.23 % +- 0.23 % in every ring of cos_o), against +0.5 % and
// +0.3 % for a step of 4 / mm over 2 mm, whose rings depart by up to 1.3 %.
// This bound is what the measurement allows (its value plus two standard
// errors): the rendered sums are held to |rendered / expected - 1| <=
// kDeparture + z sigma.
constexpr double kDeparture = 0.002;

struct SphereMaterial {
  const char* name;
  Rgb3 base;
  float roughness, metallic;
};
// A dielectric whose diffuse lobe carries most of the light, and a metal
// (specular lobe only).
const SphereMaterial kDielectric{"dielectric", {0.8, 0.6, 0.4}, 0.6f, 0.f};
const SphereMaterial kMetal{"metal", {0.9, 0.75, 0.5}, 0.4f, 1.f};

Scene SphereScene(const SphereMaterial& m, float density, float width, int size) {
  HostVolume volume = MakeVolume(kVolume, kVolume, kVolume, [](int i, int j, int k) {
    const double x = i - kCentre, y = j - kCentre, z = k - kCentre;
    return (float)(kRadius - std::sqrt(x * x + y * y + z * z));
  });
  Scene s = MakeMediumScene(std::move(volume), density, RGB((float)m.base[0], (float)m.base[1], (float)m.base[2]));
  s.tfs[0].keys = {-0.5f * width, 0.5f * width};
  s.tfs[0].values = {0.f, 1.f};
  s.materials[0].base[4] = m.roughness;
  s.materials[0].base[5] = m.metallic;
  s.materials[0].base[6] = 1.f;  // every collision is a surface event
  s.environment = EnvironmentMap::Constant(kEnvironment);
  s.camera.autoFrame = false;
  s.camera.projection = Projection::Orthographic;
  s.camera.position = {(float)kCentre, (float)kCentre - 100.f, (float)kCentre};
  s.camera.lookAt = {(float)kCentre, (float)kCentre, (float)kCentre};
  s.camera.up = {0.f, 0.f, 1.f};
  s.camera.orthoHeight = 2.2f * (float)kRadius;
  s.render.width = s.render.height = size;
  s.render.integrator.maxBounces = 1;
  s.render.integrator.sampler = PixelSampler::Independent;
  return s;
}

// R1(cos_o) per channel (file comment), and its diffuse part, tabulated for
// cos_o in [kMinCosine - 0.05, 1] and interpolated by 4-point Lagrange.
class SingleScatteringTable {
 public:
  explicit SingleScatteringTable(const SphereMaterial& m) : ref_(ReferenceBSDF::Make(m.base, m.roughness, m.metallic)) {
    for (int i = 0; i < kNodes; ++i) {
      const double c = Node(i);
      const auto [total, diffuse] = Integrate(c);
      total_.push_back(total);
      diffuse_.push_back(diffuse);
    }
  }
  static double Node(int i) { return kLow + (1 - kLow) * i / (kNodes - 1); }

  // The integral, at cos_o: {all of it, the diffuse lobe's part}.
  std::array<Rgb3, 2> Integrate(double cosO) const {
    const D3 wo = OutgoingAt(cosO);
    Rgb3 total{}, diffuse{};
    ReflectedDirectionQuadrature(wo, ref_.alpha, [&](D3 wi, double w) {
      const double escape = wi.z / (wi.z + cosO);
      const Rgb3 d = ref_.DiffuseFCos(wo, wi), s = ref_.SpecularFCos(wo, wi);
      for (int c = 0; c < 3; ++c) {
        total[c] += w * escape * (d[c] + s[c]);
        diffuse[c] += w * escape * d[c];
      }
    });
    return {total, diffuse};
  }
  Rgb3 Total(double cosO) const { return Interpolate(total_, cosO); }
  Rgb3 Diffuse(double cosO) const { return Interpolate(diffuse_, cosO); }

 private:
  static constexpr int kNodes = 33;
  static constexpr double kLow = kMinCosine - 0.05;
  Rgb3 Interpolate(const std::vector<Rgb3>& table, double cosO) const {
    const double x = (cosO - kLow) / (1 - kLow) * (kNodes - 1);
    const int i0 = std::clamp((int)std::floor(x) - 1, 0, kNodes - 4);
    Rgb3 out{};
    for (int a = 0; a < 4; ++a) {
      double l = 1;
      for (int b = 0; b < 4; ++b)
        if (b != a) l *= (x - (i0 + b)) / (double)(a - b);
      for (int c = 0; c < 3; ++c) out[c] += l * table[i0 + a][c];
    }
    return out;
  }
  ReferenceBSDF ref_;
  std::vector<Rgb3> total_, diffuse_;
};

// The expected image: per pixel, L R1 averaged over the box-filtered pixel
// (8 x 8 positions), for pixels whose corners all see the ideal sphere at
// cos_o >= kMinCosine; `covered` marks them, `cosine` holds the pixel
// centre's cos_o (0 elsewhere).
struct ExpectedImage {
  ImageEstimate total, diffuse;
  std::vector<char> covered;
  std::vector<double> cosine;
};

ExpectedImage Expected(const SceneView& view, const SingleScatteringTable& table) {
  const int W = view.camera.width, H = view.camera.height;
  const D3 centre{kCentre, kCentre, kCentre};
  auto cosineAt = [&](double px, double py) {
    const Ray r = view.camera.GenerateRay((float)px, (float)py, 0.f, 0.f);
    const D3 o{r.o.x, r.o.y, r.o.z}, d = Normalized({r.d.x, r.d.y, r.d.z});
    const D3 toCentre = centre - o, across = toCentre - d * Dot(toCentre, d);
    const double b2 = Dot(across, across) / (kRadius * kRadius);
    return b2 < 1 ? std::sqrt(1 - b2) : -1.0;
  };
  ExpectedImage e;
  for (ImageEstimate* im : {&e.total, &e.diffuse}) {
    im->width = W;
    im->height = H;
    im->mean.assign((size_t)W * H * 3, 0.0);
    im->variance.assign((size_t)W * H * 3, 0.0);
  }
  e.covered.assign((size_t)W * H, 0);
  e.cosine.assign((size_t)W * H, 0.0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      bool inside = true;
      for (int corner = 0; corner < 4; ++corner) inside &= cosineAt(x + corner % 2, y + corner / 2) >= kMinCosine;
      if (!inside) continue;
      const size_t p = (size_t)y * W + x;
      e.covered[p] = 1;
      e.cosine[p] = cosineAt(x + 0.5, y + 0.5);
      const int n = 8;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const double c = cosineAt(x + (i + 0.5) / n, y + (j + 0.5) / n);
          const Rgb3 t = table.Total(c), d = table.Diffuse(c);
          for (int ch = 0; ch < 3; ++ch) {
            e.total.mean[p * 3 + ch] += kEnvironment[ch] * t[ch] / (n * n);
            e.diffuse.mean[p * 3 + ch] += kEnvironment[ch] * d[ch] / (n * n);
          }
        }
    }
  return e;
}

// The render and the expected image over the covered pixels: per channel
// the relative difference of their sums and its standard error.
struct SumComparison {
  Rgb3 relative{}, standardError{}, diffuseShare{};
  size_t pixels = 0;
};

SumComparison CompareSums(const ImageEstimate& rendered, const ExpectedImage& e,
                          const std::function<bool(size_t)>& select) {
  SumComparison r;
  for (int c = 0; c < 3; ++c) {
    double a = 0, b = 0, var = 0, diffuse = 0;
    size_t n = 0;
    for (size_t p = 0; p < e.covered.size(); ++p) {
      if (!e.covered[p] || !select(p)) continue;
      a += rendered.mean[p * 3 + c];
      b += e.total.mean[p * 3 + c];
      var += rendered.variance[p * 3 + c];
      diffuse += e.diffuse.mean[p * 3 + c];
      ++n;
    }
    r.relative[c] = a / b - 1;
    r.standardError[c] = std::sqrt(var) / b;
    r.diffuseShare[c] = diffuse / b;
    r.pixels = n;
  }
  return r;
}

Film Render(const SceneView& view, int spp, uint64_t seed) {
  SceneView v = view;
  v.settings.seed = seed;
  Film film(v.camera.width, v.camera.height);
  CpuRenderer(2).Render(v, film, spp);
  return film;
}

// The interpolated table against the integral between its nodes.
TEST(SurfaceScene, SingleScatteringTableIsTheIntegral) {
  for (const SphereMaterial& m : {kDielectric, kMetal}) {
    const SingleScatteringTable table(m);
    for (int i = 0; i + 1 < 33; i += 5) {
      const double c = 0.5 * (SingleScatteringTable::Node(i) + SingleScatteringTable::Node(i + 1));
      const Rgb3 direct = table.Integrate(c)[0], interpolated = table.Total(c);
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(interpolated[ch], direct[ch], 1e-6 * direct[ch]) << m.name << " " << c;
    }
  }
}

// The rendered sphere against L R1 over the covered pixels:
//  - the global test, per channel: |sum rendered / sum expected - 1| <=
//    kDeparture + z_limit sigma, sigma from the independent samples'
//    variances (a sum over about 2000 pixels: normal); z_limit two-sided
//    over the channels with half of the false-failure budget;
//  - the block test of ImageAgreement.h (4 x 4 blocks of z^2, the other
//    half) against the expected image as a noiseless estimate, which
//    catches a change in how the radiance varies with the angle.
// Power: a relative change of one lobe of kDeparture + (z_limit + z_power)
// sigma over that lobe's share of the sum fails with probability
// 1 - 1e-4; asserted below 3 % for the lobe each case is there for.
void CheckSphere(const SphereMaterial& m, bool diffuseLobe) {
  const int size = 64, replicates = 8, spp = 8;
  Scene scene = SphereScene(m, kSteepDensity, kSteepWidth, size);
  scene.render.integrator.sampler = PixelSampler::Sobol;
  const SceneView view = scene.Build();
  const SingleScatteringTable table(m);
  const ExpectedImage expected = Expected(view, table);
  const ImageEstimate rendered = RenderReplicates(view, replicates, spp, 101);

  const SumComparison sums = CompareSums(rendered, expected, [](size_t) { return true; });
  const double zLimit = NormalQuantile(1 - kFalseFailure / 2 / (2 * 3)), zPower = NormalQuantile(1 - kFalseFailure);
  for (int c = 0; c < 3; ++c) {
    const double limit = kDeparture + zLimit * sums.standardError[c];
    const double share = diffuseLobe ? sums.diffuseShare[c] : 1 - sums.diffuseShare[c];
    const double power = (kDeparture + (zLimit + zPower) * sums.standardError[c]) / share;
    std::printf(
        "%s, channel %d: rendered / expected - 1 = %+.4f (limit %.4f: departure %.4f + %.2f sigma, sigma "
        "%.4f, %zu pixels); power: the %s lobe (%.0f %% of the light) changed by %.2f %% fails\n",
        m.name, c, sums.relative[c], limit, kDeparture, zLimit, sums.standardError[c], sums.pixels,
        diffuseLobe ? "diffuse" : "specular", 100 * share, 100 * power);
    EXPECT_LE(std::fabs(sums.relative[c]), limit) << m.name << " channel " << c;
    EXPECT_LE(power, kRequiredPower) << m.name << " channel " << c;
  }

  // The block test on the covered pixels only: the rest set to agree
  // without noise (replicates included, from which the block variances
  // come), so that blocks outside add no terms.
  ImageEstimate a = rendered, b = expected.total;
  b.degreesOfFreedom = 0;
  for (size_t p = 0; p < expected.covered.size(); ++p)
    if (!expected.covered[p])
      for (int c = 0; c < 3; ++c) {
        a.mean[p * 3 + c] = b.mean[p * 3 + c] = 0;
        a.variance[p * 3 + c] = 0;
        for (std::vector<float>& r : a.replicates) r[p * 3 + c] = 0;
      }
  AgreementOptions options;
  options.falseFailure = kFalseFailure / 2;
  const Agreement agreement = test::Compare(a, b, options);
  std::printf("%s: block mean z^2 %.3f (limit %.3f, %zu terms)\n", m.name, agreement.blockMeanZ2, agreement.blockLimit,
              agreement.blockTerms);
  EXPECT_TRUE(agreement.BlocksAgree()) << m.name << ": " << agreement.Describe();
}

TEST(SurfaceScene, DielectricSphereIsSingleScatteringOfTheBSDF) { CheckSphere(kDielectric, true); }
TEST(SurfaceScene, MetalSphereIsSingleScatteringOfTheBSDF) { CheckSphere(kMetal, false); }

// Measures the departure of the volume-made sphere from L R1 against the
// steepness of its density step, by rings of cos_o, at many samples:
//   build/bin/TestSurfaceScenes --gtest_also_run_disabled_tests --gtest_filter='*Departure*'
// (about 5 minutes on 2 cores).
TEST(SurfaceScene, DISABLED_DepartureAgainstSteepness) {
  struct Step {
    float density, width;
  };
  const int size = 64, spp = 1024;
  const double rings[] = {0.5, 0.7, 0.85, 0.95, 1.0001};
  for (const SphereMaterial& m : {kDielectric, kMetal}) {
    const SingleScatteringTable table(m);
    for (Step step : {Step{4.f, 2.f}, Step{16.f, 1.f}, Step{64.f, 1.f}, Step{64.f, kSteepWidth}}) {
      Scene scene = SphereScene(m, step.density, step.width, size);
      const SceneView view = scene.Build();
      const ExpectedImage expected = Expected(view, table);
      const ImageEstimate rendered = FromIndependentSamples(Render(view, spp, 7));
      std::printf("%s, density %g / mm over %g mm:", m.name, step.density, step.width);
      const SumComparison all = CompareSums(rendered, expected, [](size_t) { return true; });
      std::printf(" all %+.4f +- %.4f;", all.relative[1], all.standardError[1]);
      for (int r = 0; r + 1 < 5; ++r) {
        const SumComparison ring = CompareSums(rendered, expected, [&](size_t p) {
          return expected.cosine[p] >= rings[r] && expected.cosine[p] < rings[r + 1];
        });
        std::printf(" cos %.2f-%.2f %+.4f +- %.4f;", rings[r], std::min(1.0, rings[r + 1]), ring.relative[1],
                    ring.standardError[1]);
      }
      std::printf("\n");
    }
  }
}

}  // namespace
}  // namespace mmrtm
