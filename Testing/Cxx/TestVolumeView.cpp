// Tests of VolumeView's lookups: trilinear values against their definition
// (voxel values at the centres, clamping at the border, flat axes), and the
// central differences of the surface normal, whose fast path (the six cells
// read around one) must give the six separate lookups' values to the bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "TestTypedVolumes.h"

using namespace mmrtm;
using namespace mmrtm::test;

namespace {

// Values in [0, 250) that change along every axis, shifted to [-120, 130)
// for int16 and float, so that negative voxels are converted too.
double Pattern(int i, int j, int k) { return std::fmod(37.0 * i + 101.0 * j * j + 53.0 * k + 0.25 * i * k, 250.0); }

template <typename T>
HostVolume Make(std::array<int, 3> dims) {
  const bool isSigned = std::is_same_v<T, int16_t> || std::is_same_v<T, float>;
  return MakeTyped<T>(
      dims, [&](int i, int j, int k) { return isSigned ? Pattern(i, j, k) - 120.0 : Pattern(i, j, k); },
      Grid({0, 0, 0}, {1, 1, 1}));
}

bool SameBits(Vec3 a, Vec3 b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }

// Trilinear interpolation in double, from the definition.
double Reference(const HostVolume& v, Vec3 p) {
  double f[3];
  int c0[3], c1[3];
  for (int a = 0; a < 3; ++a) {
    const int n = v.dims[a];
    f[a] = std::min(std::max((double)p[a], 0.0), (double)(n - 1));
    c0[a] = std::min((int)std::floor(f[a]), std::max(n - 2, 0));
    c1[a] = std::min(c0[a] + 1, n - 1);
    f[a] -= c0[a];
  }
  double sum = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    double w = 1.0;
    int idx[3];
    for (int a = 0; a < 3; ++a) {
      const bool far = (corner >> a) & 1;
      idx[a] = far ? c1[a] : c0[a];
      w *= far ? f[a] : 1.0 - f[a];
    }
    sum += w * At(v, idx[0], idx[1], idx[2]);
  }
  return sum;
}

// Points over the whole domain and a voxel beyond, plus the cases that
// decide the fast path: integer positions, the last interior positions, and
// positions just below a power of two whose p + 1 rounds.
std::vector<Vec3> Points(std::array<int, 3> dims, int count) {
  std::mt19937 rng(7);
  std::vector<Vec3> points;
  auto coordinate = [&](int a) {
    std::uniform_real_distribution<float> u(-1.5f, (float)dims[a] + 0.5f);
    return u(rng);
  };
  for (int i = 0; i < count; ++i) points.push_back({coordinate(0), coordinate(1), coordinate(2)});
  const Vec3 middle{dims[0] * 0.5f + 0.3f, dims[1] * 0.5f + 0.3f, dims[2] * 0.5f + 0.3f};
  for (int a = 0; a < 3; ++a) {
    for (float x : {0.f, 1.f, 2.f, 1.0000001f, (float)dims[a] - 3.f, std::nextafter((float)dims[a] - 3.f, 0.f),
                    (float)dims[a] - 2.f, (float)dims[a] - 1.f}) {
      Vec3 p = middle;
      p[a] = x;
      points.push_back(p);
    }
    // Just below 64 and 128: p + 1 crosses the power of two, and rounds
    // where p's last mantissa bit is set (the first of each pair).
    for (float power : {64.f, 128.f}) {
      if (power + 2.f >= (float)dims[a]) continue;
      Vec3 p = middle;
      p[a] = std::nextafter(power, 0.f);
      points.push_back(p);
      p[a] = std::nextafter(p[a], 0.f);
      points.push_back(p);
    }
  }
  return points;
}

template <typename T>
void CheckCentralDifferences(std::array<int, 3> dims) {
  const HostVolume host = Make<T>(dims);
  const VolumeView v = host.View();
  int fast = 0, slow = 0;
  for (Vec3 p : Points(dims, 4000)) {
    const Vec3 six = v.CentralDifferencesBySixLookups(p);
    const Vec3 got = v.CentralDifferences(p);
    (v.NeighbourCellsAreExact(p) ? fast : slow)++;
    ASSERT_TRUE(SameBits(got, six)) << "at (" << p.x << ", " << p.y << ", " << p.z << "): (" << got.x << ", " << got.y
                                    << ", " << got.z << ") against (" << six.x << ", " << six.y << ", " << six.z << ")";
  }
  // Both paths were taken (the test is not vacuous).
  EXPECT_GT(fast, 500);
  EXPECT_GT(slow, 100);
}

}  // namespace

TEST(VolumeView, TrilinearMatchesItsDefinition) {
  const HostVolume host = Make<int16_t>({9, 7, 5});
  const VolumeView v = host.View();
  for (Vec3 p : Points({9, 7, 5}, 2000))
    ASSERT_NEAR(v.SampleIndex(p), Reference(host, p), 1e-4 * 250) << p.x << " " << p.y << " " << p.z;
  // Voxel centres give the voxel exactly.
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 7; ++j)
      for (int i = 0; i < 9; ++i) ASSERT_EQ(v.SampleIndex({(float)i, (float)j, (float)k}), At(host, i, j, k));
  // NaN is clamped to the first voxel.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(v.SampleIndex({nan, nan, nan}), At(host, 0, 0, 0));
}

TEST(VolumeView, FlatAxesInterpolateTheOtherTwo) {
  // A single slice (and a single row): the flat axis has one voxel, which
  // both corners of a cell are; nothing is read beyond the volume.
  for (std::array<int, 3> dims :
       {std::array<int, 3>{6, 5, 1}, std::array<int, 3>{6, 1, 1}, std::array<int, 3>{1, 1, 1}}) {
    const HostVolume host = Make<float>(dims);
    const VolumeView v = host.View();
    for (Vec3 p : Points(dims, 500))
      ASSERT_NEAR(v.SampleIndex(p), Reference(host, p), 1e-3) << dims[0] << dims[1] << dims[2];
    EXPECT_FALSE(v.NeighbourCellsAreExact({2.5f, 0.f, 0.f}));
  }
}

TEST(VolumeView, CentralDifferencesAroundOneCellEqualSixLookupsToTheBit) {
  CheckCentralDifferences<uint8_t>({12, 10, 8});
  CheckCentralDifferences<int16_t>({140, 9, 6});  // crosses 64 and 128 along x
  CheckCentralDifferences<uint16_t>({7, 11, 135});
  CheckCentralDifferences<float>({10, 70, 9});
}

TEST(VolumeView, TheFastPathStaysInsideTheVolume) {
  // At p = n - 2 the cell one voxel up would be the last voxel's, whose far
  // corner lies beyond the volume. Its weight is 0 there, so the value would
  // still agree with six lookups: the bounds are checked here instead.
  const HostVolume host = Make<float>({8, 8, 8});
  const VolumeView v = host.View();
  EXPECT_TRUE(v.NeighbourCellsAreExact({1.f, 3.5f, 3.5f}));
  EXPECT_FALSE(v.NeighbourCellsAreExact({std::nextafter(1.f, 0.f), 3.5f, 3.5f}));
  EXPECT_TRUE(v.NeighbourCellsAreExact({3.5f, std::nextafter(6.f, 0.f), 3.5f}));
  EXPECT_FALSE(v.NeighbourCellsAreExact({3.5f, 3.5f, 6.f}));
}

TEST(VolumeView, CentralDifferencesOfALabelMapUseSixNearestLookups) {
  HostVolume host = Make<uint8_t>({12, 10, 8});
  host.interpolation = Interpolation::Nearest;
  const VolumeView v = host.View();
  for (Vec3 p : Points({12, 10, 8}, 500))
    ASSERT_TRUE(SameBits(v.CentralDifferences(p), v.CentralDifferencesBySixLookups(p)));
}
