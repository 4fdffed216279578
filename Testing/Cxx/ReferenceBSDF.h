// Reference formulas for the surface BSDF (mmrtm/bsdf.h), written from their
// sources in double precision, and quadrature over directions for them.
// The tests compare the code with these, never with its own functions.
//   - GGX: D (Walter et al. 2007, eq. 33), Smith's Lambda and G1 (Heitz 2014,
//     "Understanding the masking-shadowing function", eq. 72 and 43), the
//     height-correlated G2 (Heitz 2014 eq. 99), and the density of visible
//     normals D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z (Heitz 2018,
//     "Sampling the GGX distribution of visible normals", eq. 1);
//   - Schlick's Fresnel and the diffuse weight bsdf.h documents
//     ((1 - metallic) (1 - Y(F0)) (1 - Y(F(wo))) times the base colour, Y
//     the Rec. 709 luminance).
// Quadrature: Gauss-Legendre on panels placed where the lobes are, in
// half-vector space and cut exactly at the horizon, so that integrals of
// the BSDF are exact to about 1e-9 (TestBSDF's Quadrature test).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <vector>

namespace mmrtm::test {

constexpr double kPiD = 3.14159265358979323846;

// Double-precision directions.
struct D3 {
  double x = 0, y = 0, z = 0;
};
inline D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline D3 operator*(D3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double Dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline D3 Normalized(D3 a) { return a * (1 / std::sqrt(Dot(a, a))); }
inline D3 Spherical(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}
// wo in the xz plane at cos(theta_o) = cosO, toward +x.
inline D3 OutgoingAt(double cosO) { return {std::sqrt(std::max(0.0, 1 - cosO * cosO)), 0, cosO}; }

using Rgb3 = std::array<double, 3>;
inline double Y709(const Rgb3& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// The BSDF of bsdf.h, written from its sources (see the file comment), in
// double precision, in the local frame (z = normal, wo.z > 0).
struct ReferenceBSDF {
  Rgb3 base{1, 1, 1};
  double metallic = 0;
  double alpha = 1;

  static ReferenceBSDF Make(Rgb3 base, double roughness, double metallic) {
    // GGX alpha = roughness^2, at least 0.01 (scene-format.md, `roughness`).
    return {base, metallic, std::max(roughness * roughness, 0.01)};
  }
  static double Schlick(double f0, double cosTheta) { return f0 + (1 - f0) * std::pow(1 - cosTheta, 5); }
  Rgb3 F0() const {
    Rgb3 f;
    for (int c = 0; c < 3; ++c) f[c] = 0.04 * (1 - metallic) + base[c] * metallic;
    return f;
  }
  Rgb3 Fresnel(double cosTheta) const {
    Rgb3 f = F0();
    for (double& v : f) v = Schlick(v, cosTheta);
    return f;
  }
  // Walter et al. 2007 eq. 33: 1 / (pi alpha^2 cos^4 (1 + tan^2 / alpha^2)^2).
  double D(D3 h) const {
    if (h.z <= 0) return 0;
    const double c2 = h.z * h.z, tan2 = (1 - c2) / c2, e = 1 + tan2 / (alpha * alpha);
    return 1 / (kPiD * alpha * alpha * c2 * c2 * e * e);
  }
  // Heitz 2014 eq. 72.
  double Lambda(D3 w) const {
    const double c2 = w.z * w.z, tan2 = (1 - c2) / c2;
    return (-1 + std::sqrt(1 + alpha * alpha * tan2)) / 2;
  }
  double G1(D3 w) const { return 1 / (1 + Lambda(w)); }
  double G2(D3 wo, D3 wi) const { return 1 / (1 + Lambda(wo) + Lambda(wi)); }
  // Heitz 2018 eq. 1: the density of the normals visible from wo.
  double VisibleNormalPdf(D3 wo, D3 h) const { return G1(wo) * std::max(0.0, Dot(wo, h)) * D(h) / wo.z; }
  // The density of wi = reflect(wo, h) for h drawn from it: dwi = 4 (wo.h) dh.
  double ReflectedPdf(D3 wo, D3 wi) const {
    const D3 h = Normalized(wo + wi);
    const double woh = Dot(wo, h);
    return woh > 0 ? VisibleNormalPdf(wo, h) / (4 * woh) : 0;
  }

  Rgb3 DiffuseWeight(double cosO) const {
    const Rgb3 f0 = F0(), f = Fresnel(cosO);
    Rgb3 w;
    for (int c = 0; c < 3; ++c) w[c] = base[c] * (1 - metallic) * (1 - Y709(f0)) * (1 - Y709(f));
    return w;
  }
  // Each lobe's f(wo, wi) cos(theta_i); zero below the horizon.
  Rgb3 DiffuseFCos(D3 wo, D3 wi) const {
    Rgb3 v = DiffuseWeight(wo.z);
    for (double& x : v) x = wi.z > 0 ? x * wi.z / kPiD : 0;
    return v;
  }
  Rgb3 SpecularFCos(D3 wo, D3 wi) const {
    if (wi.z <= 0 || wo.z <= 0) return {0, 0, 0};
    const D3 h = Normalized(wo + wi);
    const double s = D(h) * G2(wo, wi) / (4 * wo.z);
    Rgb3 f = Fresnel(Dot(wo, h));
    for (double& x : f) x *= s;
    return f;
  }
};

// n-point Gauss-Legendre nodes and weights on [0, 1] (Newton on P_n).
struct GaussLegendre {
  std::vector<double> x, w;
  explicit GaussLegendre(int n) {
    for (int i = 0; i < n; ++i) {
      double t = std::cos(kPiD * (i + 0.75) / (n + 0.5)), dp = 0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1, p1 = t;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (t * p1 - p0) / (t * t - 1);
        const double step = p1 / dp;
        t -= step;
        if (std::fabs(step) < 1e-15) break;
      }
      x.push_back((1 - t) / 2);
      w.push_back(1 / ((1 - t * t) * dp * dp));
    }
  }
};

// Calls visit(theta, weight) for the nodes of a composite Gauss-Legendre
// rule over the panels between sorted `edges`.
template <class Visit>
void PanelNodes(const std::vector<double>& edges, const GaussLegendre& gl, Visit visit) {
  for (size_t p = 0; p + 1 < edges.size(); ++p) {
    const double a = edges[p], b = edges[p + 1];
    if (!(b > a)) continue;
    for (size_t i = 0; i < gl.x.size(); ++i) visit(a + (b - a) * gl.x[i], (b - a) * gl.w[i]);
  }
}

// GGX's own angle warp: theta(t) with t = tan^2 / (alpha^2 + tan^2), the
// cumulative distribution of D(h) cos(theta_h). Uniform steps in t put
// panels (and chi-square bins) where a GGX lobe is, at any alpha.
inline double GGXTheta(double alpha, double t) { return t >= 1 ? kPiD / 2 : std::atan(alpha * std::sqrt(t / (1 - t))); }
inline double GGXT(double alpha, double theta) {
  const double s = std::sin(theta), c = std::cos(theta);
  return s * s / (alpha * alpha * c * c + s * s);
}

// Nodes and weights (solid angle) over half vectors h with polar angle in
// [0, thetaLimit(phi)], for integrands symmetric about the xz plane (wo in
// it, an isotropic BSDF): phi over [0, pi], doubled. Gauss-Legendre on
// panels throughout: in theta, the union of GGX-warped panels (the specular
// peak, however narrow) and uniform ones (broad lobes); in phi, uniform
// panels refined geometrically toward pi/2, where the limits below change
// fastest (over an angle of about cos_o at grazing wo) or have a kink.
template <class Visit>
void HalfVectorQuadrature(double alpha, const std::function<double(double)>& thetaLimit, Visit visit) {
  static const GaussLegendre gl(6);
  static const std::vector<double> phiEdges = [] {
    std::vector<double> e;
    for (int k = 0; k <= 16; ++k) e.push_back(kPiD * k / 16);
    for (int k = 1; k <= 12; ++k)
      for (double side : {-1.0, 1.0}) e.push_back(kPiD / 2 + side * (kPiD / 2) * std::pow(0.5, k));
    std::sort(e.begin(), e.end());
    return e;
  }();
  const int warped = 32, uniform = 16;
  std::vector<double> edges;
  PanelNodes(phiEdges, gl, [&](double phi, double wPhi) {
    const double limit = thetaLimit(phi), tLimit = GGXT(alpha, limit);
    edges.clear();
    for (int k = 0; k <= warped; ++k) edges.push_back(std::min(limit, GGXTheta(alpha, tLimit * k / warped)));
    for (int k = 1; k < uniform; ++k) edges.push_back(limit * k / uniform);
    std::sort(edges.begin(), edges.end());
    PanelNodes(edges, gl,
               [&](double theta, double w) { visit(Spherical(theta, phi), 2 * wPhi * w * std::sin(theta)); });
  });
}

// Over the normals h visible from wo = (sin, 0, cos): h.z > 0 and wo.h > 0.
template <class Visit>
void VisibleNormalQuadrature(D3 wo, double alpha, Visit visit) {
  HalfVectorQuadrature(
      alpha,
      [&](double phi) { return std::cos(phi) < 0 && wo.x > 0 ? std::atan2(wo.z, -wo.x * std::cos(phi)) : kPiD / 2; },
      visit);
}

// Over directions wi above the horizon, as reflections of half vectors h
// (dwi = 4 (wo.h) dh): wi.z = 0 is where tan(2 theta_h) = -cos_o / (sin_o
// cos(phi_h)), so each phi's panels end exactly at the horizon and no panel
// straddles the jump of the BSDF there. visit(wi, weight).
template <class Visit>
void ReflectedDirectionQuadrature(D3 wo, double alpha, Visit visit) {
  HalfVectorQuadrature(
      alpha, [&](double phi) { return 0.5 * std::atan2(wo.z, -wo.x * std::cos(phi)); },
      [&](D3 h, double w) {
        const double woh = Dot(wo, h);
        visit(h * (2 * woh) - wo, w * 4 * woh);
      });
}

}  // namespace mmrtm::test
