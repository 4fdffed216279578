// Low-discrepancy numbers for the first dimensions of a path: Owen-scrambled
// Sobol' points, two dimensions at a time (pbrt-v4's PaddedSobolSampler
// shape).
//
// Each pair of dimensions takes the first two dimensions of the Sobol'
// sequence at a shuffled sample index, and Owen-scrambles each coordinate
// with its own hash (pbrt-v4's FastOwenScrambler, Laine and Karras 2011).
// The shuffle is Burley's (2020): a nested uniform scramble of the index,
// which flips each bit by a hash of the bits above it. So:
//   - a pixel's first 2^k even samples of a pair, and its first 2^k odd
//     ones, are each a (0, k, 2)-net: stratified in every elementary
//     interval, whatever k (the shuffle maps net indices 0 .. 2^k - 1 onto
//     an aligned block of 2^k, which is a net as well);
//   - the pairs of one sample are not correlated with each other: without
//     the shuffle every pair would use the same index, and the pixel
//     position's first bit would decide the free path's first bit (a plain
//     XOR of the index by a constant leaves that correlation; measured: the
//     gain over independent numbers at 16 spp was gone at 64 spp);
//   - every sample point is uniform on its unit square (scrambling), so an
//     estimator stays unbiased; pixels and seeds are decorrelated by hashes;
//   - a number depends only on (seed, pixel, sample index, pair): the same
//     on every thread count and backend (DESIGN.md rule 2);
//   - the sample index's lowest bit picks one of two replicates, which are
//     independently scrambled nets (of index >> 1): the even samples of a
//     pixel and its odd samples are two independent estimates of its value,
//     and the difference of their means tells the error of the pixel's mean
//     (Film::Noise), which the samples' spread overstates for stratified
//     samples (randomised quasi-Monte Carlo's usual error estimate:
//     independent randomisations, compared).
// A pair costs two hashes and a few dozen bit operations, without loops or
// branches (a loop over the index bits with a data-dependent branch made
// a sample 12-15 % slower on the CPU).
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/rng.h"

namespace mmrtm {

MMRTM_CPU_GPU inline uint32_t ReverseBits32(uint32_t v) {
#if defined(__CUDA_ARCH__)
  return __brev(v);
#else
  v = (v << 16) | (v >> 16);
  v = ((v & 0x00ff00ffu) << 8) | ((v & 0xff00ff00u) >> 8);
  v = ((v & 0x0f0f0f0fu) << 4) | ((v & 0xf0f0f0f0u) >> 4);
  v = ((v & 0x33333333u) << 2) | ((v & 0xccccccccu) >> 2);
  v = ((v & 0x55555555u) << 1) | ((v & 0xaaaaaaaau) >> 1);
  return v;
#endif
}

// Sobol' dimension 1 with its bits reversed (bit k is the fraction's k-th
// bit after the point, counting from 0). Its generator matrix is Pascal's
// triangle mod 2: by Lucas' theorem fraction bit j is the XOR of the index
// bits k whose positions are supersets of j's, a superset-XOR transform of
// five shift-and-mask steps. (Dimension 0 reversed is the index itself.)
MMRTM_CPU_GPU inline uint32_t SobolDimension1Reversed(uint32_t index) {
  index ^= (index >> 1) & 0x55555555u;
  index ^= (index >> 2) & 0x33333333u;
  index ^= (index >> 4) & 0x0f0f0f0fu;
  index ^= (index >> 8) & 0x00ff00ffu;
  index ^= (index >> 16) & 0x0000ffffu;
  return index;
}

// The constants of the scramble and of the pairs' hashes below.
constexpr uint32_t kOwenMultiplier0 = 0x3d20adeau, kOwenMultiplier1 = 0x05526c56u, kOwenMultiplier2 = 0x53a22864u;
constexpr uint64_t kSobolKeySalt = 0x5851f42d4c957f2dULL, kSobolReplicateMultiplier = 0xda942042e4dd58b5ULL;
constexpr uint64_t kSobolPairMultiplier = 0x9e3779b97f4a7c15ULL;

// An Owen scramble of a fraction given with its bits reversed: each bit
// flipped by a hash of the bits above it (pbrt-v4's FastOwenScrambler,
// which reverses before and after); returns the scrambled fraction.
MMRTM_CPU_GPU inline uint32_t OwenScrambleReversed(uint32_t v, uint32_t seed) {
  v ^= v * kOwenMultiplier0;
  v += seed;
  v *= (seed >> 16) | 1u;
  v ^= v * kOwenMultiplier1;
  v ^= v * kOwenMultiplier2;
  return ReverseBits32(v);
}

// The replicate of a sample index (see above): 0 for even, 1 for odd.
MMRTM_CPU_GPU inline uint32_t SobolReplicate(uint32_t sampleIndex) { return sampleIndex & 1u; }

// The low-discrepancy pairs of one pixel sample, computed when asked for.
class SobolPairs {
 public:
  MMRTM_CPU_GPU SobolPairs(uint64_t seed, uint64_t pixelIndex, uint32_t sampleIndex)
      : key_(MixBits(pixelIndex ^
                     MixBits(seed + kSobolKeySalt + SobolReplicate(sampleIndex) * kSobolReplicateMultiplier))),
        reversedIndex_(ReverseBits32(sampleIndex >> 1)) {}
  // The pairs whose key and reversed index are these (Key(), ReversedIndex()).
  MMRTM_CPU_GPU static SobolPairs FromKey(uint64_t key, uint32_t reversedIndex) {
    SobolPairs p;
    p.key_ = key;
    p.reversedIndex_ = reversedIndex;
    return p;
  }
  MMRTM_CPU_GPU uint64_t Key() const { return key_; }
  MMRTM_CPU_GPU uint32_t ReversedIndex() const { return reversedIndex_; }

  // Pair `pair`, uniform on [0, 1)^2.
  MMRTM_CPU_GPU void Get(int pair, float* u0, float* u1) const {
    const uint64_t h = MixBits(key_ + (uint64_t)(pair + 1) * kSobolPairMultiplier);
    // Burley's shuffle: the index Owen-scrambled (as a fraction, whose
    // reversed bits are the index's), so bit k flips by the bits above it.
    const uint32_t index = OwenScrambleReversed(reversedIndex_, (uint32_t)MixBits(h));
    *u0 = UniformFloat(OwenScrambleReversed(index, (uint32_t)h));
    *u1 = UniformFloat(OwenScrambleReversed(SobolDimension1Reversed(index), (uint32_t)(h >> 32)));
  }

 private:
  SobolPairs() = default;
  uint64_t key_;
  uint32_t reversedIndex_;  // the sample index, bits reversed
};

}  // namespace mmrtm
