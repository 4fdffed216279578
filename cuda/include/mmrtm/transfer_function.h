// The five unified transfer-function types of the paper (section 5).
//
// Coefficient TFs map a proxy value to a coefficient (1 or 3 channels):
//   CCTF  curve: piecewise-linear between control points, clamped outside;
//   CPCTF piecewise constant: value v_i on [lo_i, hi_i), zero elsewhere;
//   CDPTF discrete points: value v_i where round(x) == key_i, zero elsewhere.
// Material TFs map a proxy value to a material index (or kNoMaterial):
//   MPCTF piecewise constant over [lo_i, hi_i) ranges;
//   MDPTF discrete points (labels) where round(x) == key_i.
// Overlapping ranges: the first listed range wins.
//
// Besides point evaluation each TF bounds itself over a value interval
// (MaxOverRange): that is what makes majorants conservative for every TF
// type (DESIGN.md rule 4), since a cell's trilinear interpolant takes every
// value between its corner values and no other.
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/planted_defect.h"

namespace mmrtm {

enum class TFType : uint8_t { CCTF, CPCTF, CDPTF, MPCTF, MDPTF };
constexpr int kNoMaterial = -1;
constexpr int kMaxTFChannels = 3;

MMRTM_CPU_GPU inline bool IsMaterialTF(TFType t) { return t == TFType::MPCTF || t == TFType::MDPTF; }
MMRTM_CPU_GPU inline bool IsDiscreteTF(TFType t) { return t == TFType::CDPTF || t == TFType::MDPTF; }
MMRTM_CPU_GPU inline bool IsRangeTF(TFType t) { return t == TFType::CPCTF || t == TFType::MPCTF; }

// A view of one TF: flat arrays owned by the host scene.
struct TransferFunctionView {
  TFType type = TFType::CCTF;
  uint8_t proxy = 0;     // which proxy volume it reads
  uint8_t channels = 1;  // coefficient TFs: output channels (1 or 3)
  uint8_t padding0 = 0;  // (padding is explicit: equal views have equal bytes, see scene_uploads.h)
  int count = 0;         // control points, ranges or discrete entries
  // CCTF, CDPTF, MDPTF: count keys, ascending.
  // CPCTF, MPCTF: count [lo, hi) pairs, 2*count floats, in priority order.
  const float* keys = nullptr;
  const float* values = nullptr;   // coefficient TFs: count*channels
  const int* materials = nullptr;  // material TFs: count material indices
  // Discrete TFs: entry index by round(x) - denseMin, -1 for none, when the
  // keys span a small integer range (labels); otherwise a binary search.
  const int* denseIndex = nullptr;
  int denseMin = 0, denseCount = 0;
  // CCTF with evenly spaced keys (tables sampled from VTK's functions): 1 /
  // the spacing, so that Evaluate finds the segment by arithmetic and one
  // correction instead of a binary search (the same segment, hence the same
  // value to the bit); 0 when the keys are not evenly spaced.
  float uniformInverseStep = 0.f;
  int padding1 = 0;

  // Entry index for x, or -1. For a CCTF: the segment start (see Evaluate).
  MMRTM_CPU_GPU int FindEntry(float x) const {
    if (IsDiscreteTF(type)) {
      float r = floorf(x + 0.5f);
      if (denseIndex) {
        // The range check in float first: a value far outside the keys (or
        // NaN) must not be converted to int (undefined behaviour).
        const float offset = r - (float)denseMin;
        return (offset >= 0.f && offset < (float)denseCount) ? denseIndex[(int)offset] : -1;
      }
      int lo = 0, hi = count - 1;
      while (lo <= hi) {
        int mid = (lo + hi) >> 1;
        if (keys[mid] == r) return mid;
        if (keys[mid] < r)
          lo = mid + 1;
        else
          hi = mid - 1;
      }
      return -1;
    }
    // Ranges: first match in priority order.
    for (int i = 0; i < count; ++i)
      if (x >= keys[2 * i] && x < keys[2 * i + 1]) return i;
    return -1;
  }

  // Coefficient TFs: writes `channels` values to out.
  MMRTM_CPU_GPU void Evaluate(float x, float* out) const {
    if (type == TFType::CCTF) {
      if (x <= keys[0] || count == 1) return Copy(0, out);
      if (x >= keys[count - 1]) return Copy(count - 1, out);
      const int lo = CurveSegment(x);
      const float t = CurveFraction(x, lo);
      for (int c = 0; c < channels; ++c) out[c] = CurveChannel(t, lo, c);
      return;
    }
    int i = FindEntry(x);
    if (i < 0) {
      for (int c = 0; c < channels; ++c) out[c] = 0.f;
    } else {
      Copy(i, out);
    }
  }

  // CCTF: the segment lo with keys[lo] <= x < keys[lo + 1], for x strictly
  // between the first and the last key.
  MMRTM_INLINE MMRTM_CPU_GPU int CurveSegment(float x) const {
    if (uniformInverseStep > 0.f) {
      const float f = (x - keys[0]) * uniformInverseStep;
      if (f >= 0.f && f < (float)(count - 1)) {
        // Evenly spaced keys (to within a quarter step, Scene::Build
        // checks): the estimate is the segment or one of its neighbours.
        const int lo = (int)f;
        if (keys[lo] > x) return lo - 1;
        return keys[lo + 1] <= x ? lo + 1 : lo;
      }
    }
    return BisectCurve(x);
  }

  // CCTF: the segment by binary search (keys not evenly spaced, or x beyond
  // the estimate's range).
  MMRTM_INLINE MMRTM_CPU_GPU int BisectCurve(float x) const {
    int lo = 0, hi = count - 1;  // keys[lo] <= x < keys[hi]
    while (hi - lo > 1) {
      const int mid = (lo + hi) >> 1;
      if (keys[mid] <= x)
        lo = mid;
      else
        hi = mid;
    }
    return lo;
  }

  // CCTF: x's position in segment lo, 0 at keys[lo] and 1 at keys[lo + 1].
  MMRTM_INLINE MMRTM_CPU_GPU float CurveFraction(float x, int lo) const {
    const float k0 = keys[lo], k1 = keys[lo + 1];
    return (x - k0) / (k1 - k0);
  }

  // CCTF: channel c at fraction t of segment lo.
  MMRTM_INLINE MMRTM_CPU_GPU float CurveChannel(float t, int lo, int c) const {
    const int first = lo * channels + c;
    return Lerp(t, values[first], values[first + channels]);
  }

  // Material TFs: the material at x, or kNoMaterial.
  MMRTM_CPU_GPU int EvaluateMaterial(float x) const {
    if (Planted(Defect::LabelSwap) && type == TFType::MDPTF) {
      const float r = floorf(x + 0.5f);
      x = r == 1.f ? 2.f : r == 2.f ? 1.f : x;
    }
    int i = FindEntry(x);
    return i < 0 ? kNoMaterial : materials[i];
  }

  // Coefficient TFs: per-channel maximum over all x in [lo, hi].
  MMRTM_CPU_GPU void MaxOverRange(float lo, float hi, float* out) const {
    Evaluate(lo, out);
    float tmp[kMaxTFChannels];
    Evaluate(hi, tmp);
    Accumulate(tmp, out);
    for (int i = 0; i < count; ++i) {
      if (EntryInRange(i, lo, hi)) Accumulate(values + i * channels, out);
    }
  }

  // Coefficient TFs: a lower bound of every channel over all x in [lo, hi]
  // (the minimum for a CCTF; 0 where a range or discrete TF may have no
  // entry): what makes minorants conservative, as MaxOverRange majorants.
  MMRTM_CPU_GPU void MinOverRange(float lo, float hi, float* out) const {
    if (type != TFType::CCTF && !CoversRange(lo, hi)) {
      for (int c = 0; c < channels; ++c) out[c] = 0.f;
      return;
    }
    bool first = true;
    float tmp[kMaxTFChannels];
    if (type == TFType::CCTF) {
      Evaluate(lo, out);
      Evaluate(hi, tmp);
      AccumulateMin(tmp, out);
      first = false;
    }
    for (int i = 0; i < count; ++i) {
      if (!EntryInRange(i, lo, hi)) continue;
      if (first)
        Copy(i, out);
      else
        AccumulateMin(values + i * channels, out);
      first = false;
    }
    if (first)
      for (int c = 0; c < channels; ++c) out[c] = 0.f;
  }

  // Range and discrete TFs: whether every x in [lo, hi] has an entry (a
  // material TF names a material there; a coefficient TF is not 0 by
  // default). Discrete TFs check each integer, up to kMaxCoverageChecks of
  // them (beyond: false, which only loosens a minorant). A CCTF covers all.
  static constexpr int kMaxCoverageChecks = 256;
  MMRTM_CPU_GPU bool CoversRange(float lo, float hi) const {
    if (type == TFType::CCTF) return true;
    if (!(lo <= hi)) return false;
    if (IsDiscreteTF(type)) {
      const float r0 = floorf(lo + 0.5f), r1 = floorf(hi + 0.5f);
      if (r1 - r0 >= (float)kMaxCoverageChecks) return false;
      for (float r = r0; r <= r1; r += 1.f)
        if (FindEntry(r) < 0) return false;
      return true;
    }
    // Ranges [lo_i, hi_i): extend the covered prefix [lo, x) until it
    // passes hi or no range continues it.
    float x = lo;
    for (int pass = 0; pass < count; ++pass) {
      bool extended = false;
      for (int i = 0; i < count; ++i)
        if (keys[2 * i] <= x && keys[2 * i + 1] > x) {
          x = keys[2 * i + 1];
          extended = true;
        }
      if (x > hi) return true;
      if (!extended) return false;
    }
    return x > hi;
  }

  // Material TFs: whether entry i (hence materials[i]) is reachable in [lo, hi].
  MMRTM_CPU_GPU bool EntryInRange(int i, float lo, float hi) const {
    if (IsRangeTF(type)) return keys[2 * i] <= hi && keys[2 * i + 1] > lo;
    if (IsDiscreteTF(type)) return keys[i] >= floorf(lo + 0.5f) && keys[i] <= floorf(hi + 0.5f);
    return keys[i] >= lo && keys[i] <= hi;
  }

 private:
  MMRTM_CPU_GPU void Copy(int i, float* out) const {
    for (int c = 0; c < channels; ++c) out[c] = values[i * channels + c];
  }
  MMRTM_CPU_GPU void Accumulate(const float* v, float* out) const {
    for (int c = 0; c < channels; ++c) out[c] = Max(out[c], v[c]);
  }
  MMRTM_CPU_GPU void AccumulateMin(const float* v, float* out) const {
    for (int c = 0; c < channels; ++c) out[c] = Min(out[c], v[c]);
  }
};

}  // namespace mmrtm
