// TactileRayCaster against analytic answers. A 6 × 14 pad (3.4 mm pitch, 4 mm foam) on a finger link at an
// arbitrary pose; objects are placed in the pad frame so the expected depth is a one-line formula. Boxes and meshes
// must match to 1e-6 m (float BVHs); spheres and cylinders are inscribed tessellations within 0.1 mm of the
// surface radially, so along a ray at distance ρ from the centre (axis) they may read shallower by at most
// sqrt(r² − ρ²) − sqrt((r − 0.1 mm)² − ρ²), never deeper.
#include "tactile/ray_caster.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "collision/collision_fixtures.h"
#include "collision/tessellation.h"
#include "test_util.h"

namespace graspsim {
namespace {

using namespace collision_fixtures;

constexpr double kPitch = 3.4e-3, kThickness = 4e-3;
constexpr unsigned kRows = 6, kCols = 14;
constexpr double kTol = 1e-6;        // m: float BVH and float rays
constexpr double kChordError = 1e-4;  // m: the promised tessellation bound
constexpr uint32_t kFirstObject = 2;  // bodies 0 (finger, carries the pad) and 1 (palm) belong to robot "hand"

const Pose kLink = At(0.3, -0.2, 0.5, QuatFromRpy(0.3, -0.4, 1.1));
const Pose kPadOrigin = At(0.01, 0.02, 0.005, QuatFromRpy(0.1, 0.2, -0.3));
const Pose kPadWorld = kLink * kPadOrigin;
const Pose kPalmAway = At(-1, -1, -1);

TactileArraySpec PadSpec(unsigned subdivision = 1) {
  TactileArraySpec pad;
  pad.id = "hand/pad";
  pad.body_id = "hand/finger";
  pad.origin = kPadOrigin;
  pad.rows = kRows;
  pad.cols = kCols;
  pad.pitch = kPitch;
  pad.thickness = kThickness;
  pad.subdivision = subdivision;
  return pad;
}

BodySpec RobotLink(const std::string& id, Geometry geometry) {
  BodySpec body = Body(id, geometry, BodyMotion::kArticulated);
  body.robot_id = "hand";
  return body;
}

// The finger's own box sits right behind the pad (its top face is the pad's z = 0): it must never be sensed.
SceneModel Scene(std::vector<BodySpec> objects, const TactileArraySpec& pad) {
  Geometry finger = BoxGeometry(Vec3(0.06, 0.03, 0.01));
  finger.origin = kPadOrigin * At(0, 0, -0.005);
  std::vector<BodySpec> bodies = {RobotLink("hand/finger", finger), RobotLink("hand/palm", BoxGeometry(Vec3(0.1, 0.1, 0.02)))};
  for (BodySpec& o : objects) bodies.push_back(std::move(o));
  SceneModel model = Model(std::move(bodies));
  model.tactile_arrays.push_back(pad);
  model.Reindex();
  return model;
}
SceneModel Scene(std::vector<BodySpec> objects, unsigned subdivision = 1) {
  return Scene(std::move(objects), PadSpec(subdivision));
}

// World poses: the hand as above, then each object at its given pose in the pad frame.
std::vector<Pose> Poses(const std::vector<Pose>& in_pad, const Pose& palm = kPalmAway) {
  std::vector<Pose> poses = {kLink, palm};
  for (const Pose& p : in_pad) poses.push_back(kPadWorld * p);
  return poses;
}

std::vector<PadHit> Cast(const TactileRayCaster& caster, const std::vector<Pose>& poses) {
  std::vector<PadHit> hits;
  caster.Cast(poses, &hits);
  return hits;
}

// A 10 × 10 × 2 cm box whose bottom face is at pad height z, yawed so its edges are not the pad's.
const Vec3 kBigBox(0.1, 0.1, 0.02);
Pose BoxBottomAt(double z) { return At(0, 0, z + 0.01, QuatFromRpy(0, 0, 0.3)); }

void ExpectFlatContact(const TactileRayCaster& caster, const std::vector<PadHit>& hits, double face_z, uint32_t body) {
  const auto& elements = caster.Elements(0);
  ASSERT_EQ(hits.size(), elements.size());
  const Vec3 normal = kPadWorld.orientation * Vec3::UnitZ();
  for (uint32_t e = 0; e < hits.size(); ++e) {
    const PadHit& h = hits[e];
    EXPECT_EQ(h.pad, 0u);
    EXPECT_EQ(h.element, e);  // ordered by element
    EXPECT_EQ(h.body, body);
    EXPECT_NEAR(h.depth, kThickness - face_z, kTol) << e;
    const Vec3 expected = kPadWorld * Vec3(elements[e].position.x(), elements[e].position.y(), face_z);
    EXPECT_LT((h.point - expected).norm(), kTol) << e;
    EXPECT_LT((h.normal - normal).norm(), 1e-12) << e;
  }
}

TEST(TactileRaysTest, ElementsAreAFlatSymmetricGridFacingUp) {
  const std::vector<PadElement> elements = MakePadElements(PadSpec());
  ASSERT_EQ(elements.size(), kRows * kCols);
  for (size_t i = 0; i < elements.size(); ++i) {
    const PadElement& e = elements[i];
    EXPECT_LT((e.normal - Vec3::UnitZ()).norm(), 1e-12) << i;
    EXPECT_EQ(e.row, i / kCols);
    EXPECT_EQ(e.col, i % kCols);
    EXPECT_NEAR(e.position.x(), (e.col + 0.5) * kPitch - kCols * kPitch / 2, 1e-12);
    EXPECT_NEAR(e.position.y(), (e.row + 0.5) * kPitch - kRows * kPitch / 2, 1e-12);
    EXPECT_EQ(e.position.z(), 0);
    // Point symmetry about the pad origin: element i mirrors element N − 1 − i.
    EXPECT_LT((e.position + elements[elements.size() - 1 - i].position).norm(), 1e-12) << i;
  }
  EXPECT_NEAR(elements.front().position.x(), -0.0221, 1e-12);
  EXPECT_NEAR(elements.front().position.y(), -0.0085, 1e-12);
  EXPECT_EQ(MakePadElements(PadSpec(0)).size(), kRows * kCols);  // subdivision 0 means 1
  TactileArraySpec single = PadSpec();
  single.rows = single.cols = 1;  // no faces at all: still +z
  EXPECT_LT((MakePadElements(single).at(0).normal - Vec3::UnitZ()).norm(), 1e-12);
}

TEST(TactileRaysTest, SubdivisionTwoGivesFourElementsPerTexel) {
  const std::vector<PadElement> elements = MakePadElements(PadSpec(2));
  ASSERT_EQ(elements.size(), 4u * kRows * kCols);
  std::vector<int> per_texel(kRows * kCols, 0);
  for (size_t i = 0; i < elements.size(); ++i) {
    const PadElement& e = elements[i];
    const size_t r = i / (2 * kCols), c = i % (2 * kCols);
    EXPECT_EQ(e.row, r / 2);
    EXPECT_EQ(e.col, c / 2);
    EXPECT_NEAR(e.position.x(), (c + 0.5) * kPitch / 2 - kCols * kPitch / 2, 1e-12);
    EXPECT_NEAR(e.position.y(), (r + 0.5) * kPitch / 2 - kRows * kPitch / 2, 1e-12);
    // Inside its texel's square.
    EXPECT_NEAR(e.position.x(), (e.col + 0.5) * kPitch - kCols * kPitch / 2, kPitch / 4 + 1e-12);
    ++per_texel[e.row * kCols + e.col];
  }
  for (int n : per_texel) EXPECT_EQ(n, 4);

  const SceneModel model = Scene({Body("box", BoxGeometry(kBigBox))}, 2);
  const TactileRayCaster caster(model);
  ASSERT_EQ(caster.Elements(0).size(), elements.size());
  ExpectFlatContact(caster, Cast(caster, Poses({BoxBottomAt(2.5e-3)})), 2.5e-3, kFirstObject);
}

TEST(TactileRaysTest, BoxPressedIntoTheWholePad) {
  const SceneModel model = Scene({Body("box", BoxGeometry(kBigBox))});
  const TactileRayCaster caster(model);
  const auto hits = Cast(caster, Poses({BoxBottomAt(2.5e-3)}));
  ExpectFlatContact(caster, hits, 2.5e-3, kFirstObject);
  EXPECT_EQ(caster.last_ray_count(), kRows * kCols);
}

TEST(TactileRaysTest, BoxOverPartOfThePadHitsExactlyTheElementsUnderIt) {
  // x from -6.8 mm (between columns 4 and 5), y from -3.4 to 6.8 mm (rows 2..4); a static body counts too.
  const Vec3 size(0.05, 0.0102, 0.01);
  const SceneModel model = Scene({Body("block", BoxGeometry(size), BodyMotion::kStatic)});
  const TactileRayCaster caster(model);
  const Pose pose = At(-0.0068 + size.x() / 2, -0.0034 + size.y() / 2, 1e-3 + size.z() / 2);
  const auto hits = Cast(caster, Poses({pose}));
  ASSERT_EQ(hits.size(), 27u);
  std::set<std::pair<uint32_t, uint32_t>> texels;
  for (const PadHit& h : hits) {
    const PadElement& e = caster.Elements(0)[h.element];
    texels.insert({e.row, e.col});
    EXPECT_NEAR(h.depth, 3e-3, kTol);
  }
  std::set<std::pair<uint32_t, uint32_t>> expected;
  for (uint32_t r = 2; r <= 4; ++r) {
    for (uint32_t c = 5; c < kCols; ++c) expected.insert({r, c});
  }
  EXPECT_EQ(texels, expected);
}

TEST(TactileRaysTest, TiltedBoxDepthIsLinearAcrossThePad) {
  // Bottom face through (0, 0, 2 mm), tilted about pad y: z(x) = 2 mm − tan θ x, depth = 2 mm + tan θ x.
  const double theta = std::atan(0.05);
  const Quat tilt(Eigen::AngleAxisd(theta, Vec3::UnitY()));
  const SceneModel model = Scene({Body("box", BoxGeometry(kBigBox))});
  const TactileRayCaster caster(model);
  const Pose pose{Vec3(0, 0, 2e-3) + tilt * Vec3(0, 0, 0.01), tilt};
  const auto hits = Cast(caster, Poses({pose}));
  ASSERT_EQ(hits.size(), kRows * kCols);
  for (const PadHit& h : hits) {
    const Vec3& p = caster.Elements(0)[h.element].position;
    EXPECT_NEAR(h.depth, 2e-3 + std::tan(theta) * p.x(), kTol) << h.element;
    const Vec3 expected = kPadWorld * Vec3(p.x(), p.y(), kThickness - h.depth);
    EXPECT_LT((h.point - expected).norm(), kTol);
  }
}

// Checks hits against a round surface whose entry height and radial distance per element are given.
template <typename Surface>
void ExpectRound(const TactileRayCaster& caster, const std::vector<PadHit>& hits, double radius, Surface surface) {
  std::vector<const PadHit*> by_element(caster.Elements(0).size(), nullptr);
  for (const PadHit& h : hits) by_element.at(h.element) = &h;
  int hit_count = 0;
  for (uint32_t e = 0; e < by_element.size(); ++e) {
    const Vec3& p = caster.Elements(0)[e].position;
    const auto [rho, centre_z] = surface(p);  // distance from the centre (axis) to the ray, height of the centre
    const bool crosses = rho < radius;
    const double analytic = crosses ? kThickness - (centre_z - std::sqrt(radius * radius - rho * rho)) : -1;
    const double inner = radius - kChordError;
    const double slack = rho < inner ? std::sqrt(radius * radius - rho * rho) - std::sqrt(inner * inner - rho * rho) : 1;
    const PadHit* h = by_element[e];
    if (analytic <= 0) {
      EXPECT_EQ(h, nullptr) << e;
    } else if (analytic - slack > kTol) {
      ASSERT_NE(h, nullptr) << e;
    }
    if (h == nullptr) continue;
    ++hit_count;
    EXPECT_LE(h->depth, analytic + kTol) << e;          // inscribed: never deeper
    EXPECT_GE(h->depth, analytic - slack - kTol) << e;  // and within the chord error
  }
  EXPECT_GT(hit_count, 20);
}

TEST(TactileRaysTest, SphereDepthMatchesTheAnalyticSurface) {
  const double r = 0.02;
  const Vec3 centre(1e-3, -0.5e-3, 1.5e-3 + r);  // lowest point 2.5 mm into the foam
  const SceneModel model = Scene({Body("ball", SphereGeometry(r))});
  const TactileRayCaster caster(model);
  const auto hits = Cast(caster, Poses({At(centre.x(), centre.y(), centre.z())}));
  ExpectRound(caster, hits, r, [&](const Vec3& p) {
    return std::pair{std::hypot(p.x() - centre.x(), p.y() - centre.y()), centre.z()};
  });
  for (const PadHit& h : hits) {
    const double distance = (h.point - kPadWorld * centre).norm();
    EXPECT_LE(distance, r + kTol);
    EXPECT_GE(distance, r - kChordError - kTol);
  }
}

TEST(TactileRaysTest, CylinderOnItsSideMatchesTheAnalyticSurface) {
  const double r = 0.015;
  const double cy = 0.7e-3, cz = 1e-3 + r;  // axis along pad x, lowest line 3 mm into the foam
  const SceneModel model = Scene({Body("roller", CylinderGeometry(r, 0.1))});
  const TactileRayCaster caster(model);
  const auto hits = Cast(caster, Poses({At(0, cy, cz, Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY())))}));
  ExpectRound(caster, hits, r, [&](const Vec3& p) { return std::pair{std::abs(p.y() - cy), cz}; });
}

TEST(TactileRaysTest, MeshCubeReadsLikeTheBox) {
  // A unit cube mesh scaled to the box, placed through a geometry origin inside the body.
  auto mesh = std::make_shared<TriangleMesh>(*BoxMesh(Vec3(1, 1, 1)));
  for (auto& v : mesh->vertices) v = v.cwiseProduct(kBigBox.cast<float>());
  Geometry geometry = MeshGeometry(mesh);
  const Pose offset = At(0.01, -0.02, 0.003, QuatFromRpy(0, 0, 0.5));
  geometry.origin = offset;
  const SceneModel model = Scene({Body("mesh", geometry)});
  const TactileRayCaster caster(model);
  // body pose = (desired geometry pose) · offset⁻¹
  ExpectFlatContact(caster, Cast(caster, Poses({BoxBottomAt(1.2e-3) * offset.Inverse()})), 1.2e-3, kFirstObject);
}

TEST(TactileRaysTest, AnalyticBoxAgreesWithItsTriangleMesh) {
  // A body that is one box is met by the slab test, any other body through Embree: the same box both ways (and
  // behind a geometry origin), at 200 seeded poses around the pad — tilted, over part of it, base inside —
  // gives the same elements, bodies and depths to the float BVH's tolerance.
  auto mesh = std::make_shared<TriangleMesh>(*BoxMesh(Vec3(1, 1, 1)));
  for (auto& v : mesh->vertices) v = v.cwiseProduct(kBigBox.cast<float>());
  const Pose offset = At(0.004, -0.01, 0.002, QuatFromRpy(0.2, 0, 0.5));
  Geometry box = BoxGeometry(kBigBox), meshed = MeshGeometry(mesh);
  box.origin = meshed.origin = offset;
  const SceneModel box_model = Scene({Body("box", box)}), mesh_model = Scene({Body("mesh", meshed)});
  const TactileRayCaster analytic(box_model), embree(mesh_model);
  std::mt19937 random(7);
  // The box's bottom centre from 4 mm above the foam to 8 mm into it (base inside past 4 mm).
  std::uniform_real_distribution<double> shift(-0.03, 0.03), depth(-0.004, 0.008), tilt(-0.3, 0.3);
  size_t compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Pose bottom = At(shift(random), shift(random), kThickness - depth(random),
                           QuatFromRpy(tilt(random), tilt(random), 3 * tilt(random)));
    const Pose in_pad = bottom * At(0, 0, kBigBox.z() / 2) * offset.Inverse();  // body pose = geometry pose · offset⁻¹
    const auto a = Cast(analytic, Poses({in_pad})), b = Cast(embree, Poses({in_pad}));
    ASSERT_EQ(a.size(), b.size()) << "trial " << trial;
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].element, b[i].element);
      EXPECT_EQ(a[i].body, b[i].body);
      EXPECT_NEAR(a[i].depth, b[i].depth, kTol) << "trial " << trial << " element " << a[i].element;
      EXPECT_LT((a[i].point - b[i].point).norm(), kTol);
    }
    compared += a.size();
  }
  EXPECT_GT(compared, 200u * kRows * kCols / 4) << "most poses must touch the pad";
}

// The first surface along the ray o + t d, t >= 0, over every triangle of `mesh` (Möller–Trumbore, double): an
// independent reading of a pad element. Entering within the foam: thickness − t; leaving first: the base is
// inside, thickness; else no contact (0).
double EveryTriangleDepth(const TriangleMesh& mesh, const Vec3& o, const Vec3& d) {
  double first = INFINITY, facing = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
               c = mesh.vertices[t[2]].cast<double>();
    const Vec3 e1 = b - a, e2 = c - a, p = d.cross(e2);
    const double det = e1.dot(p);
    if (det == 0) continue;
    const Vec3 s = o - a;
    const double u = s.dot(p) / det;
    const Vec3 q = s.cross(e1);
    const double v = d.dot(q) / det, along = e2.dot(q) / det;
    if (u < 0 || v < 0 || u + v > 1 || along < 0 || along >= first) continue;
    first = along;
    facing = e1.cross(e2).dot(d);
  }
  if (facing > 0) return kThickness;
  return facing < 0 && first < kThickness ? kThickness - first : 0;
}

TEST(TactileRaysTest, FineMeshReadsAsEveryTriangleWhileThePadCreepsAndJumps) {
  // A finely tessellated ball as a mesh body (thousands of triangles). The mesh path gathers each segment's
  // candidate triangles once and keeps them while the pad moves less than their slack: 400 poses, creeping
  // 0.02–0.3 mm and a few mrad per step with a jump every 40, from 4 mm clear of the foam to the ball 8 mm past the
  // pad's base (bases inside). Each pose is read by the caster that keeps its candidates, by a fresh caster, and
  // by every triangle (EveryTriangleDepth): the same elements, the kept and fresh readings bit for bit.
  const double r = 0.02;
  const collision::LocalMesh ball = collision::SphereMesh(r);
  auto mesh = std::make_shared<TriangleMesh>();
  for (const Vec3& v : ball.vertices) mesh->vertices.push_back(v.cast<float>());
  mesh->triangles = ball.triangles;
  ASSERT_GT(mesh->triangles.size(), 2000u);
  const SceneModel model = Scene({Body("ball", MeshGeometry(mesh))});
  const TactileRayCaster kept(model);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  Vec3 centre(0, 0, r);
  Quat turn = Quat::Identity();
  size_t touching = 0, buried = 0;
  for (int step = 0; step < 400; ++step) {
    if (step % 40 == 0) {
      centre = Vec3(0.01 * unit(random), 0.01 * unit(random), r - 0.002 + 0.006 * unit(random));
      turn = QuatFromRpy(unit(random), unit(random), unit(random));
    } else {
      centre += 3e-4 / std::sqrt(3.0) * Vec3(unit(random), unit(random), unit(random));
      centre.z() = std::clamp(centre.z(), r - 0.008, r + 0.004);
      turn = turn * QuatFromRpy(3e-3 * unit(random), 3e-3 * unit(random), 3e-3 * unit(random));
    }
    const Pose in_pad = At(centre.x(), centre.y(), centre.z(), turn);
    const TactileRayCaster fresh(model);
    const auto a = Cast(kept, Poses({in_pad})), b = Cast(fresh, Poses({in_pad}));
    ASSERT_EQ(a.size(), b.size()) << "step " << step;
    const Pose to_body = in_pad.Inverse();  // pad frame → ball frame
    size_t next = 0;
    for (uint32_t e = 0; e < kRows * kCols; ++e) {
      const PadElement& element = kept.Elements(0)[e];
      const double expected = EveryTriangleDepth(*mesh, to_body * element.position,
                                                 to_body.orientation * element.normal);
      if (next < a.size() && a[next].element == e) {
        EXPECT_EQ(a[next].depth, b[next].depth) << "step " << step << " element " << e;
        EXPECT_EQ(a[next].point, b[next].point) << "step " << step << " element " << e;
        EXPECT_NEAR(a[next].depth, expected, 1e-9) << "step " << step << " element " << e;
        buried += a[next].depth == kThickness;
        ++touching;
        ++next;
      } else {
        EXPECT_EQ(expected, 0) << "step " << step << " element " << e << ": missed";
      }
    }
  }
  EXPECT_GT(touching, 400u * 10) << "most poses must touch the pad";
  EXPECT_GT(buried, 400u) << "bases inside the ball must be read";
  // Kept while the pad creeps: far fewer gathers than poses, at least one per jump.
  EXPECT_GE(kept.candidate_gathers(), 10u);
  EXPECT_LT(kept.candidate_gathers(), 200u);
}

TEST(TactileRaysTest, NothingNearCastsNoRays) {
  const SceneModel model = Scene({Body("box", BoxGeometry(kBigBox))});
  const TactileRayCaster caster(model);
  EXPECT_TRUE(Cast(caster, Poses({BoxBottomAt(0.05)})).empty());
  EXPECT_EQ(caster.last_ray_count(), 0u);
  EXPECT_FALSE(Cast(caster, Poses({BoxBottomAt(2e-3)})).empty());  // the count resets per Cast
  EXPECT_GT(caster.last_ray_count(), 0u);
  EXPECT_TRUE(Cast(caster, Poses({BoxBottomAt(0.05)})).empty());
  EXPECT_EQ(caster.last_ray_count(), 0u);
}

TEST(TactileRaysTest, LinksOfTheSameRobotAreIgnored) {
  // The palm (robot "hand") pressed 1.5 mm into the pad: no hits, no rays; an object there is sensed.
  const SceneModel model = Scene({Body("box", BoxGeometry(kBigBox))});
  const TactileRayCaster caster(model);
  std::vector<Pose> poses = Poses({BoxBottomAt(0.05)}, kPadWorld * BoxBottomAt(2.5e-3));
  EXPECT_TRUE(Cast(caster, poses).empty());
  EXPECT_EQ(caster.last_ray_count(), 0u);
  poses[kFirstObject] = kPadWorld * BoxBottomAt(2.5e-3);
  ExpectFlatContact(caster, Cast(caster, poses), 2.5e-3, kFirstObject);
}

TEST(TactileRaysTest, ThePadsOwnBodyIsIgnoredWithoutARobot) {
  // A pad on a free object (no robot id) sunk 2 mm into that object's own box: nothing to sense, no rays.
  Geometry own = BoxGeometry(Vec3(0.06, 0.03, 0.007));
  own.origin = kPadOrigin * At(0, 0, -1.5e-3);
  SceneModel model = Model({Body("probe", own)});
  model.tactile_arrays.push_back(PadSpec());
  model.tactile_arrays[0].body_id = "probe";
  model.Reindex();
  const TactileRayCaster caster(model);
  EXPECT_TRUE(Cast(caster, {kLink}).empty());
  EXPECT_EQ(caster.last_ray_count(), 0u);
}

TEST(TactileRaysTest, BaseInsideABodyIsFullyCompressed) {
  const SceneModel model = Scene({Body("box", BoxGeometry(kBigBox))});
  const TactileRayCaster caster(model);
  // Exit within the segment (box from -17 mm to 3 mm) and beyond it (from -1 mm to 19 mm).
  for (double bottom : {-17e-3, -1e-3}) {
    const auto hits = Cast(caster, Poses({BoxBottomAt(bottom)}));
    ASSERT_EQ(hits.size(), kRows * kCols) << bottom;
    for (const PadHit& h : hits) {
      EXPECT_EQ(h.depth, kThickness);
      EXPECT_LT((h.point - kPadWorld * caster.Elements(0)[h.element].position).norm(), 1e-12);
    }
  }
}

TEST(TactileRaysTest, DeepestBodyWinsPerElement) {
  // Box A 1 mm in over the whole pad; box B 2 mm in over x > 0 (columns 7..13). Both body orders, so that
  // neither "first wins" nor "last wins" passes.
  const Pose a = BoxBottomAt(3e-3), b = At(0.05, 0, 2e-3 + 0.01);
  for (bool b_first : {false, true}) {
    const SceneModel model = Scene({Body("x", BoxGeometry(kBigBox)), Body("y", BoxGeometry(kBigBox))});
    const TactileRayCaster caster(model);
    const uint32_t body_a = b_first ? kFirstObject + 1 : kFirstObject, body_b = b_first ? kFirstObject : kFirstObject + 1;
    const auto hits = Cast(caster, Poses(b_first ? std::vector<Pose>{b, a} : std::vector<Pose>{a, b}));
    ASSERT_EQ(hits.size(), kRows * kCols);
    for (const PadHit& h : hits) {
      const bool under_b = caster.Elements(0)[h.element].col >= 7;
      EXPECT_EQ(h.body, under_b ? body_b : body_a) << h.element << " b_first " << b_first;
      EXPECT_NEAR(h.depth, under_b ? 2e-3 : 1e-3, kTol) << h.element;
    }
  }
}

TEST(TactileRaysTest, MovedCasterStillCasts) {
  const SceneModel model = Scene({Body("box", BoxGeometry(kBigBox))});
  TactileRayCaster first(model);
  TactileRayCaster second = std::move(first);
  ExpectFlatContact(second, Cast(second, Poses({BoxBottomAt(2.5e-3)})), 2.5e-3, kFirstObject);
  test_util::ExpectError([&] { Cast(second, {kLink}); }, ErrorCode::kInternal, {"1 poses for 3 bodies"});
}

TEST(TactileRaysTest, ElementTexelAgreesWithTheGrid) {
  TactileArraySpec pad;
  pad.rows = 14;
  pad.cols = 6;
  pad.pitch = 0.0034;
  pad.thickness = 0.004;
  for (unsigned s : {0u, 1u, 2u, 3u}) {
    pad.subdivision = s;
    const std::vector<PadElement> elements = MakePadElements(pad);
    for (uint32_t e = 0; e < elements.size(); ++e) {
      const auto [row, col] = ElementTexel(pad, e);
      ASSERT_EQ(row, elements[e].row) << "subdivision " << s << ", element " << e;
      ASSERT_EQ(col, elements[e].col) << "subdivision " << s << ", element " << e;
    }
  }
}

TEST(TactileRaysTest, FaceCentresAreTheTwoTriangleCentroidsOfEachCell) {
  // Two triangles per cell of the corner grid: centroids at 1/3 and 2/3 of the cell's diagonal box, normals +z,
  // both in the cell's texel; the same grid cast against a box reads the same depth everywhere.
  for (unsigned subdivision : {1u, 2u}) {
    TactileArraySpec pad = PadSpec(subdivision);
    pad.placement = PadElementPlacement::kFaceCentres;
    const std::vector<PadElement> elements = MakePadElements(pad);
    ASSERT_EQ(elements.size(), 2u * kRows * kCols * subdivision * subdivision);
    ASSERT_EQ(elements.size(), pad.ElementCount());
    const double cell = kPitch / subdivision;
    const uint32_t cols = kCols * subdivision;
    for (uint32_t i = 0; i < elements.size(); ++i) {
      const PadElement& e = elements[i];
      const uint32_t r = i / 2 / cols, c = i / 2 % cols;
      const double x0 = c * cell - kCols * kPitch / 2, y0 = r * cell - kRows * kPitch / 2;
      // Triangle (00, 01, 11) has its centroid at (2/3, 1/3) of the cell, triangle (00, 11, 10) at (1/3, 2/3).
      const double fx = i % 2 == 0 ? 2.0 / 3 : 1.0 / 3, fy = 1 - fx;
      EXPECT_NEAR(e.position.x(), x0 + fx * cell, 1e-12) << i;
      EXPECT_NEAR(e.position.y(), y0 + fy * cell, 1e-12) << i;
      EXPECT_LT((e.normal - Vec3::UnitZ()).norm(), 1e-12) << i;
      EXPECT_EQ(e.row, r / subdivision);
      EXPECT_EQ(e.col, c / subdivision);
      const auto [row, col] = ElementTexel(pad, i);
      EXPECT_EQ(row, e.row);
      EXPECT_EQ(col, e.col);
    }
    const SceneModel model = Scene({Body("box", BoxGeometry(kBigBox))}, pad);
    const TactileRayCaster caster(model);
    ExpectFlatContact(caster, Cast(caster, Poses({BoxBottomAt(2.5e-3)})), 2.5e-3, kFirstObject);
  }
}

TEST(TactileRaysTest, CurvedFingertipElementsLieOnTheCylinderAndSenseAlongItsRadius) {
  // The pad wrapped around an axis along y at radius R below its centre: every element on the circle
  // x² + (z + R)² = R² (face centroids on the chords just inside it), vertex elements at arc length x from the
  // top; normals along the radius through them.
  const double R = 0.02;
  for (PadElementPlacement placement : {PadElementPlacement::kVertices, PadElementPlacement::kFaceCentres}) {
    TactileArraySpec pad = PadSpec();
    pad.bend_radius_x = R;
    pad.placement = placement;
    const std::vector<PadElement> elements = MakePadElements(pad);
    const bool faces = placement == PadElementPlacement::kFaceCentres;
    for (uint32_t i = 0; i < elements.size(); ++i) {
      const PadElement& e = elements[i];
      const Vec3 centre(0, e.position.y(), -R);
      const Vec3 radial = e.position - centre;
      // Face centroids lie on the chord, inside the circle by at most R (1 − cos(half the cell angle)).
      const double sag = faces ? R * (1 - std::cos(kPitch / (2 * R))) : 1e-12;
      EXPECT_LE(radial.norm(), R + 1e-12) << i;
      EXPECT_GE(radial.norm(), R - sag - 1e-12) << i;
      // Off the radius by at most half a cell's angle (a face's own tilt); an interior vertex, whose faces lie
      // symmetrically about it, exactly on it.
      const double angle = std::acos(std::clamp(e.normal.dot(radial.normalized()), -1.0, 1.0));
      EXPECT_LT(angle, kPitch / (2 * R) + 1e-9) << i;
      if (!faces) {
        const uint32_t r = i / kCols, c = i % kCols;
        if (r > 0 && r + 1 < kRows && c > 0 && c + 1 < kCols) {
          EXPECT_LT(angle, 1e-7) << i;
        }
        const double arc = (c + 0.5) * kPitch - kCols * kPitch / 2;
        EXPECT_NEAR(std::atan2(radial.x(), radial.z()), arc / R, 1e-12) << i;
      }
    }
    // A box face pressed down onto the apex (plane z = h in the pad frame) is met by each element's segment at
    // t = (h − z) / n_z: depth thickness − t wherever that is positive.
    const double h = 2.5e-3;
    const SceneModel model = Scene({Body("box", BoxGeometry(kBigBox))}, pad);
    const TactileRayCaster caster(model);
    const std::vector<PadHit> hits = Cast(caster, Poses({BoxBottomAt(h)}));
    std::vector<double> depth(elements.size(), 0);
    for (const PadHit& hit : hits) depth[hit.element] = hit.depth;
    size_t touching = 0;
    for (uint32_t i = 0; i < elements.size(); ++i) {
      const double expected = kThickness - (h - elements[i].position.z()) / elements[i].normal.z();
      EXPECT_NEAR(depth[i], std::max(expected, 0.0), kTol) << i;
      touching += expected > kTol;
    }
    EXPECT_LT(touching, elements.size()) << "the edges fall away from a flat face";
    EXPECT_GT(touching, 0u);
  }
}

}  // namespace
}  // namespace graspsim
