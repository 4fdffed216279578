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
//     computed on the host (TFs x 256 entries, microseconds).
#pragma once

#include "mmrtm/classifier.h"
#include "mmrtm/majorant_grid.h"

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
    const MaterialView& mat = c.materials[m];
    float d = mat.base[0];
    for (int b = 0; b < mat.densityBindingCount && d > 0.f; ++b) {
      const int t = c.bindings[mat.bindingBegin + b].tf;
      d *= MaxOverBins(in, t, in.summaries[c.tfs[t].proxy] + summary * kSummaryWords);
    }
    majorant = c.additive ? majorant + d : Max(majorant, d);  // a mixture's extinctions add up
  }
  return Min(majorant, c.maxExtinction);  // as Classify clamps sigma_t
}

// An upper-level node's bound: the maximum of its (up to 8) children.
MMRTM_CPU_GPU inline float UpperNodeMajorant(const MajorantGridView& g, const float* majorants, int level, int x,
                                             int y, int z) {
  const int* rc = g.res[level + 1];
  float mx = 0.f;
  for (int cz = 2 * z; cz <= 2 * z + 1 && cz < rc[2]; ++cz)
    for (int cy = 2 * y; cy <= 2 * y + 1 && cy < rc[1]; ++cy)
      for (int cx = 2 * x; cx <= 2 * x + 1 && cx < rc[0]; ++cx) mx = Max(mx, majorants[g.Index(level + 1, cx, cy, cz)]);
  return mx;
}

}  // namespace mmrtm
