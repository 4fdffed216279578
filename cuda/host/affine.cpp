// Host-only affine helpers declared in mmrtm/vecmath.h.
#include <cmath>
#include <stdexcept>

#include "mmrtm/vecmath.h"

namespace mmrtm {

Affine3 AffineInverse(const Affine3& a) {
  // Inverse of the 3x3 linear part by cofactors, in double for accuracy.
  double m[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m[r][c] = a.m[r][c];
  double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
  double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
  double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
  double scale = std::fabs(m[0][0]) + std::fabs(m[1][1]) + std::fabs(m[2][2]) + 1e-30;
  if (!std::isfinite(det) || std::fabs(det) < 1e-12 * scale * scale * scale)
    throw std::runtime_error("singular transform (a zero spacing or degenerate direction matrix)");
  double inv[3][3] = {
      {c00 / det, (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det, (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det},
      {c01 / det, (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det, (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det},
      {c02 / det, (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det, (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det}};
  Affine3 out;
  for (int r = 0; r < 3; ++r) {
    double t = 0;
    for (int c = 0; c < 3; ++c) {
      out.m[r][c] = (float)inv[r][c];
      t -= inv[r][c] * a.m[c][3];
    }
    out.m[r][3] = (float)t;
  }
  return out;
}

Affine3 AffineCompose(const Affine3& outer, const Affine3& inner) {
  Affine3 out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      double v = c == 3 ? outer.m[r][3] : 0.0;
      for (int k = 0; k < 3; ++k) v += (double)outer.m[r][k] * inner.m[k][c];
      out.m[r][c] = (float)v;
    }
  }
  return out;
}

}  // namespace mmrtm
