// ContactFinder against hand-computed answers: a 5 cm cube 1 mm into a 1 m table (samples 5 mm apart), a
// sphere 2 mm in, separated and culled pairs, mesh versus primitive, rotation, robots, determinism.
#include "collision/contact_finder.h"

#include <cmath>
#include <cstring>
#include <numbers>
#include <tuple>

#include <gtest/gtest.h>

#include "collision_fixtures.h"
#include "core/error.h"

namespace graspsim {
namespace {

using namespace collision_fixtures;

constexpr double kExact = 1e-12;  // m: only rounding separates these from the analytic answer
const Vec3 kCubeSize(0.05, 0.05, 0.05);

// Body 0: a static 1 x 1 x 0.05 m table whose top face is z = 0. Body 1: `top`.
SceneModel OnTable(const Geometry& top, const Geometry& table = BoxGeometry(Vec3(1, 1, 0.05))) {
  return Model({Body("table", table, BodyMotion::kStatic), Body("top", top)});
}

const Pose kTablePose = At(0, 0, -0.025);
// The cube's centre is off the table's 5 mm lattice by 1.25 mm, so no table sample lies on a cube face.
const Pose kCubeSunk = At(0.00125, 0.00125, 0.024);

std::vector<ContactPoint> Find(const ContactFinder& finder, const std::vector<Pose>& poses) {
  std::vector<ContactPoint> contacts;
  finder.Find(poses, &contacts);
  return contacts;
}

std::vector<ContactPoint> Between(const std::vector<ContactPoint>& all, uint32_t a, uint32_t b) {
  std::vector<ContactPoint> out;
  for (const ContactPoint& c : all) {
    if (c.body_a == a && c.body_b == b) out.push_back(c);
  }
  return out;
}

void ExpectSame(const std::vector<ContactPoint>& x, const std::vector<ContactPoint>& y, double depth_tolerance) {
  ASSERT_EQ(x.size(), y.size());
  for (size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(x[i].body_a, y[i].body_a);
    EXPECT_EQ(x[i].body_b, y[i].body_b);
    EXPECT_EQ(x[i].feature, y[i].feature);
    EXPECT_LT((x[i].point - y[i].point).norm(), kExact);
    EXPECT_LT((x[i].normal - y[i].normal).norm(), 1e-9);
    EXPECT_NEAR(x[i].depth, y[i].depth, depth_tolerance);
  }
}

TEST(ContactFinder, BoxSamplesAreTheSurfaceLattice) {
  const SceneModel model = OnTable(BoxGeometry(kCubeSize));
  const ContactFinder finder(model);
  // 10 intervals per edge: 11^3 lattice points minus the 9^3 inside.
  EXPECT_EQ(finder.Samples(1).size(), 11u * 11 * 11 - 9 * 9 * 9);
  for (const Vec3& s : finder.Samples(1)) EXPECT_NEAR(s.cwiseAbs().maxCoeff(), 0.025, kExact);
}

TEST(ContactFinder, CubeOneMillimetreIntoTable) {
  const SceneModel model = OnTable(BoxGeometry(kCubeSize));
  const ContactFinder finder(model);
  const auto contacts = Find(finder, {kTablePose, kCubeSunk});

  // The cube's bottom face: 11 x 11 samples, each 1 mm deep, pushed up out of the table.
  const auto cube_in_table = Between(contacts, 1, 0);
  ASSERT_EQ(cube_in_table.size(), 121u);
  for (const ContactPoint& c : cube_in_table) {
    EXPECT_NEAR(c.depth, 1e-3, kExact);
    EXPECT_NEAR(c.point.z(), -1e-3, kExact);
    EXPECT_EQ(c.normal, Vec3::UnitZ());
  }
  // The table's top-face samples under the cube: 10 x 10 lattice points, 1 mm from the cube's bottom face.
  const auto table_in_cube = Between(contacts, 0, 1);
  ASSERT_EQ(table_in_cube.size(), 100u);
  for (const ContactPoint& c : table_in_cube) {
    EXPECT_NEAR(c.depth, 1e-3, kExact);
    EXPECT_EQ(c.normal, -Vec3::UnitZ());
  }
  EXPECT_EQ(contacts.size(), 221u);
}

TEST(ContactFinder, OrderIsBodyABodyBFeature) {
  const SceneModel model = OnTable(BoxGeometry(kCubeSize));
  const ContactFinder finder(model);
  const auto contacts = Find(finder, {kTablePose, kCubeSunk});
  ASSERT_FALSE(contacts.empty());
  for (size_t i = 1; i < contacts.size(); ++i) {
    const auto& p = contacts[i - 1];
    const auto& q = contacts[i];
    EXPECT_LT(std::tie(p.body_a, p.body_b, p.feature), std::tie(q.body_a, q.body_b, q.feature));
  }
}

// A sphere on a box touches in one point: one exact support contact at the pole (not a patch of samples, on
// neither side), so that it rolls as a sphere (issue 21).
TEST(ContactFinder, SphereTwoMillimetresIntoTable) {
  const double r = 0.025;
  const SceneModel model = OnTable(SphereGeometry(r));
  const ContactFinder finder(model);
  const auto contacts = Find(finder, {kTablePose, At(0.0013, -0.0007, r - 2e-3)});
  const auto sphere_in_table = Between(contacts, 1, 0);
  ASSERT_EQ(sphere_in_table.size(), 1u);
  const ContactPoint& c = sphere_in_table[0];
  EXPECT_EQ(c.normal, Vec3::UnitZ());
  EXPECT_NEAR(c.depth, 2e-3, kExact);
  EXPECT_LT((c.point - Vec3(0.0013, -0.0007, -2e-3)).norm(), kExact);
  EXPECT_EQ(c.feature, 0xffff0000u) << "geometry 0 of the sphere, support against the table's geometry 0";
  EXPECT_TRUE(Between(contacts, 0, 1).empty()) << "the table's samples do not touch the sphere as well";
  // Tilted and turned, the sphere still touches at its lowest point, as deep as the centre is below r.
  const Quat turn(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  const auto turned = Between(Find(finder, {kTablePose, At(0.01, 0.02, r - 1e-3, turn)}), 1, 0);
  ASSERT_EQ(turned.size(), 1u);
  EXPECT_NEAR(turned[0].depth, 1e-3, kExact);
  EXPECT_LT((turned[0].point - Vec3(0.01, 0.02, -1e-3)).norm(), kExact);
  // Off the table's edge, the contact is at the edge, along the line from it to the centre.
  const double half = model.bodies[0].collision[0].box_size.x() / 2;
  const Vec3 centre(half + 0.01, 0, 0.005);  // beyond the top edge, 1.1 cm from it
  const auto edge = Between(Find(finder, {kTablePose, At(centre.x(), centre.y(), centre.z())}), 1, 0);
  const double distance = std::hypot(0.01, 0.005);
  ASSERT_EQ(edge.size(), 1u);
  EXPECT_NEAR(edge[0].depth, r - distance, kExact);
  EXPECT_LT((edge[0].normal - Vec3(0.01, 0, 0.005) / distance).norm(), 1e-12);
  EXPECT_LT((edge[0].point - (centre - r * edge[0].normal)).norm(), kExact);
}

TEST(ContactFinder, CylinderCapOneMillimetreIntoTable) {
  const SceneModel model = OnTable(CylinderGeometry(0.02, 0.06));
  const ContactFinder finder(model);
  const auto contacts = Between(Find(finder, {kTablePose, At(0.00125, 0.00125, 0.029)}), 1, 0);
  size_t cap = 0;
  for (const Vec3& s : finder.Samples(1)) cap += std::abs(s.z() + 0.03) < kExact;
  EXPECT_GT(cap, 10u);
  ASSERT_EQ(contacts.size(), cap);
  for (const ContactPoint& c : contacts) {
    EXPECT_NEAR(c.depth, 1e-3, kExact);
    EXPECT_EQ(c.normal, Vec3::UnitZ());
  }
}

TEST(ContactFinder, SeparatedBodiesHaveNoContacts) {
  const SceneModel model = OnTable(BoxGeometry(kCubeSize));
  const ContactFinder finder(model);
  EXPECT_TRUE(Find(finder, {kTablePose, At(0, 0, 0.030)}).empty());  // 5 mm above
  EXPECT_TRUE(Find(finder, {kTablePose, At(0, 0, 0.025)}).empty());  // touching: depth 0 is no contact
  EXPECT_TRUE(Find(finder, {kTablePose, At(100, 0, 0)}).empty());    // boxes apart: culled
}

TEST(ContactFinder, MarginReportsNearSamplesWithNegativeDepth) {
  const SceneModel model = OnTable(BoxGeometry(kCubeSize));
  const ContactFinder finder(model, {0.005, 0.008});
  const auto contacts = Between(Find(finder, {kTablePose, At(0.00125, 0.00125, 0.030)}), 1, 0);
  // The bottom face is 5 mm above the table, within the 8 mm margin; the next lattice row up is 10 mm above.
  ASSERT_EQ(contacts.size(), 121u);
  for (const ContactPoint& c : contacts) {
    EXPECT_NEAR(c.depth, -5e-3, kExact);
    EXPECT_LT((c.normal - Vec3::UnitZ()).norm(), kExact);
  }
}

TEST(ContactFinder, RejectsSpacingThatIsNotPositive) {
  const SceneModel model = OnTable(BoxGeometry(kCubeSize));
  for (double spacing : {0.0, -1.0, std::nan("")}) {
    EXPECT_THROW(ContactFinder(model, {spacing, 0}), Error) << spacing;
  }
}

TEST(ContactFinder, StaticPairsAndLinksOfOneRobotNeverCollide) {
  SceneModel statics = Model({Body("a", BoxGeometry(kCubeSize), BodyMotion::kStatic),
                              Body("b", BoxGeometry(kCubeSize), BodyMotion::kStatic)});
  EXPECT_TRUE(Find(ContactFinder(statics), {At(0, 0, 0), At(0.01, 0, 0)}).empty());

  BodySpec left = Body("r/left", BoxGeometry(kCubeSize), BodyMotion::kArticulated);
  BodySpec right = Body("r/right", BoxGeometry(kCubeSize), BodyMotion::kArticulated);
  left.robot_id = right.robot_id = "r";
  EXPECT_TRUE(Find(ContactFinder(Model({left, right})), {At(0, 0, 0), At(0.01, 0, 0)}).empty());
  right.robot_id = "other";  // a second robot's link does collide
  EXPECT_FALSE(Find(ContactFinder(Model({left, right})), {At(0, 0, 0), At(0.01, 0, 0)}).empty());
}

TEST(ContactFinder, MeshCubeMatchesBoxPrimitive) {
  const SceneModel boxes_model = OnTable(BoxGeometry(kCubeSize));
  const ContactFinder boxes(boxes_model);
  const auto expected = Find(boxes, {kTablePose, kCubeSunk});

  // A mesh cube as body_b: the table's samples find the same depths and normals as in the box.
  const SceneModel mesh_cube_model = OnTable(MeshGeometry(BoxMesh(kCubeSize)));
  const ContactFinder mesh_cube(mesh_cube_model);
  const auto with_mesh_cube = Find(mesh_cube, {kTablePose, kCubeSunk});
  ExpectSame(Between(with_mesh_cube, 0, 1), Between(expected, 0, 1), 1e-6);
  // Its own samples are its 8 vertices: the 4 bottom corners are 1 mm into the table.
  EXPECT_EQ(mesh_cube.Samples(1).size(), 8u);
  const auto corners = Between(with_mesh_cube, 1, 0);
  ASSERT_EQ(corners.size(), 4u);
  for (const ContactPoint& c : corners) {
    EXPECT_NEAR(c.depth, 1e-3, 1e-6);
    EXPECT_EQ(c.normal, Vec3::UnitZ());
  }

  // A mesh table as body_b: the cube's 121 bottom samples, as against the box table.
  const SceneModel mesh_table_model = OnTable(BoxGeometry(kCubeSize), MeshGeometry(BoxMesh(Vec3(1, 1, 0.05))));
  const ContactFinder mesh_table(mesh_table_model);
  ExpectSame(Between(Find(mesh_table, {kTablePose, kCubeSunk}), 1, 0), Between(expected, 1, 0), 1e-6);
}

// A cylinder lying on a box touches along its lowest line: the two ends of that line (clipped to the box's face)
// are its contacts, exact, and neither its side samples nor the box's samples inside it count (issue 21).
TEST(ContactFinder, CylinderOnItsSideTouchesAlongALine) {
  const double r = 0.02, length = 0.06;
  const SceneModel model = OnTable(CylinderGeometry(r, length));
  const ContactFinder finder(model);
  const Quat lying(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX()));  // axis along y
  const Quat rolled = lying * Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));  // turned about its own axis
  for (const Quat& q : {lying, rolled}) {
    const auto contacts = Find(finder, {kTablePose, At(0.1, 0.2, r - 1e-3, q)});
    const auto cylinder_in_table = Between(contacts, 1, 0);
    ASSERT_EQ(cylinder_in_table.size(), 2u);
    for (const ContactPoint& c : cylinder_in_table) {
      EXPECT_NEAR(c.depth, 1e-3, kExact);
      EXPECT_EQ(c.normal, Vec3::UnitZ());
      EXPECT_NEAR(c.point.x(), 0.1, kExact);
      EXPECT_NEAR(c.point.z(), -1e-3, kExact);
      EXPECT_NEAR(std::abs(c.point.y() - 0.2), length / 2, kExact);
    }
    EXPECT_TRUE(Between(contacts, 0, 1).empty());
  }
  // Across the table's edge (x = 0.5), half over it: the line is cut where it leaves the top.
  const Quat across(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitY()));  // axis along x
  const auto over_edge = Between(Find(finder, {kTablePose, At(0.5, 0, r - 1e-3, across)}), 1, 0);
  ASSERT_EQ(over_edge.size(), 2u);
  EXPECT_NEAR(std::min(over_edge[0].point.x(), over_edge[1].point.x()), 0.5 - length / 2, kExact);
  EXPECT_NEAR(std::max(over_edge[0].point.x(), over_edge[1].point.x()), 0.5, kExact);
  // Tilted 30° onto one cap's rim: one contact, at the rim's lowest point.
  const Quat tilted(Eigen::AngleAxisd(std::numbers::pi / 6, Vec3::UnitX()));
  const double low = -(length / 2) * std::cos(std::numbers::pi / 6) - r * std::sin(std::numbers::pi / 6);
  const auto on_rim = Between(Find(finder, {kTablePose, At(0, 0, -low - 1e-3, tilted)}), 1, 0);
  ASSERT_EQ(on_rim.size(), 1u);
  EXPECT_NEAR(on_rim[0].depth, 1e-3, kExact);
}

TEST(ContactFinder, MeshSphereAgreesWithSphereWithinFacetError) {
  // 2 * 64 * 31 triangles: the chord sag r (1 - cos(pi / 32)) bounds how far the facets sit inside the sphere.
  // The table's samples inside the mesh sphere are as deep, and pushed along the same normals, as the exact
  // sphere's signed distance says (a primitive sphere itself meets the table in one support contact instead).
  const double r = 0.025, sag = r * (1 - std::cos(std::numbers::pi / 32));
  const SceneModel mesh_model = OnTable(MeshGeometry(SphereMesh(r, 64, 32)));
  const ContactFinder mesh(mesh_model);
  const Vec3 centre(0, 0, r - 2e-3);
  const auto faceted = Between(Find(mesh, {kTablePose, At(centre.x(), centre.y(), centre.z())}), 0, 1);
  ASSERT_EQ(faceted.size(), 9u);  // the 3 x 3 lattice points within sqrt(r^2 - 23 mm^2) = 9.8 mm of the axis
  for (const ContactPoint& c : faceted) {
    EXPECT_NEAR(c.depth, r - (c.point - centre).norm(), sag);
    EXPECT_GT(c.normal.dot((c.point - centre).normalized()), std::cos(std::numbers::pi / 16));
  }
}

TEST(ContactFinder, RotatedCubeOnTable) {
  const SceneModel model = OnTable(BoxGeometry(kCubeSize));
  const ContactFinder finder(model);
  const Quat yaw(Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()));
  const Pose cube = At(0.00125, 0.00125, 0.024, yaw);
  const auto contacts = Find(finder, {kTablePose, cube});
  const auto cube_in_table = Between(contacts, 1, 0);
  ASSERT_EQ(cube_in_table.size(), 121u);
  for (const ContactPoint& c : cube_in_table) {
    EXPECT_NEAR(c.depth, 1e-3, kExact);
    EXPECT_LT((c.normal - Vec3::UnitZ()).norm(), kExact);
  }
  // Table samples: exactly those strictly inside the turned cube, each as deep as its nearest cube face, pressing
  // along the normal of the cube's bottom (the face that faces the table top) even where a side face is nearer.
  const Pose table_to_cube = cube.Inverse() * kTablePose;
  size_t inside = 0, nearer_a_side = 0;
  for (const Vec3& s : finder.Samples(0)) {
    const Vec3 p = table_to_cube * s;
    const bool in = (p.cwiseAbs().array() < 0.025).all();
    inside += in;
    nearer_a_side += in && (Vec3::Constant(0.025) - p.cwiseAbs()).head<2>().minCoeff() < p.z() + 0.025;
  }
  EXPECT_GT(nearer_a_side, 0u);  // the case the rule is for occurs here
  const auto table_in_cube = Between(contacts, 0, 1);
  EXPECT_EQ(table_in_cube.size(), inside);
  for (const ContactPoint& c : table_in_cube) {
    const Vec3 p = cube.Inverse() * c.point;
    EXPECT_NEAR(c.depth, (Vec3::Constant(0.025) - p.cwiseAbs()).minCoeff(), kExact);
    EXPECT_LT((c.normal + Vec3::UnitZ()).norm(), kExact);
  }
}

TEST(ContactFinder, DeepestGeometryOfABodyWins) {
  // The table body has a second slab whose top is 0.5 mm higher: the cube's samples are 1.5 mm into it.
  BodySpec table = Body("table", BoxGeometry(Vec3(1, 1, 0.05)), BodyMotion::kStatic);
  Geometry slab = BoxGeometry(Vec3(0.2, 0.2, 0.05));
  slab.origin.position = Vec3(0, 0, 0.0005);
  table.collision.push_back(slab);
  const SceneModel model = Model({table, Body("cube", BoxGeometry(kCubeSize))});
  const ContactFinder finder(model);
  const auto contacts = Between(Find(finder, {kTablePose, kCubeSunk}), 1, 0);
  ASSERT_EQ(contacts.size(), 121u);
  for (const ContactPoint& c : contacts) EXPECT_NEAR(c.depth, 1.5e-3, kExact);
}

TEST(ContactFinder, SameInputSameOutputBitForBit) {
  BodySpec pile = Body("pile", MeshGeometry(SphereMesh(0.03, 24, 12)));
  pile.collision.push_back(CylinderGeometry(0.01, 0.08));
  const SceneModel model = Model({Body("table", BoxGeometry(Vec3(1, 1, 0.05)), BodyMotion::kStatic),
                                  Body("cube", BoxGeometry(kCubeSize)), pile, Body("ball", SphereGeometry(0.02))});
  const Quat tilt(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  const std::vector<Pose> poses{kTablePose, At(0.01, 0.02, 0.02, tilt), At(0.04, 0.0, 0.025), At(-0.02, 0.03, 0.019)};
  const ContactFinder first(model), second(model);
  const auto a = Find(first, poses), b = Find(first, poses), c = Find(second, poses);
  ASSERT_GT(a.size(), 100u);
  for (const auto* other : {&b, &c}) {
    ASSERT_EQ(a.size(), other->size());
    for (size_t i = 0; i < a.size(); ++i) {
      const ContactPoint& x = a[i];
      const ContactPoint& y = (*other)[i];
      EXPECT_TRUE(x.body_a == y.body_a && x.body_b == y.body_b && x.feature == y.feature);
      EXPECT_EQ(std::memcmp(x.point.data(), y.point.data(), sizeof(double) * 3), 0);
      EXPECT_EQ(std::memcmp(x.normal.data(), y.normal.data(), sizeof(double) * 3), 0);
      EXPECT_EQ(std::memcmp(&x.depth, &y.depth, sizeof(double)), 0);
    }
  }
}

}  // namespace
}  // namespace graspsim
