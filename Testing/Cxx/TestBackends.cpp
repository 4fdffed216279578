// Backend choice and the CPU fall-back, on any machine: CI has nvcc but no
// GPU, so there the auto backend must pick the CPU and say why once, and an
// explicit cuda request must be a clear error. On a GPU machine the same
// tests check the other branch.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "render_backend.h"
#if MMRTM_TEST_HAVE_CUDA
#include "cuda_device.h"
#endif

namespace mmrtm {
namespace {

bool DeviceAvailable() {
#if MMRTM_TEST_HAVE_CUDA
  return CudaDevice().available;
#else
  return false;
#endif
}

TEST(Backends, ParsesNames) {
  EXPECT_EQ(ParseBackend("auto"), Backend::Auto);
  EXPECT_EQ(ParseBackend("cpu"), Backend::Cpu);
  EXPECT_EQ(ParseBackend("cuda"), Backend::Cuda);
  EXPECT_FALSE(ParseBackend("gpu").has_value());
  EXPECT_FALSE(ParseBackend("").has_value());
}

TEST(Backends, CpuIsAlwaysThere) {
  std::vector<std::string> notes;
  auto r = MakeRenderer(Backend::Cpu, 2, [&](const std::string& n) { notes.push_back(n); });
  EXPECT_FALSE(r->IsCuda());
  EXPECT_EQ(r->Description(), "cpu, 2 thread(s)");
  EXPECT_TRUE(notes.empty());
}

TEST(Backends, AutoUsesCudaOnlyWithADeviceAndSaysWhyOnce) {
  std::vector<std::string> notes;
  auto note = [&](const std::string& n) { notes.push_back(n); };
  auto first = MakeRenderer(Backend::Auto, 1, note);
  auto second = MakeRenderer(Backend::Auto, 1, note);
  EXPECT_EQ(first->IsCuda(), DeviceAvailable());
  EXPECT_EQ(second->IsCuda(), DeviceAvailable());
  if (DeviceAvailable() || !CudaBackendBuilt()) {
    EXPECT_TRUE(notes.empty()) << "nothing to say: a device, or a build without CUDA";
  } else {
    ASSERT_EQ(notes.size(), 1u) << "the missing device is reported once per process";
    EXPECT_NE(notes[0].find("rendering on the CPU"), std::string::npos) << notes[0];
    EXPECT_NE(notes[0].find("CUDA"), std::string::npos) << notes[0];
  }
}

TEST(Backends, ExplicitCudaWithoutADeviceIsAClearError) {
  if (DeviceAvailable()) {
    EXPECT_NO_THROW(RequireBackend(Backend::Cuda));
    EXPECT_TRUE(MakeRenderer(Backend::Cuda, 1)->IsCuda());
    return;
  }
  try {
    RequireBackend(Backend::Cuda);
    FAIL() << "no BackendError";
  } catch (const BackendError& e) {
    EXPECT_NE(std::string(e.what()).find("--backend cuda: "), std::string::npos) << e.what();
  }
  EXPECT_THROW(MakeRenderer(Backend::Cuda, 1), BackendError);
  EXPECT_NO_THROW(RequireBackend(Backend::Auto));
  EXPECT_NO_THROW(RequireBackend(Backend::Cpu));
}

#if MMRTM_TEST_HAVE_CUDA
TEST(Backends, DeviceQueryIsCached) {
  const CudaDeviceStatus* a = &CudaDevice();
  const CudaDeviceStatus* b = &CudaDevice();
  EXPECT_EQ(a, b);
  EXPECT_EQ(a->available, a->reason.empty());
}
#endif

}  // namespace
}  // namespace mmrtm
