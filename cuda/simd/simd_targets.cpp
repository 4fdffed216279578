#include "simd_targets.h"

#include <hwy/highway.h>

namespace mmrtm {

std::vector<SimdTarget> AvailableSimdTargets() {
  std::vector<SimdTarget> targets;
  for (int64_t bits : hwy::SupportedAndGeneratedTargets()) targets.push_back({bits, hwy::TargetName(bits)});
  return targets;
}

void ForceSimdTarget(int64_t bits) {
  // Highway's test hook: SupportedTargets() returns only `bits` (0: the CPU's
  // own again), and the next dynamic dispatch chooses among them.
  hwy::SetSupportedTargetsForTest(bits);
}

}  // namespace mmrtm
