// The surface-scattering BSDF of the MM-RTM (paper section 3): a diffuse
// lobe plus a GGX microfacet reflection lobe, on the shading normal given by
// the volume gradient. Reflection only: light arriving from the back side of
// the gradient surface is absorbed. The normal is turned toward wo, so a
// surface seen from either side reflects on the viewer's side.
//
// The base colour is the material albedo; it is this BSDF's own albedo A(p)
// (paper eq. 2-3), so a surface event does not also apply the volumetric
// single-scattering albedo. Metallic blends the specular colour from 0.04
// (dielectric) to the base colour (metal) and fades the diffuse lobe out.
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/planted_defect.h"
#include "mmrtm/sampling.h"
#include "mmrtm/vecmath.h"

namespace mmrtm {

// GGX alpha below this is treated as this: keeps the lobe finite in float.
constexpr float kMinGGXAlpha = 0.01f;

struct BSDFSample {
  Vec3 wi;
  RGB f_cos;        // f(wo, wi) |cos theta_i|
  float pdf = 0.f;  // solid-angle pdf of wi
};

MMRTM_CPU_GPU inline RGB SchlickFresnel(RGB f0, float cosTheta) {
  float m = Clamp(1.f - cosTheta, 0.f, 1.f);
  float m5 = (m * m) * (m * m) * m;
  return f0 + (RGB(1.f) - f0) * m5;
}

// Trowbridge-Reitz (GGX) distribution with Smith masking, sampled by its
// distribution of visible normals (Heitz 2018). All vectors in the local
// shading frame (z = normal).
struct GGX {
  float alpha;

  MMRTM_CPU_GPU float D(Vec3 h) const {
    float a2 = alpha * alpha;
    float c2 = h.z * h.z;
    float d = c2 * (a2 - 1.f) + 1.f;
    return a2 / (kPi * d * d);
  }
  MMRTM_CPU_GPU float Lambda(Vec3 w) const {
    float c2 = w.z * w.z;
    float t2 = Max(0.f, 1.f - c2) / Max(c2, 1e-12f);
    return 0.5f * (-1.f + sqrtf(1.f + alpha * alpha * t2));
  }
  MMRTM_CPU_GPU float G1(Vec3 w) const { return 1.f / (1.f + Lambda(w)); }
  MMRTM_CPU_GPU float G(Vec3 wo, Vec3 wi) const { return 1.f / (1.f + Lambda(wo) + Lambda(wi)); }

  MMRTM_CPU_GPU Vec3 SampleVisibleNormal(Vec3 wo, float u0, float u1) const {
    Vec3 vh = Normalize(Vec3{alpha * wo.x, alpha * wo.y, wo.z});
    float lensq = vh.x * vh.x + vh.y * vh.y;
    Vec3 t1 = lensq > 0.f ? Vec3{-vh.y, vh.x, 0.f} / sqrtf(lensq) : Vec3{1.f, 0.f, 0.f};
    Vec3 t2 = Cross(vh, t1);
    float r = sqrtf(u0), phi = 2.f * kPi * u1;
    float p1 = r * cosf(phi), p2 = r * sinf(phi);
    float s = 0.5f * (1.f + vh.z);
    p2 = (1.f - s) * SafeSqrt(1.f - p1 * p1) + s * p2;
    Vec3 nh = t1 * p1 + t2 * p2 + vh * SafeSqrt(1.f - p1 * p1 - p2 * p2);
    return Normalize(Vec3{alpha * nh.x, alpha * nh.y, Max(1e-6f, nh.z)});
  }
  // pdf of wi = reflect(wo, h) under visible-normal sampling.
  MMRTM_CPU_GPU float PdfReflect(Vec3 wo, Vec3 h) const { return G1(wo) * D(h) / (4.f * wo.z); }
};

struct SurfaceBSDF {
  Frame frame;  // z: the gradient normal, facing wo
  RGB baseColor;
  float metallic = 0.f;
  float alpha = 1.f;

  MMRTM_CPU_GPU static SurfaceBSDF Make(Vec3 gradientNormal, Vec3 wo, RGB baseColor, float roughness, float metallic) {
    SurfaceBSDF b;
    b.frame = Frame::FromZ(FaceForward(gradientNormal, wo));
    b.baseColor = baseColor;
    b.metallic = metallic;
    b.alpha = Max(roughness * roughness, kMinGGXAlpha);
    return b;
  }

  MMRTM_CPU_GPU RGB SpecularF0() const { return RGB(0.04f) * (1.f - metallic) + baseColor * metallic; }
  // Diffuse reflectance, reduced by what the specular lobe reflects. 1 - F(wo)
  // alone lets the sum gain up to ~0.02% at low roughness (microfacets seen
  // at wo reflect more than F(wo)); the extra (1 - F0) keeps the sum below 1
  // (checked by the energy test for roughness 0.1..1 and all angles).
  MMRTM_CPU_GPU RGB DiffuseWeight(float cosO) const {
    RGB f0 = SpecularF0();
    return baseColor * ((1.f - metallic) * (1.f - Luminance(f0)) * (1.f - Luminance(SchlickFresnel(f0, cosO))) *
                        (Planted(Defect::DiffuseLobe) ? 0.95f : 1.f));
  }
  MMRTM_CPU_GPU float SpecularProbability(float cosO) const {
    float s = Luminance(SchlickFresnel(SpecularF0(), cosO));
    float d = Luminance(DiffuseWeight(cosO));
    return s + d > 0.f ? s / (s + d) : 1.f;
  }

  // f(wo, wi) |cos theta_i|; zero for wi behind the surface.
  MMRTM_CPU_GPU RGB Eval(Vec3 woWorld, Vec3 wiWorld) const {
    Vec3 wo = frame.ToLocal(woWorld), wi = frame.ToLocal(wiWorld);
    if (wo.z <= 0.f || wi.z <= 0.f) return RGB(0.f);
    GGX ggx{alpha};
    Vec3 h = Normalize(wo + wi);
    RGB spec = SchlickFresnel(SpecularF0(), Dot(wo, h)) *
               (ggx.D(h) * ggx.G(wo, wi) / (4.f * wo.z) * (Planted(Defect::SpecularLobe) ? 0.95f : 1.f));
    return spec + DiffuseWeight(wo.z) * (kInvPi * wi.z);
  }

  MMRTM_CPU_GPU float Pdf(Vec3 woWorld, Vec3 wiWorld) const {
    Vec3 wo = frame.ToLocal(woWorld), wi = frame.ToLocal(wiWorld);
    if (wo.z <= 0.f || wi.z <= 0.f) return 0.f;
    GGX ggx{alpha};
    Vec3 h = Normalize(wo + wi);
    float ps = SpecularProbability(wo.z);
    return ps * ggx.PdfReflect(wo, h) + (1.f - ps) * CosineHemispherePdf(wi.z);
  }

  // Samples the mixture of both lobes; pdf is the mixture pdf, so the weight
  // f_cos / pdf is unbiased whichever lobe produced wi.
  MMRTM_CPU_GPU BSDFSample Sample(Vec3 woWorld, float uLobe, float u0, float u1) const {
    BSDFSample s;
    Vec3 wo = frame.ToLocal(woWorld);
    if (wo.z <= 0.f) return s;
    Vec3 wi;
    if (uLobe < SpecularProbability(wo.z)) {
      Vec3 h = GGX{alpha}.SampleVisibleNormal(wo, u0, u1);
      wi = h * (2.f * Dot(wo, h)) - wo;
    } else {
      wi = SampleCosineHemisphere(u0, u1);
    }
    if (wi.z <= 0.f) return s;
    s.wi = frame.FromLocal(wi);
    s.f_cos = Eval(woWorld, s.wi);
    s.pdf = Pdf(woWorld, s.wi);
    return s;
  }
};

}  // namespace mmrtm
