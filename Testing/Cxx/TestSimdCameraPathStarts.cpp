// The camera paths' starts in SIMD lanes (cuda/simd/camera_path_starts.h,
// and the walks' starts of cuda/simd/grid_walk_lanes.h) against the scalar
// CameraSample, SceneView::DomainInterval and GridMajorantIterator, number
// by number, on every instruction set this machine runs.
//
// What it catches, and names: a hash, a Sobol' pair or the PCG32 seeding
// that differs in any bit, a camera ray or depth-buffer end that rounds
// differently (perspective, orthographic, an off-centre window), a ray
// judged in or out of the domain otherwise (the volume's box, clip planes
// from every side and parallel to the ray), a walk that starts in another
// cell or node. TestSimdBackend sees such a drift only as an image that
// differs; this test says which number. Planted and seen failing: the
// replicate's key constant swapped, the box's far-distance factor left out,
// the clip planes' parallel case dropped.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "TestSceneHelpers.h"
#include "camera_path_starts.h"
#include "grid_walk_lanes.h"
#include "mmrtm/integrator.h"
#include "simd_targets.h"

namespace mmrtm {
namespace {

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

float Pattern(int i, int j, int k) { return (float)((i * j + k) % 5) / 4.f; }

// The lanes' starts of every sample of a w x h film (spp each) against the
// scalar ones; `what` names the scene.
void ExpectSameStarts(const SceneView& s, int spp, const std::string& what) {
  ASSERT_TRUE(CameraPathStartsRun(s)) << what;
  const int w = s.camera.width, h = s.camera.height;
  for (const SimdTarget& target : AvailableSimdTargets()) {
    ForceSimdTarget(target.bits);
    CameraPathStarts st;
    st.Resize((size_t)w * h * spp);
    size_t i = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int k = 0; k < spp; ++k, ++i) {
          st.x[i] = x;
          st.y[i] = y;
          st.sampleIndex[i] = (uint32_t)(k * 7919 + 1);  // large and odd indices too
        }
    StartCameraPaths(s, st);
    GridWalkLanes walks;
    walks.Resize(st.Size());
    const float* const o[3] = {st.indexO[0].data(), st.indexO[1].data(), st.indexO[2].data()};
    const float* const d[3] = {st.indexD[0].data(), st.indexD[1].data(), st.indexD[2].data()};
    StartWalks(s.majorants.grid, o, d, st.t0.data(), st.t1.data(), st.Size(), walks);
    int failures = 0, inDomain = 0;
    for (i = 0; i < st.Size() && failures < 5; ++i) {
      const std::string at = what + ", " + target.name + ", sample " + std::to_string(i);
      const CameraSample cs(s, st.x[i], st.y[i], st.sampleIndex[i]);
      const int before = ::testing::UnitTest::GetInstance()->current_test_info()->result()->total_part_count();
      EXPECT_EQ(cs.rng.State(), st.rngState[i]) << at << ": PCG32 state";
      EXPECT_EQ(cs.rng.Inc(), st.rngInc[i]) << at << ": PCG32 increment";
      EXPECT_EQ(cs.pairs.Key(), st.sobolKey[i]) << at << ": Sobol' key";
      EXPECT_EQ(cs.pairs.ReversedIndex(), st.sobolReversedIndex[i]) << at << ": Sobol' index";
      float u0, u1;
      cs.FreePathPair(&u0, &u1);
      EXPECT_TRUE(SameBits(u0, st.freePathU0[i]) && SameBits(u1, st.freePathU1[i])) << at << ": free-path pair";
      for (int a = 0; a < 3; ++a)
        EXPECT_TRUE(SameBits(cs.ray.o[a], st.o[a][i]) && SameBits(cs.ray.d[a], st.d[a][i]))
            << at << ": camera ray, axis " << a << " (" << cs.ray.d[a] << " vs " << st.d[a][i] << ")";
      EXPECT_TRUE(SameBits(cs.tMax, st.tMax[i])) << at << ": ray end";
      const TentativeCollisionStart walk(s, cs.ray, cs.tMax, 1.f);
      EXPECT_EQ(walk.inDomain, st.inDomain[i] != 0) << at << ": in the domain";
      if (walk.inDomain && st.inDomain[i]) {
        ++inDomain;
        const GridWalkState g = walk.it.GridWalk()->State();
        for (int a = 0; a < 3; ++a) {
          EXPECT_TRUE(SameBits(g.o[a], walks.o[a][i]) && SameBits(g.d[a], walks.d[a][i])) << at << ": index ray";
          EXPECT_TRUE(SameBits(g.invD[a], walks.invD[a][i])) << at << ": 1 / d";
          EXPECT_TRUE(SameBits(g.tFace[a], walks.tFace[a][i])) << at << ": face ahead, axis " << a;
          EXPECT_EQ(g.cell[a], walks.cell[a][i]) << at << ": cell, axis " << a;
        }
        EXPECT_TRUE(SameBits(g.t, walks.itT[i]) && SameBits(g.tEnd, walks.tEnd[i])) << at << ": interval";
        EXPECT_EQ(g.level, walks.level[i]) << at << ": level";
        EXPECT_EQ(g.node, (int64_t)walks.node[i]) << at << ": node";
      }
      if (::testing::UnitTest::GetInstance()->current_test_info()->result()->total_part_count() != before) ++failures;
    }
    EXPECT_GT(inDomain, 0) << what << ": no ray reached the volume; the walks' starts went untested";
    EXPECT_LT(inDomain, (int)st.Size()) << what << ": every ray reached the volume; misses went untested";
  }
  ForceSimdTarget(0);
}

Scene MakeScene() {
  Scene scene = test::MakeLitSurfaceScene(test::MakeVolume(12, 10, 9, Pattern));
  scene.render.width = 19;
  scene.render.height = 13;
  return scene;
}

TEST(SimdCameraPathStarts, Perspective) {
  Scene scene = MakeScene();
  SceneView view = scene.Build();
  ExpectSameStarts(view, 3, "perspective");
}

TEST(SimdCameraPathStarts, OrthographicOffCentreWithDepthBuffer) {
  Scene scene = MakeScene();
  SceneView view = scene.Build();
  view.camera.projection = Projection::Orthographic;
  view.camera.orthoHalfHeight = 9.f;
  view.camera.windowCenterX = 0.3f;
  view.camera.windowCenterY = -0.2f;
  std::vector<float> depth((size_t)view.camera.width * view.camera.height);
  for (size_t i = 0; i < depth.size(); ++i) depth[i] = i % 3 == 0 ? INFINITY : 20.f + (float)(i % 17);
  view.cameraRayMaxDistance = depth.data();
  ExpectSameStarts(view, 2, "orthographic, off centre, depth buffer");
}

TEST(SimdCameraPathStarts, ClipPlanes) {
  Scene scene = MakeScene();
  SceneView view = scene.Build();
  const Vec3 c = view.camera.position + view.camera.forward * 30.f;
  // Planes facing each way, and an oblique one.
  const Vec3 normals[4] = {view.camera.right, view.camera.up * -1.f, view.camera.forward,
                           view.camera.right * 0.6f + view.camera.up * 0.8f};
  for (int i = 0; i < 4; ++i) {
    view.clipPlanes[i].normal = normals[i];
    view.clipPlanes[i].offset = -Dot(normals[i], c) + (i == 2 ? -3.f : 1.5f);
  }
  view.clipPlaneCount = 4;
  ExpectSameStarts(view, 2, "clip planes");
}

// Rays exactly parallel to a clip plane (DomainInterval's own case): an
// orthographic camera along z, planes whose normals are x and y.
TEST(SimdCameraPathStarts, ClipPlanesParallelToTheRays) {
  Scene scene = MakeScene();
  SceneView view = scene.Build();
  view.camera.projection = Projection::Orthographic;
  view.camera.position = Vec3(5.5f, 4.5f, -20.f);
  view.camera.forward = Vec3(0.f, 0.f, 1.f);
  view.camera.right = Vec3(1.f, 0.f, 0.f);
  view.camera.up = Vec3(0.f, 1.f, 0.f);
  view.camera.orthoHalfHeight = 7.f;
  view.clipPlanes[0] = {Vec3(1.f, 0.f, 0.f), -5.5f};  // keeps x >= 5.5
  view.clipPlanes[1] = {Vec3(0.f, -1.f, 0.f), 6.f};   // keeps y <= 6
  view.clipPlaneCount = 2;
  ExpectSameStarts(view, 2, "clip planes parallel to the rays");
}

}  // namespace
}  // namespace mmrtm
