// The majorant refit after a TF or material change (paper section 4), per
// node, shared by the CPU refit (cuda/host/majorant_grid.cpp, threads over
// summaries and leaves) and the CUDA refit (cuda/gpu, a thread per summary,
// then per leaf, then per node of each upper level). Both read the same
// inputs, so they agree exactly:
//   - the TF-independent leaf summaries: for every proxy a 256-bin mask of
//     the values a leaf can interpolate to (built once per data load), each
//     distinct one stored once (cuda/host/leaf_summary_table.h); a refit
//     bounds each distinct summary, then gives every leaf its summary's bound;
//   - per TF and bin, the TF's maximum over the bin's value range
//     (coefficient TFs) or the materials it can pick there (material TFs),
//     computed on the host (TFs x 256 entries, microseconds); for the
//     minorants also its minimum, and whether a material TF names a
//     material over the whole bin.
#pragma once

#include "mmrtm/classifier.h"
#include "mmrtm/majorant_grid_view.h"
#include "mmrtm/planted_defect.h"

namespace mmrtm {

constexpr int kSummaryBins = 256;
constexpr int kSummaryWords = kSummaryBins / 64;

MMRTM_CPU_GPU inline int CountTrailingZeros64(uint64_t x) {
#if defined(__CUDA_ARCH__)
  return __ffsll((long long)x) - 1;
#else
  return __builtin_ctzll(x);
#endif
}

// Calls fn(bin) for every set bin of a kSummaryWords-word mask.
template <typename Fn>
MMRTM_CPU_GPU inline void ForEachBin(const uint64_t* words, Fn fn) {
  for (int w = 0; w < kSummaryWords; ++w)
    for (uint64_t bits = words[w]; bits; bits &= bits - 1) fn((w << 6) + CountTrailingZeros64(bits));
}

// What a refit reads besides the classifier.
struct RefitInputs {
  const uint64_t* summaries[kMaxProxies] = {};  // per proxy: kSummaryWords words per distinct summary
  const float* binMax = nullptr;                // [tf * kSummaryBins + bin]: coefficient TFs
  const uint64_t* binMaterials = nullptr;       // [tf * kSummaryBins + bin]: material TFs, a mask of materials
  bool materialMasks = true;                    // false with more than 64 materials: every material counts
  // Optional: [tf][byte of the summary][its value] the maximum of binMax
  // over the byte's set bits, so that a summary's maximum takes a lookup per
  // non-zero byte instead of one per set bin. The same maximum either way.
  const float* byteMax = nullptr;
  // For minorants: [tf * kSummaryBins + bin] a lower bound of coefficient TF
  // tf over the bin (MinOverRange); [tf * kSummaryWords + word] the bins
  // where material TF tf may name no material (not CoversRange), as a mask.
  const float* binMin = nullptr;
  const uint64_t* uncoveredBins = nullptr;
  // Optional, as byteMax: the minimum of binMin over a byte's set bits.
  const float* byteMin = nullptr;
};

constexpr int kSummaryBytes = kSummaryBins / 8;

// The maximum of coefficient TF t's binMax over the set bins of a summary.
MMRTM_CPU_GPU inline float MaxOverBins(const RefitInputs& in, int t, const uint64_t* words) {
  float mx = 0.f;
  if (in.byteMax) {
    const float* table = in.byteMax + (size_t)t * kSummaryBytes * 256;
    for (int w = 0; w < kSummaryWords; ++w)
      for (uint64_t bits = words[w], byte = (uint64_t)w * 8; bits; bits >>= 8, ++byte)
        if (bits & 0xff) mx = Max(mx, table[(byte << 8) | (bits & 0xff)]);
    return mx;
  }
  ForEachBin(words, [&](int bin) { mx = Max(mx, in.binMax[t * kSummaryBins + bin]); });
  return mx;
}

// The minimum of coefficient TF t's binMin over the set bins of a summary.
MMRTM_CPU_GPU inline float MinOverBins(const RefitInputs& in, int t, const uint64_t* words) {
  float mn = kInfinity;
  if (in.byteMin) {
    const float* table = in.byteMin + (size_t)t * kSummaryBytes * 256;
    for (int w = 0; w < kSummaryWords; ++w)
      for (uint64_t bits = words[w], byte = (uint64_t)w * 8; bits; bits >>= 8, ++byte)
        if (bits & 0xff) mn = Min(mn, table[(byte << 8) | (bits & 0xff)]);
  } else {
    ForEachBin(words, [&](int bin) { mn = Min(mn, in.binMin[t * kSummaryBins + bin]); });
  }
  return mn < kInfinity ? mn : 0.f;
}

// Material m's base density times each of its density TFs' maximum
// (`Lower`: minimum) over the bins of summary `summary`.
template <bool Lower>
MMRTM_CPU_GPU inline float MaterialDensityBound(const Classifier& c, const RefitInputs& in, int64_t summary, int m) {
  const MaterialView& mat = c.materials[m];
  float d = mat.base[0];
  for (int b = 0; b < mat.densityBindingCount && d > 0.f; ++b) {
    const int t = c.bindings[mat.bindingBegin + b].tf;
    const uint64_t* words = in.summaries[c.tfs[t].proxy] + summary * kSummaryWords;
    d *= Lower ? MinOverBins(in, t, words) : MaxOverBins(in, t, words);
  }
  return d;
}

// The extinction bound of the leaves with summary `summary`: over the
// materials that can occur in them (the default, and whatever a material TF
// can pick from the summary's bins), the product of each density TF's
// maximum over the summary's bins; their maximum, or their sum for an
// additive mixture.
MMRTM_CPU_GPU inline float SummaryMajorant(const Classifier& c, const RefitInputs& in, int64_t summary) {
  // (A mixture has every material everywhere.)
  uint64_t candidates = c.additive ? ~0ull : (c.defaultMaterial != kNoMaterial ? 1ull << c.defaultMaterial : 0);
  for (int s = 0; s < c.selectorCount && in.materialMasks && !c.additive; ++s) {
    const int t = c.selectors[s];
    ForEachBin(in.summaries[c.tfs[t].proxy] + summary * kSummaryWords,
               [&](int b) { candidates |= in.binMaterials[t * kSummaryBins + b]; });
  }
  float majorant = 0.f;
  for (int m = 0; m < c.materialCount; ++m) {
    if (in.materialMasks && !(candidates & (1ull << m))) continue;
    const float d = MaterialDensityBound<false>(c, in, summary, m);
    majorant = c.additive ? majorant + d : Max(majorant, d);  // a mixture's extinctions add up
  }
  if (Planted(Defect::MajorantLow)) majorant *= 0.98f;
  return Min(majorant, c.maxExtinction);  // as Classify clamps sigma_t
}

// A lower bound of the extinction in the leaves with summary `summary`
// (the residual ratio tracking's control, tracking.h): 0 where a point may
// have no material; otherwise the least, over the materials that can occur,
// of base density times the product of each density TF's lower bound over
// the summary's bins (their sum for an additive mixture). Why the least over
// the candidates bounds the classification: at a value where the first
// selector naming a material picks m, m's density is at least m's bound, so
// if every candidate's bound is above 0 that material wins; where no
// selector names one, the default (a candidate) classifies, and without a
// default some selector must name a material over all the summary's bins.
MMRTM_CPU_GPU inline float SummaryMinorant(const Classifier& c, const RefitInputs& in, int64_t summary) {
  if (!in.binMin) return 0.f;
  uint64_t candidates = ~0ull;
  if (!c.additive) {
    bool covered = c.defaultMaterial != kNoMaterial;
    candidates = covered ? 1ull << (c.defaultMaterial & 63) : 0;  // (unread without materialMasks)
    for (int s = 0; s < c.selectorCount; ++s) {
      const int t = c.selectors[s];
      const uint64_t* words = in.summaries[c.tfs[t].proxy] + summary * kSummaryWords;
      uint64_t uncovered = 0;
      for (int w = 0; w < kSummaryWords; ++w) uncovered |= words[w] & in.uncoveredBins[t * kSummaryWords + w];
      covered = covered || uncovered == 0;
      if (in.materialMasks) ForEachBin(words, [&](int b) { candidates |= in.binMaterials[t * kSummaryBins + b]; });
    }
    if (!covered) return 0.f;
  }
  float minorant = c.additive ? 0.f : kInfinity;
  for (int m = 0; m < c.materialCount; ++m) {
    if (in.materialMasks && !(candidates & (1ull << m))) continue;
    const float d = MaterialDensityBound<true>(c, in, summary, m);
    minorant = c.additive ? minorant + d : Min(minorant, d);
  }
  if (Planted(Defect::MinorantHigh)) minorant *= 1.02f;
  return minorant < kInfinity ? Min(Max(minorant, 0.f), c.maxExtinction) : 0.f;
}

// An upper-level node's bounds from its (up to 8) children: the maximum of
// their majorants, and the least of their minorants as the node's minorant
// byte (MajorantGridView::minorants).
MMRTM_CPU_GPU inline void UpperNodeBounds(const MajorantGridView& g, float* majorants, uint8_t* minorants, int level,
                                          int x, int y, int z) {
  const int* rc = g.res[level + 1];
  const int64_t strideY = rc[0], strideZ = (int64_t)rc[0] * rc[1];
  const int64_t first = g.Index(level + 1, 2 * x, 2 * y, 2 * z);
  const int nx = Min(2, rc[0] - 2 * x), ny = Min(2, rc[1] - 2 * y), nz = Min(2, rc[2] - 2 * z);
  float mx = 0.f, mn = kInfinity;
  for (int cz = 0; cz < nz; ++cz)
    for (int cy = 0; cy < ny; ++cy)
      for (int cx = 0; cx < nx; ++cx) {
        const int64_t i = first + cx + cy * strideY + cz * strideZ;
        mx = Max(mx, majorants[i]);
        mn = Min(mn, DecodeMinorant(majorants[i], minorants[i]));
      }
  const int64_t node = g.Index(level, x, y, z);
  majorants[node] = mx;
  minorants[node] = EncodeMinorant(mx, mn);
}

}  // namespace mmrtm
