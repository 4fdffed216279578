// The running test's own folder under the test output folder:
// MMRTM_TEST_OUTPUT_DIR/<suite>.<test>, made when first asked for. CTest
// runs every test of a file as a process of its own, side by side, so two
// tests that wrote the same name in a shared folder collided (the NRRD and
// the MetaImage cases of TestVolumeLoader both wrote raw.raw).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

inline std::filesystem::path TestOutputFolder() {
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = test ? std::string(test->test_suite_name()) + "." + test->name() : "outside_a_test";
  for (char& c : name)
    if (c == '/') c = '_';  // parameterized tests' names
  const std::filesystem::path dir = std::filesystem::path(MMRTM_TEST_OUTPUT_DIR) / name;
  std::filesystem::create_directories(dir);
  return dir;
}
