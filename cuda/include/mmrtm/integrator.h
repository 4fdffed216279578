// The per-pixel MM-RTM path integrator (paper sections 3.1-3.2).
//
// A path is traced by free-path sampling. At each real collision:
//   - the emission term sigma_t * Le is collected (DVR's opacity-weighted
//     emission);
//   - with probability P_fs the collision is a surface-scattering particle:
//     the BSDF on the gradient normal, whose own albedo holds the surface
//     absorption; otherwise a volume-scattering particle: the throughput is
//     multiplied by the single-scattering albedo and the HG phase scatters;
//   - next-event estimation samples one light and estimates the shadow ray's
//     transmittance (ratio tracking, with the shadow extinction scale);
//   - a new direction is sampled from the BSDF or phase function.
// Environment light is combined by multiple importance sampling (power
// heuristic) between light sampling and BSDF/phase sampling; delta lights are
// reached by next-event estimation only. Russian roulette and a bounce limit
// end long paths.
#pragma once

#include "mmrtm/bsdf.h"
#include "mmrtm/phase.h"
#include "mmrtm/planted_defect.h"
#include "mmrtm/sobol.h"
#include "mmrtm/tracking.h"

namespace mmrtm {

// The pairs of low-discrepancy numbers of a pixel sample (mmrtm/sobol.h),
// with IntegratorSettings::sampler Sobol: the pixel position, the lens, and
// the first kSobolVertices vertices of the path, where a pixel's samples
// differ most in what they see (where the camera ray first collides, which
// particle scatters there, the light it samples, how much of that light
// arrives and the direction the path leaves in). The rest of the path draws
// from its PCG32 stream.
constexpr int kPairPixel = 0;
constexpr int kPairLens = 1;
constexpr int kPairFirstVertex = 2;
constexpr int kSobolVertices = 2;
// Each vertex's pairs, from kPairFirstVertex + depth * kPairsPerVertex:
constexpr int kPairFreePath = 0;   // the free path's first arrival and its real-or-null choice
constexpr int kPairParticle = 1;   // surface or volume particle; the BSDF lobe
constexpr int kPairLight = 2;      // the light sample of next-event estimation
constexpr int kPairShadow = 3;     // the shadow ray's first arrival; which light
constexpr int kPairDirection = 4;  // the scattered direction
constexpr int kPairsPerVertex = 5;

// Uses uniform u for a choice of probability p and returns a uniform again,
// for the next choice (the part of [0, 1) that u fell in, stretched), so
// that one stratified number can make a sequence of choices.
MMRTM_CPU_GPU inline bool ChooseAndReuse(float p, float* u) {
  if (*u < p) {
    *u = Min(*u / p, kOneMinusEpsilon);
    return true;
  }
  *u = Min((*u - p) / (1.f - p), kOneMinusEpsilon);
  return false;
}

// `cameraTMax`: how far the camera ray may go (opaque geometry of the host
// application in front, e.g. a VTK mesh); beyond it the pixel is not the
// volume's and nothing (not even the environment) is seen.
// `pairs`, when given, supplies the first vertices' numbers.
MMRTM_CPU_GPU inline PixelSample Li(const SceneView& s, Ray ray, PCG32& rng, TraceCounters& ctr,
                                    float cameraTMax = kInfinity, const SobolPairs* pairs = nullptr) {
  PixelSample out;
  RGB beta(1.f);
  float scatterPdf = 0.f;  // pdf of the last sampled direction, for MIS
  // With one light every mode is the same estimator: One's code and random
  // numbers, so images of one-light scenes do not depend on the mode.
  const LightSampling lightSampling = s.lightCount == 1 ? LightSampling::One : s.settings.lightSampling;
  // The probability that NEE samples a given light, for the MIS weights:
  // 1/K when it picks one of K uniformly; 1 when it estimates the sum over
  // all lights (All, and Resampled, which estimates that same sum).
  float lightSelectPdf = s.lightCount <= 0                     ? 0.f
                         : lightSampling == LightSampling::One ? 1.f / (float)s.lightCount
                                                               : 1.f;
  for (int depth = 0;; ++depth) {
    // This vertex's low-discrepancy pairs, or none (then rng).
    const SobolPairs* ld = depth < kSobolVertices ? pairs : nullptr;
    const int pairBase = kPairFirstVertex + depth * kPairsPerVertex;
    float ldFreePath[2];
    if (ld) ld->Get(pairBase + kPairFreePath, &ldFreePath[0], &ldFreePath[1]);
    FreePathResult fp =
        SampleFreePath(s, ray, depth == 0 ? cameraTMax : kInfinity, rng, ctr, ld ? ldFreePath : nullptr);
    if (!fp.collided) {
      if (depth == 0 && cameraTMax < kInfinity) break;  // stopped at opaque geometry
      if (s.environmentLight >= 0) {
        if (depth == 0) {
          if (s.settings.backgroundVisible) {
            const RGB Le = s.environment.Le(ray.d);
            out.L += beta * Le;
            // The background as the albedo guide, clamped to an albedo's
            // range (OIDN's advice for what a camera ray sees directly).
            if (s.settings.firstHitGuides) out.albedo = RGB(Min(1.f, Le.r), Min(1.f, Le.g), Min(1.f, Le.b));
          }
        } else {
          float lightPdf;
          RGB Le = s.environment.LeAndPdf(ray.d, &lightPdf);
          out.L += beta * Le * PowerHeuristic(scatterPdf, lightSelectPdf * lightPdf);
        }
      }
      break;
    }
    if (depth == 0) out.alpha = 1.f;

    Vec3 p = ray(fp.t), wo = -ray.d;
    MaterialCoefficients k = s.classifier.Coefficients(fp.c);
    out.L += beta * k.emission;
    // The camera vertex's gradient, for the guides and the surface below.
    const bool guides = depth == 0 && s.settings.firstHitGuides;
    Vec3 firstGradient;
    if (guides) {
      firstGradient = s.classifier.Gradient(p);
      out.albedo = RGB(Min(1.f, k.albedo.r + k.emission.r), Min(1.f, k.albedo.g + k.emission.g),
                       Min(1.f, k.albedo.b + k.emission.b));
      const float len = Length(firstGradient);
      if (len > 0.f && isfinite(len)) out.normal = firstGradient / (Dot(firstGradient, ray.d) > 0.f ? -len : len);
    }
    if (depth >= s.settings.maxBounces) break;

    // Which particle scattered: surface (BSDF) with probability P_fs.
    bool surface = false;
    SurfaceBSDF bsdf;
    float ldParticle[2];
    if (ld) ld->Get(pairBase + kPairParticle, &ldParticle[0], &ldParticle[1]);
    if (k.surfaceProbability > 0.f && (ld ? ldParticle[0] : rng.Uniform()) < k.surfaceProbability) {
      Vec3 G = guides ? firstGradient : s.classifier.Gradient(p);
      float len = Length(G);
      if (len > 0.f && isfinite(len)) {
        surface = true;
        bsdf = SurfaceBSDF::Make(G / len, wo, k.albedo, k.roughness, k.metallic);
      }
    }
    HGPhaseFunction phase{k.g};
    if (!surface) beta *= Planted(Defect::VolumeAlbedo) ? k.albedo * 0.97f : k.albedo;

    // Next-event estimation (IntegratorSettings::lightSampling).
    if (s.lightCount > 0) {
      // A light's unshadowed contribution for a direction sampled on it;
      // false when it has none.
      LightSample ls;
      auto unshadowed = [&](int li, RGB* c) {
        float u0, u1;
        if (ld) {
          ld->Get(pairBase + kPairLight, &u0, &u1);
        } else {
          u0 = rng.Uniform();
          u1 = rng.Uniform();
        }
        ls = SampleLight(s.lights[li], s.environment, p, u0, u1);
        if (ls.pdf <= 0.f || ls.L.IsBlack()) return false;
        RGB f = surface ? bsdf.Eval(wo, ls.wi) : RGB(phase.p(wo, ls.wi));
        if (f.IsBlack()) return false;
        float lightPdf = lightSelectPdf * ls.pdf;
        const float misLightPdf = Planted(Defect::LightWeights) ? ls.pdf : lightPdf;
        float w = ls.isDelta ? 1.f : PowerHeuristic(misLightPdf, surface ? bsdf.Pdf(wo, ls.wi) : phase.Pdf(wo, ls.wi));
        *c = beta * f * ls.L * (w / lightPdf);
        return true;
      };
      // The shadow ray's first arrival and the choice of light: a pair,
      // or (negative) drawn from rng.
      float ldShadow[2] = {-1.f, -1.f};
      if (ld) ld->Get(pairBase + kPairShadow, &ldShadow[0], &ldShadow[1]);
      RGB c;
      switch (lightSampling) {
        case LightSampling::One: {
          const float u = ld ? ldShadow[1] : rng.Uniform();
          int li = ClampInt((int)(u * s.lightCount), 0, s.lightCount - 1);
          if (unshadowed(li, &c)) out.L += c * Transmittance(s, Ray{p, ls.wi}, ls.distance, rng, ctr, ldShadow[0]);
          break;
        }
        case LightSampling::All:
          for (int li = 0; li < s.lightCount; ++li)
            if (unshadowed(li, &c)) out.L += c * Transmittance(s, Ray{p, ls.wi}, ls.distance, rng, ctr, ldShadow[0]);
          break;
        case LightSampling::Resampled: {
          // One candidate per light, one kept with probability in
          // proportion to its unshadowed luminance (a one-sample reservoir
          // over the lights), one shadow ray: c T / P(kept) estimates the
          // sum over all lights, and where no shadow falls it is that sum
          // exactly, whichever light was kept.
          RGB kept;
          Vec3 keptDir;
          float keptDistance = 0.f, keptWeight = 0.f, weightSum = 0.f;
          for (int li = 0; li < s.lightCount; ++li) {
            if (!unshadowed(li, &c)) continue;
            const float weight = Luminance(c);
            if (!(weight > 0.f)) continue;
            weightSum += weight;
            const bool keep =
                ld ? ChooseAndReuse(weight / weightSum, &ldShadow[1]) : rng.Uniform() * weightSum < weight;
            if (keep) {
              kept = c;
              keptDir = ls.wi;
              keptDistance = ls.distance;
              keptWeight = weight;
            }
          }
          if (keptWeight > 0.f)
            out.L += kept *
                     (Transmittance(s, Ray{p, keptDir}, keptDistance, rng, ctr, ldShadow[0]) * weightSum / keptWeight);
          break;
        }
      }
    }

    // Continue the path.
    float uLobe, u0, u1;
    if (ld) {
      uLobe = ldParticle[1];
      ld->Get(pairBase + kPairDirection, &u0, &u1);
    } else {
      uLobe = rng.Uniform();
      u0 = rng.Uniform();
      u1 = rng.Uniform();
    }
    Vec3 wi;
    if (surface) {
      BSDFSample bs = bsdf.Sample(wo, uLobe, u0, u1);
      if (bs.pdf <= 0.f || bs.f_cos.IsBlack()) break;
      beta *= bs.f_cos / bs.pdf;
      wi = bs.wi;
      scatterPdf = bs.pdf;
    } else {
      PhaseSample ps = phase.Sample(wo, u0, u1);
      wi = ps.wi;  // p / pdf == 1 for HG
      scatterPdf = ps.pdf;
    }
    ray = Ray{p, wi};

    if (depth + 1 >= s.settings.russianRouletteDepth) {
      float q = Max(0.f, 1.f - beta.MaxComponent());
      if (rng.Uniform() < q) break;
      beta = beta / (1.f - q);
    }
  }
  return out;
}

// The start of one sample of pixel (x, y): its own random stream (DESIGN.md
// rule 2), a box-filtered position in the pixel, a lens position and the
// camera ray; with the Sobol' sampler the position, the lens and the first
// vertices' numbers are Owen-scrambled Sobol' pairs of the same (seed,
// pixel, sample index).
struct CameraSample {
  PCG32 rng;
  SobolPairs pairs;
  bool sobol;
  Ray ray;
  float tMax;  // Li's cameraTMax

  MMRTM_CPU_GPU CameraSample(const SceneView& s, int x, int y, uint32_t sampleIndex)
      : rng(PixelSampleRNG(s.settings.seed, (uint64_t)x + (uint64_t)s.camera.width * (uint64_t)y, sampleIndex)),
        pairs(s.settings.seed, (uint64_t)x + (uint64_t)s.camera.width * (uint64_t)y, sampleIndex),
        sobol(s.settings.sampler == PixelSampler::Sobol) {
    float fx, fy, l0 = 0.f, l1 = 0.f;
    if (sobol) {
      pairs.Get(kPairPixel, &fx, &fy);
      if (s.camera.lensRadius > 0.f) pairs.Get(kPairLens, &l0, &l1);
    } else {
      fx = rng.Uniform();
      fy = rng.Uniform();
      l0 = rng.Uniform();
      l1 = rng.Uniform();
    }
    ray = s.camera.GenerateRay((float)x + fx, (float)y + fy, l0, l1);
    tMax = s.cameraRayMaxDistance ? s.cameraRayMaxDistance[x + (int64_t)s.camera.width * y] : kInfinity;
  }
  MMRTM_CPU_GPU const SobolPairs* Pairs() const { return sobol ? &pairs : nullptr; }
};

// One sample of pixel (x, y).
MMRTM_CPU_GPU inline PixelSample RenderPixelSample(const SceneView& s, int x, int y, uint32_t sampleIndex,
                                                   TraceCounters& ctr) {
  CameraSample cs(s, x, y, sampleIndex);
  ++ctr.paths;
  return Li(s, cs.ray, cs.rng, ctr, cs.tMax, cs.Pairs());
}

}  // namespace mmrtm
