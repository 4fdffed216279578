// Tests of the derived proxies (gradient magnitude, smoothed, opacity) on
// synthetic ramps, constants and impulses, and of their use by SceneFromJson:
// computed with the right type and values when read, not at all when unread.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "derived_proxies.h"
#include "scene_json.h"
#include "TestTypedVolumes.h"

using namespace mmrtm;
using namespace mmrtm::test;
using nlohmann::json;

namespace {

// An oblique, sheared, anisotropic grid.
Affine3 ObliqueGrid() {
  Affine3 a;
  const float m[3][4] = {{0.8f, 0.3f, 0.f, -4.f}, {-0.2f, 1.1f, 0.2f, 7.f}, {0.1f, 0.f, 1.5f, 2.f}};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) a.m[r][c] = m[r][c];
  return a;
}

template <typename F>
void ForEachVoxel(const HostVolume& v, F f) {
  for (int k = 0; k < v.dims[2]; ++k)
    for (int j = 0; j < v.dims[1]; ++j)
      for (int i = 0; i < v.dims[0]; ++i) f(i, j, k);
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(DerivedProxies, GradientOfARampOnAnObliqueGrid) {
  // v = a . world: its gradient is a at every voxel, border included (the
  // one-sided differences of a linear function are exact too).
  const Affine3 grid = ObliqueGrid();
  const Vec3 a{3.f, -2.f, 6.f};  // |a| = 7 per mm
  HostVolume ramp = MakeTyped<float>(
      {7, 6, 5},
      [&](int i, int j, int k) {
        return Dot(a, grid.ApplyPoint({float(i), float(j), float(k)}));
      },
      grid);
  HostVolume g = GradientMagnitudeProxy(ramp, "grad");
  EXPECT_EQ(g.name, "grad");
  EXPECT_EQ(g.type, VoxelType::Float32);
  EXPECT_EQ(g.interpolation, Interpolation::Trilinear);
  EXPECT_EQ(g.dims, ramp.dims);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) EXPECT_EQ(g.indexToWorld.m[r][c], grid.m[r][c]);
  ForEachVoxel(g, [&](int i, int j, int k) { ASSERT_NEAR(At(g, i, j, k), 7.f, 2e-4f) << i << " " << j << " " << k; });
}

TEST(DerivedProxies, GradientOfIntegerRampsUsesTheSmallestType) {
  struct Case {
    VoxelType sourceType;
    double slopePerVoxel, spacing, expected;
    VoxelType expectedType;
  } cases[] = {
      {VoxelType::UInt8, 3, 1, 3, VoxelType::UInt8},
      {VoxelType::Int16, 100, 0.5, 200, VoxelType::UInt8},
      {VoxelType::Int16, 400, 0.5, 800, VoxelType::Int16},
      {VoxelType::UInt16, 20000, 0.5, 40000, VoxelType::UInt16},
      {VoxelType::UInt16, 30000, 0.25, 120000, VoxelType::Float32},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.expected);
    // Ramp along y (the middle axis), 3 voxels long; x and z are 2 and 1 thick.
    auto f = [&](int, int j, int) { return c.slopePerVoxel * j - (c.sourceType == VoxelType::Int16 ? 300 : 0); };
    const Affine3 grid = Grid({0, 0, 0}, {1.5, c.spacing, 2});
    HostVolume v = c.sourceType == VoxelType::UInt8   ? MakeTyped<uint8_t>({2, 3, 1}, f, grid)
                   : c.sourceType == VoxelType::Int16 ? MakeTyped<int16_t>({2, 3, 1}, f, grid)
                                                      : MakeTyped<uint16_t>({2, 3, 1}, f, grid);
    HostVolume g = GradientMagnitudeProxy(v, "grad");
    EXPECT_EQ(g.type, c.expectedType);
    ForEachVoxel(g, [&](int i, int j, int k) { EXPECT_EQ(At(g, i, j, k), (float)c.expected); });
  }
}

TEST(DerivedProxies, GradientIsRoundedForIntegerSources) {
  // v = i with spacing 3: 1/3 per mm rounds to 0; v = 2i: 2/3 rounds to 1.
  HostVolume v = MakeTyped<uint8_t>(
      {4, 2, 2}, [](int i, int, int) { return i; }, Grid({0, 0, 0}, {3, 1, 1}));
  EXPECT_EQ(At(GradientMagnitudeProxy(v, "g"), 1, 0, 0), 0.f);
  v = MakeTyped<uint8_t>(
      {4, 2, 2}, [](int i, int, int) { return 2 * i; }, Grid({0, 0, 0}, {3, 1, 1}));
  EXPECT_EQ(At(GradientMagnitudeProxy(v, "g"), 1, 0, 0), 1.f);
}

TEST(DerivedProxies, SmoothingAConstantIsConstant) {
  HostVolume f = MakeTyped<float>(
      {9, 7, 5}, [](int, int, int) { return 2.5; }, ObliqueGrid());
  HostVolume s = SmoothedProxy(f, 1.7f, "smooth");
  EXPECT_EQ(s.type, VoxelType::Float32);
  ForEachVoxel(s, [&](int i, int j, int k) { ASSERT_NEAR(At(s, i, j, k), 2.5f, 1e-5f); });
  HostVolume ct = MakeTyped<int16_t>(
      {6, 6, 6}, [](int, int, int) { return -500; }, Grid({0, 0, 0}, {0.7, 0.7, 2}));
  s = SmoothedProxy(ct, 3.f, "smooth");
  EXPECT_EQ(s.type, VoxelType::Int16);
  ForEachVoxel(s, [&](int i, int j, int k) { ASSERT_EQ(At(s, i, j, k), -500.f); });
  HostVolume u = MakeTyped<uint16_t>(
      {6, 6, 6}, [](int, int, int) { return 7; }, Grid({0, 0, 0}, {1, 1, 1}));
  s = SmoothedProxy(u, 0.4f, "smooth");
  EXPECT_EQ(s.type, VoxelType::UInt8);  // the smallest type that holds 7
  ForEachVoxel(s, [&](int i, int j, int k) { ASSERT_EQ(At(s, i, j, k), 7.f); });
}

TEST(DerivedProxies, SmoothingSigmaIsInMillimetresPerAxis) {
  // An impulse: the result is the product of three 1D kernels, so the ratio
  // of a neighbour to the centre along axis a is exp(-1 / (2 sigma_a^2))
  // with sigma_a = sigma_mm / spacing_a voxels.
  const int n = 27, c = 13;  // the x kernel (radius 12) fits inside
  HostVolume impulse = MakeTyped<float>(
      {n, n, n}, [&](int i, int j, int k) { return i == c && j == c && k == c ? 1000 : 0; },
      Grid({0, 0, 0}, {0.5, 1, 2}));
  HostVolume s = SmoothedProxy(impulse, 2.f, "smooth");
  const float centre = At(s, c, c, c);
  const double sigma[3] = {4, 2, 1};
  EXPECT_NEAR(At(s, c + 1, c, c) / centre, std::exp(-0.5 / (sigma[0] * sigma[0])), 1e-5);
  EXPECT_NEAR(At(s, c, c - 1, c) / centre, std::exp(-0.5 / (sigma[1] * sigma[1])), 1e-5);
  EXPECT_NEAR(At(s, c, c, c + 1) / centre, std::exp(-0.5 / (sigma[2] * sigma[2])), 1e-5);
  // Radius ceil(3 sigma): 3 voxels along z, nothing beyond.
  EXPECT_GT(At(s, c, c, c + 3), 0.f);
  EXPECT_EQ(At(s, c, c, c + 4), 0.f);
  // The kernels are normalised and reach no border: the sum is kept.
  double sum = 0;
  ForEachVoxel(s, [&](int i, int j, int k) { sum += At(s, i, j, k); });
  EXPECT_NEAR(sum, 1000.0, 1e-2);
}

TEST(DerivedProxies, OpacityFollowsTheTransferFunction) {
  HostVolume v = MakeTyped<float>(
      {16, 16, 1}, [](int i, int j, int) { return 16 * j + i - 0.25; }, Grid({0, 0, 0}, {1, 1, 1}));
  HostVolume o = OpacityProxy(v, {{50, 0}, {150, 1}, {200, 0.5}}, "opacity");
  EXPECT_EQ(o.type, VoxelType::UInt8);
  EXPECT_EQ(o.interpolation, Interpolation::Trilinear);
  ForEachVoxel(o, [&](int i, int j, int k) {
    const double x = At(v, i, j, k);
    const double op = x <= 50 ? 0 : x <= 150 ? (x - 50) / 100 : x <= 200 ? 1 - 0.5 * (x - 150) / 50 : 0.5;
    ASSERT_EQ(At(o, i, j, k), (float)std::lround(op * 255)) << x;
  });
  // A repeated value is a step (at the value itself, the later point wins, as in a CCTF).
  HostVolume step = OpacityProxy(v, {{100, 0}, {100, 1}}, "opacity");
  ForEachVoxel(step, [&](int i, int j, int k) { ASSERT_EQ(At(step, i, j, k), At(v, i, j, k) >= 100 ? 255.f : 0.f); });
}

TEST(DerivedProxies, BadParametersThrow) {
  HostVolume v = MakeTyped<uint8_t>(
      {4, 4, 4}, [](int i, int, int) { return i; }, Grid({0, 0, 0}, {1, 1, 1}));
  for (float sigma : {0.f, -1.f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    const std::string m = ErrorOf([&] { SmoothedProxy(v, sigma, "smooth"); });
    EXPECT_NE(m.find("smooth: the smoothing sigma must be a positive number of mm"), std::string::npos) << m;
  }
  EXPECT_NE(
      ErrorOf([&] { OpacityProxy(v, {}, "op"); }).find("op: an opacity transfer function needs at least one point"),
      std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              OpacityProxy(v, {{10, 0}, {5, 1}}, "op");
            }).find("op: opacity point 1 [5, 1]: values must not decrease"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { OpacityProxy(v, {{10, 1.5f}}, "op"); }).find("opacity must be in 0..1"), std::string::npos);
  HostVolume broken = v;
  broken.voxels.resize(3);
  EXPECT_NE(ErrorOf([&] { GradientMagnitudeProxy(broken, "g"); }).find("scalars.nrrd: voxel buffer size"),
            std::string::npos);
}

// ---- Through the scene format ----

namespace {

SceneInputs RampInputs() {
  // uint8 ramp of 10 per voxel along x, 0.5 mm voxels: 20 per mm.
  SceneInputs in;
  in.volumes["scalars"] = MakeTyped<uint8_t>(
      {10, 6, 4}, [](int i, int, int) { return 10 * i; }, Grid({0, 0, 0}, {0.5, 0.8, 1.2}));
  return in;
}

// A scene whose one material's density reads `proxy`.
json SceneReading(const std::string& proxy, const json& volumes) {
  json doc =
      json::parse(R"({"materials": {"m": {"tfs": {"density": [{"type": "cctf", "points": [[0, 0], [255, 1]]}]}}}})");
  doc["materials"]["m"]["tfs"]["density"][0]["proxy"] = proxy;
  doc["volumes"] = volumes;
  return doc;
}

std::string SceneError(const json& doc, SceneInputs in = RampInputs()) {
  try {
    SceneFromJson(doc, std::move(in));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(DerivedProxies, SceneBuildsAReadGradientProxy) {
  Scene s = SceneFromJson(
      SceneReading("grad", json::parse(R"({"grad": {"derived": "gradient_magnitude", "from": "scalars"}})")),
      RampInputs());
  const int g = s.ProxyIndex("grad");
  ASSERT_EQ(g, 1);
  const HostVolume& grad = s.proxies[g];
  EXPECT_EQ(grad.type, VoxelType::UInt8);
  EXPECT_EQ(grad.dims, s.proxies[0].dims);
  EXPECT_EQ(grad.interpolation, Interpolation::Trilinear);
  ForEachVoxel(grad, [&](int i, int j, int k) { ASSERT_EQ(At(grad, i, j, k), 20.f); });
  EXPECT_EQ(s.tfs[0].proxy, g);
}

TEST(DerivedProxies, SceneBuildsSmoothedAndOpacityProxies) {
  SceneInputs in;
  in.volumes["scalars"] = MakeTyped<float>(
      {8, 8, 8}, [](int, int, int) { return 3.25; }, ObliqueGrid());
  Scene s = SceneFromJson(
      SceneReading("smooth", json::parse(R"({"smooth": {"derived": "smoothed", "from": "scalars", "sigma_mm": 1.0}})")),
      in);
  const HostVolume& smooth = s.proxies[s.ProxyIndex("smooth")];
  EXPECT_EQ(smooth.type, VoxelType::Float32);
  ForEachVoxel(smooth, [&](int i, int j, int k) { ASSERT_NEAR(At(smooth, i, j, k), 3.25f, 1e-5f); });

  s = SceneFromJson(
      SceneReading("op",
                   json::parse(R"({"op": {"derived": "opacity", "from": "scalars", "points": [[0, 0], [80, 0.4]]}})")),
      RampInputs());
  const HostVolume& op = s.proxies[s.ProxyIndex("op")];
  EXPECT_EQ(op.type, VoxelType::UInt8);
  ForEachVoxel(op, [&](int i, int j, int k) {
    ASSERT_EQ(At(op, i, j, k), (float)std::lround(std::min(10.0 * i, 80.0) / 80 * 0.4 * 255));
  });
}

TEST(DerivedProxies, SceneBuildsADerivedGradientProxy) {
  // Read only as the surface normal's proxy: kept and computed.
  json doc =
      SceneReading("scalars", json::parse(R"({"smooth": {"derived": "smoothed", "from": "scalars", "sigma_mm": 2}})"));
  doc["gradient_proxy"] = "smooth";
  Scene s = SceneFromJson(doc, RampInputs());
  ASSERT_GE(s.ProxyIndex("smooth"), 0);
  EXPECT_EQ(s.gradientProxy, s.ProxyIndex("smooth"));
  EXPECT_EQ(s.proxies[s.gradientProxy].type, VoxelType::UInt8);
}

TEST(DerivedProxies, SceneSkipsUnreadDerivedProxies) {
  // The source of "grad" is a broken volume: computing it would throw, so no
  // error means it was never computed.
  SceneInputs in = RampInputs();
  in.volumes["other"] = in.volumes["scalars"];
  in.volumes["other"].source = "other.nrrd";
  in.volumes["other"].voxels.resize(5);
  json doc = SceneReading("scalars", json::parse(R"({
    "grad": {"derived": "gradient_magnitude", "from": "other"},
    "op": {"derived": "opacity", "from": "scalars", "points": [[0, 1]]}})"));
  Scene s = SceneFromJson(doc, in);
  EXPECT_EQ(s.ProxyIndex("grad"), -1);
  EXPECT_EQ(s.ProxyIndex("op"), -1);
  EXPECT_EQ(s.proxies.size(), 1u);
  // Read, the broken source is reported.
  doc["materials"]["m"]["tfs"]["density"][0]["proxy"] = "grad";
  const std::string message = SceneError(doc, in);
  EXPECT_NE(message.find("other.nrrd: voxel buffer size"), std::string::npos) << message;
}

TEST(DerivedProxies, SceneErrorsNameTheJsonPath) {
  struct Case {
    const char* volumes;
    const char* expected;
  } cases[] = {
      {R"({"g": {"derived": "laplacian", "from": "scalars"}})",
       "volumes.g.derived: expected gradient_magnitude, smoothed or opacity, got 'laplacian'"},
      {R"({"g": {"derived": 3, "from": "scalars"}})", "volumes.g.derived: expected gradient_magnitude"},
      {R"({"g": {"derived": "gradient_magnitude", "from": "ct"}})",
       "volumes.g.from: no volume named 'ct' (the scene has: scalars)"},
      {R"({"g": {"derived": "gradient_magnitude"}})", "volumes.g.from: a derived volume needs 'from'"},
      {R"({"g": {"derived": "gradient_magnitude", "from": "h"}, "h": {"derived": "gradient_magnitude", "from": "scalars"}})",
       "volumes.g.from: 'h' is itself derived"},
      {R"({"g": {"derived": "gradient_magnitude", "from": "scalars", "sigma_mm": 1}})",
       "volumes.g: unknown key 'sigma_mm' (expected one of: derived, from)"},
      {R"({"s": {"derived": "smoothed", "from": "scalars", "sigma_mm": 0}})",
       "volumes.s.sigma_mm: must be a positive number of mm"},
      {R"({"s": {"derived": "smoothed", "from": "scalars", "sigma_mm": -2}})",
       "volumes.s.sigma_mm: must be a positive number of mm"},
      {R"({"s": {"derived": "smoothed", "from": "scalars", "sigma_mm": "big"}})",
       "volumes.s.sigma_mm: expected a number"},
      {R"({"s": {"derived": "smoothed", "from": "scalars"}})", "volumes.s: a smoothed volume needs sigma_mm"},
      {R"({"o": {"derived": "opacity", "from": "scalars"}})", "volumes.o.points: an opacity volume needs"},
      {R"({"o": {"derived": "opacity", "from": "scalars", "points": []}})",
       "volumes.o.points: an opacity volume needs"},
      {R"({"o": {"derived": "opacity", "from": "scalars", "points": [[10, 0], [5, 1]]}})",
       "volumes.o.points[1]: values must be in ascending order"},
      {R"({"o": {"derived": "opacity", "from": "scalars", "points": [[10, 2]]}})",
       "volumes.o.points[0]: opacity must be in 0..1"},
      {R"({"o": {"derived": "opacity", "from": "scalars", "points": [[10, 0, 1]]}})",
       "volumes.o.points[0]: expected [value, opacity]"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.volumes);
    // Errors are reported whether or not a TF reads the volume.
    const std::string message = SceneError(SceneReading("scalars", json::parse(c.volumes)));
    EXPECT_EQ(message.rfind(c.expected, 0), 0u) << message;
  }
}
