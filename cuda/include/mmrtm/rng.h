// Deterministic random numbers (DESIGN.md rule 2).
//
// A pixel sample's stream depends only on (seed, pixel index, sample index):
// never on thread count, tile order or backend. PCG32 (O'Neill 2014, the
// generator pbrt-v4 uses) with the stream selected from a hash of the three.
#pragma once

#include "mmrtm/defs.h"

namespace mmrtm {

// The constants of the hashes and the generator below.
constexpr uint64_t kMixBitsMultiplier0 = 0x7fb5d329728ea185ULL, kMixBitsMultiplier1 = 0x81dadef4bc2dd44dULL;
constexpr uint64_t kPCG32Multiplier = 0x5851f42d4c957f2dULL;
constexpr uint64_t kPixelSequenceSalt = 0x9e3779b97f4a7c15ULL, kSampleOffsetMultiplier = 0x2545f4914f6cdd1dULL;

// 64-bit finaliser of MurmurHash3: spreads nearby integers over all bits.
MMRTM_CPU_GPU inline uint64_t MixBits(uint64_t v) {
  v ^= v >> 31;
  v *= kMixBitsMultiplier0;
  v ^= v >> 27;
  v *= kMixBitsMultiplier1;
  v ^= v >> 33;
  return v;
}

// A float in [0, 1) from 32 random bits (their top 24, which a float holds
// exactly); also the Sobol' numbers' conversion (mmrtm/sobol.h).
MMRTM_CPU_GPU inline float UniformFloat(uint32_t bits) {
  const float u = (float)(bits >> 8) * 0x1p-24f;
  return u < kOneMinusEpsilon ? u : kOneMinusEpsilon;
}

class PCG32 {
 public:
  MMRTM_CPU_GPU PCG32() { SetSequence(0, 0x853c49e6748fea9bULL); }
  MMRTM_CPU_GPU PCG32(uint64_t sequence, uint64_t offset) { SetSequence(sequence, offset); }

  // Selects stream `sequence`, starting at a state derived from `offset`.
  MMRTM_CPU_GPU void SetSequence(uint64_t sequence, uint64_t offset) {
    state_ = 0u;
    inc_ = (sequence << 1u) | 1u;
    NextU32();
    state_ += offset;
    NextU32();
  }

  MMRTM_CPU_GPU uint32_t NextU32() {
    uint64_t old = state_;
    state_ = old * kPCG32Multiplier + inc_;
    uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
  }

  // Uniform float in [0, 1).
  MMRTM_CPU_GPU float Uniform() { return UniformFloat(NextU32()); }

 private:
  uint64_t state_, inc_;
};

// The random stream of one pixel sample.
MMRTM_CPU_GPU inline PCG32 PixelSampleRNG(uint64_t seed, uint64_t pixelIndex, uint64_t sampleIndex) {
  uint64_t sequence = MixBits(pixelIndex ^ MixBits(seed + kPixelSequenceSalt));
  uint64_t offset = MixBits(sampleIndex * kSampleOffsetMultiplier + seed);
  return PCG32(sequence, offset);
}

}  // namespace mmrtm
