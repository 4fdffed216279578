// The instruction sets the SIMD code was built for, and forcing one of them,
// so that a test runs each that the machine can (AVX2 on an AVX-512 machine).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mmrtm {

struct SimdTarget {
  int64_t bits = 0;  // Highway's target bit (HWY_AVX3, HWY_AVX2, ...)
  std::string name;
};

// The targets compiled into this binary that this CPU runs, best first.
std::vector<SimdTarget> AvailableSimdTargets();

// Dispatch to `bits` from now on (one of AvailableSimdTargets); 0 returns to
// the machine's best. Not thread-safe: for tests and benchmarks.
void ForceSimdTarget(int64_t bits);

}  // namespace mmrtm
