// Small vector types: 3-vectors, RGB triples, affine transforms and shading
// frames. Plain structs with public data (pbrt-v4 style).
#pragma once

#include "mmrtm/defs.h"

namespace mmrtm {

struct Vec3 {
  float x = 0.f, y = 0.f, z = 0.f;

  Vec3() = default;
  MMRTM_CPU_GPU Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}

  MMRTM_CPU_GPU float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  MMRTM_CPU_GPU float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  MMRTM_CPU_GPU Vec3 operator+(Vec3 b) const { return {x + b.x, y + b.y, z + b.z}; }
  MMRTM_CPU_GPU Vec3 operator-(Vec3 b) const { return {x - b.x, y - b.y, z - b.z}; }
  MMRTM_CPU_GPU Vec3 operator-() const { return {-x, -y, -z}; }
  MMRTM_CPU_GPU Vec3 operator*(float s) const { return {x * s, y * s, z * s}; }
  MMRTM_CPU_GPU Vec3 operator/(float s) const {
    float r = 1.f / s;
    return {x * r, y * r, z * r};
  }
  MMRTM_CPU_GPU Vec3& operator+=(Vec3 b) {
    x += b.x;
    y += b.y;
    z += b.z;
    return *this;
  }
};

MMRTM_CPU_GPU inline Vec3 operator*(float s, Vec3 v) { return v * s; }
MMRTM_CPU_GPU inline float Dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
MMRTM_CPU_GPU inline Vec3 Cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
MMRTM_CPU_GPU inline float LengthSquared(Vec3 v) { return Dot(v, v); }
MMRTM_CPU_GPU inline float Length(Vec3 v) { return sqrtf(Dot(v, v)); }
MMRTM_CPU_GPU inline Vec3 Normalize(Vec3 v) { return v / Length(v); }
MMRTM_CPU_GPU inline Vec3 FaceForward(Vec3 n, Vec3 v) { return Dot(n, v) < 0.f ? -n : n; }

// Linear RGB radiance, albedo or throughput.
struct RGB {
  float r = 0.f, g = 0.f, b = 0.f;

  RGB() = default;
  MMRTM_CPU_GPU explicit RGB(float v) : r(v), g(v), b(v) {}
  MMRTM_CPU_GPU RGB(float r_, float g_, float b_) : r(r_), g(g_), b(b_) {}

  MMRTM_CPU_GPU float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }
  MMRTM_CPU_GPU float& operator[](int i) { return i == 0 ? r : (i == 1 ? g : b); }
  MMRTM_CPU_GPU RGB operator+(RGB o) const { return {r + o.r, g + o.g, b + o.b}; }
  MMRTM_CPU_GPU RGB operator-(RGB o) const { return {r - o.r, g - o.g, b - o.b}; }
  MMRTM_CPU_GPU RGB operator*(RGB o) const { return {r * o.r, g * o.g, b * o.b}; }
  MMRTM_CPU_GPU RGB operator*(float s) const { return {r * s, g * s, b * s}; }
  MMRTM_CPU_GPU RGB operator/(float s) const {
    float i = 1.f / s;
    return {r * i, g * i, b * i};
  }
  MMRTM_CPU_GPU RGB& operator+=(RGB o) {
    r += o.r;
    g += o.g;
    b += o.b;
    return *this;
  }
  MMRTM_CPU_GPU RGB& operator*=(RGB o) {
    r *= o.r;
    g *= o.g;
    b *= o.b;
    return *this;
  }
  MMRTM_CPU_GPU RGB& operator*=(float s) {
    r *= s;
    g *= s;
    b *= s;
    return *this;
  }

  MMRTM_CPU_GPU float MaxComponent() const { return Max(r, Max(g, b)); }
  MMRTM_CPU_GPU bool IsBlack() const { return r == 0.f && g == 0.f && b == 0.f; }
};

MMRTM_CPU_GPU inline RGB operator*(float s, RGB c) { return c * s; }
// Rec. 709 luminance of linear RGB.
MMRTM_CPU_GPU inline float Luminance(RGB c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

// Row-major 3x4 affine transform: p' = M p + t, with the translation in
// column 3. Maps world points to voxel index space and back.
struct Affine3 {
  float m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

  MMRTM_CPU_GPU Vec3 ApplyPoint(Vec3 p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
  }
  MMRTM_CPU_GPU Vec3 ApplyVector(Vec3 v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  // Applies the transpose of the linear part: turns an index-space gradient
  // into a world-space gradient when this is the world-to-index transform.
  MMRTM_CPU_GPU Vec3 ApplyTransposeLinear(Vec3 v) const {
    return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z, m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
            m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
  }
};

// Host-only helpers for building transforms.
Affine3 AffineInverse(const Affine3& a);                            // throws std::runtime_error if singular
Affine3 AffineCompose(const Affine3& outer, const Affine3& inner);  // outer(inner(p))

// Orthonormal frame around a unit normal (Duff et al. 2017).
struct Frame {
  Vec3 x, y, z;

  MMRTM_CPU_GPU static Frame FromZ(Vec3 n) {
    float sign = copysignf(1.f, n.z);
    float a = -1.f / (sign + n.z);
    float b = n.x * n.y * a;
    Frame f;
    f.x = {1.f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    f.y = {b, sign + n.y * n.y * a, -n.y};
    f.z = n;
    return f;
  }
  MMRTM_CPU_GPU Vec3 ToLocal(Vec3 v) const { return {Dot(v, x), Dot(v, y), Dot(v, z)}; }
  MMRTM_CPU_GPU Vec3 FromLocal(Vec3 v) const { return x * v.x + y * v.y + z * v.z; }
};

}  // namespace mmrtm
