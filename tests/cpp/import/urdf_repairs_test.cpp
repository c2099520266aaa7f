// ImportUrdf on the community's conventions (docs/import.md): zero-mass frame links, inertia from geometry per
// ImportOptions, PyBullet's plane and capsule, liberal numbers and limits, ball joints, names; each repair says so
// in a warning, and strict mode refuses instead. Expected values are closed forms (box m(b²+c²)/12).
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "import/robot_import.h"

namespace graspsim {
namespace {

constexpr double kTolerance = 1e-12;

std::string Inertial(const std::string& mass, const std::string& izz = "0.01") {
  return "<inertial><mass value=\"" + mass + "\"/><inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"" +
         izz + "\"/></inertial>";
}
const std::string kBox = "<collision><geometry><box size=\"0.1 0.2 0.3\"/></geometry></collision>";
const std::string kRevolute = "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>";

std::string Arm(const std::string& tip_body, const std::string& tip_joint = "fixed", const std::string& extra = "") {
  return "<robot name=\"arm\"><link name=\"base\">" + Inertial("1") + "</link><link name=\"tip\">" + tip_body +
         "</link><joint name=\"j\" type=\"" + tip_joint + "\"><parent link=\"base\"/><child link=\"tip\"/>"
         "<origin xyz=\"0 0 0.5\"/>" + (tip_joint == "fixed" ? "" : kRevolute) + "</joint>" + extra + "</robot>";
}

ImportOptions Strict() {
  ImportOptions options;
  options.strict = true;
  return options;
}
ImportOptions AtDensity(double density) {
  ImportOptions options;
  options.density = density;
  return options;
}
ImportOptions Inertia(InertiaSource source) {
  ImportOptions options;
  options.inertia = source;
  return options;
}

ImportedRobot Import(const std::string& urdf, ImportOptions options = {}) {
  return ImportUrdf(urdf, nullptr, options, Limits());
}

const BodySpec& Link(const ImportedRobot& robot, const std::string& name) {
  for (const BodySpec& link : robot.description.links) {
    if (link.id == name) return link;
  }
  throw std::runtime_error("no link " + name);
}

bool Warned(const ImportedRobot& robot, const std::string& element_part, const std::string& action_part) {
  for (const ImportWarning& w : robot.warnings) {
    if (w.element.find(element_part) != std::string::npos && w.action.find(action_part) != std::string::npos) return true;
  }
  return false;
}

void ExpectInvalid(const std::function<void()>& load, const std::vector<std::string>& parts) {
  try {
    load();
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    for (const std::string& part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(UrdfRepairsTest, ZeroMassFixedLinkIsAMasslessFrameOfItsParent) {
  const ImportedRobot robot = Import(Arm(Inertial("0")));
  EXPECT_EQ(Link(robot, "tip").inertial.mass, 0);
  EXPECT_EQ(robot.description.joints.at(0).origin.position, Vec3(0, 0, 0.5));  // the frame stays
  EXPECT_TRUE(Warned(robot, "link 'tip' inertial mass", "merged into its parent link 'base'"));
  ExpectInvalid([] { Import(Arm(Inertial("0")), Strict()); }, {"'tip'", "mass", ": 0 "});
}

TEST(UrdfRepairsTest, ZeroMassRootIsTheFixedBase) {
  const ImportedRobot robot = Import("<robot name=\"t\"><link name=\"table\">" + Inertial("0", "0") + kBox + "</link></robot>");
  EXPECT_EQ(Link(robot, "table").inertial.mass, 0);
  EXPECT_TRUE(Warned(robot, "'table'", "fixed base"));
}

TEST(UrdfRepairsTest, ZeroMassBehindAMovingJointTakesTheGeometryAtTheDensity) {
  const ImportedRobot robot = Import(Arm(Inertial("0") + kBox, "revolute"), AtDensity(500));
  const double m = 500 * 0.1 * 0.2 * 0.3;
  EXPECT_NEAR(Link(robot, "tip").inertial.mass, m, kTolerance);
  EXPECT_NEAR(Link(robot, "tip").inertial.inertia(0, 0), m / 12 * (0.04 + 0.09), kTolerance);
  EXPECT_TRUE(Warned(robot, "'tip'", "from the collision geometry at 500 kg/m^3"));
  ExpectInvalid([] { Import(Arm(Inertial("0") + kBox, "revolute"), Inertia(InertiaSource::kFromFile)); },
                {"'tip'", "mass", "moving joint 'j'"});
}

TEST(UrdfRepairsTest, UnphysicalTensorTakesTheGeometrysShapeAtTheFilesMass) {
  // izz = 0, as in every pybullet_data random_urdf: not positive definite.
  const ImportedRobot robot = Import(Arm(Inertial("2", "0") + kBox, "revolute"));
  const Mat3& I = Link(robot, "tip").inertial.inertia;
  EXPECT_EQ(Link(robot, "tip").inertial.mass, 2);
  EXPECT_NEAR(I(0, 0), 2.0 / 12 * (0.04 + 0.09), kTolerance);
  EXPECT_NEAR(I(1, 1), 2.0 / 12 * (0.01 + 0.09), kTolerance);
  EXPECT_NEAR(I(2, 2), 2.0 / 12 * (0.01 + 0.04), kTolerance);
  EXPECT_TRUE(Warned(robot, "principal moments", "scaled to the file's mass 2 kg"));
  ExpectInvalid([] { Import(Arm(Inertial("2", "0") + kBox, "revolute"), Inertia(InertiaSource::kFromFile)); },
                {"'tip'", "positive definite"});
}

TEST(UrdfRepairsTest, FromGeometryReplacesEveryInertialThatHasGeometry) {
  const ImportedRobot robot = Import(Arm(Inertial("7") + kBox, "revolute"), Inertia(InertiaSource::kFromGeometry));
  EXPECT_NEAR(Link(robot, "tip").inertial.mass, 1000 * 0.006, kTolerance);
  EXPECT_EQ(Link(robot, "base").inertial.mass, 1);  // no geometry: the file's
  EXPECT_TRUE(robot.warnings.empty());              // asked for, not a repair
}

TEST(UrdfRepairsTest, MissingInertialWithGeometryIsTakenFromIt) {
  const ImportedRobot robot = Import(Arm(kBox, "revolute"));
  EXPECT_NEAR(Link(robot, "tip").inertial.mass, 6, kTolerance);
  EXPECT_TRUE(Warned(robot, "'tip' inertial", "from the collision geometry"));
  ExpectInvalid([] { Import(Arm(kBox, "revolute"), Strict()); }, {"'tip'", "no <inertial>"});
}

TEST(UrdfRepairsTest, PlaneIsAThinBoxUnderItAndCapsuleACylinderWithTwoSpheres) {
  const ImportedRobot robot = Import(
      "<robot name=\"p\"><link name=\"ground\">" + Inertial("0") +
      "<collision><origin xyz=\"0 0 1\"/><geometry><plane normal=\"0 0 1\"/></geometry></collision>"
      "<collision><geometry><capsule radius=\"0.1\" length=\"0.4\"/></geometry></collision></link></robot>");
  const std::vector<Geometry>& shapes = Link(robot, "ground").collision;
  ASSERT_EQ(shapes.size(), 4u);
  EXPECT_EQ(shapes[0].kind, Geometry::Kind::kBox);
  EXPECT_NEAR(shapes[0].origin.position.z() + shapes[0].box_size.z() / 2, 1.0, kTolerance);  // top face on the plane
  EXPECT_EQ(shapes[1].kind, Geometry::Kind::kCylinder);
  EXPECT_NEAR(std::abs(shapes[2].origin.position.z() - shapes[3].origin.position.z()), 0.4, kTolerance);
  EXPECT_NEAR(shapes[2].origin.position.z() + shapes[3].origin.position.z(), 0, kTolerance);
  EXPECT_TRUE(Warned(robot, "<plane>", "box"));
  ExpectInvalid([&] {
    Import("<robot name=\"p\"><link name=\"g\"><collision><geometry><plane normal=\"0 0 1\"/></geometry></collision></link></robot>",
           Strict());
  }, {"urdf"});
}

TEST(UrdfRepairsTest, NumbersAndLimitsAsPyBulletReadsThem) {
  const ImportedRobot robot = Import(
      "<robot name=\"r\"><link name=\"a\">" + Inertial("1") + "</link><link name=\"b\">" + Inertial("1") +
      "</link><link name=\"c\">" + Inertial("1") + "</link>"
      "<joint name=\"ab\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/><origin xyz=\"0.07, 0 0 0\"/>"
      "<limit lower=\"1\" upper=\"-1\"/></joint>"
      "<joint name=\"bc\" type=\"revolute\"><parent link=\"b\"/><child link=\"c\"/>"
      "<limit lower=\"-1.57.\" upper=\"1.5\" effort=\"1\" velocity=\"1\"/></joint></robot>");
  const auto& joints = robot.description.joints;
  EXPECT_EQ(joints[0].origin.position, Vec3(0.07, 0, 0));
  EXPECT_EQ(joints[0].type, JointType::kContinuous);  // lower above upper: no limit
  EXPECT_EQ(joints[1].lower, -1.57);
  EXPECT_TRUE(Warned(robot, "xyz", "read as '0.07 0 0'"));
  EXPECT_TRUE(Warned(robot, "joint 'ab' limit", "unlimited"));
}

TEST(UrdfRepairsTest, LimitWithoutVelocityLoadsWithNothingElseToRepair) {
  const ImportedRobot robot = Import(
      "<robot name=\"r\"><link name=\"a\">" + Inertial("1") + "</link><link name=\"b\">" + Inertial("1") +
      "</link><joint name=\"ab\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>"
      "<limit lower=\"-1\" upper=\"1\" effort=\"1\"/></joint></robot>");
  EXPECT_EQ(robot.description.joints.at(0).upper, 1);
  EXPECT_EQ(robot.description.joints.at(0).velocity_limit, 0);  // none given
}

TEST(UrdfRepairsTest, BallJointIsThreeRevoluteJointsThroughMasslessLinks) {
  const ImportedRobot robot = Import(Arm(Inertial("1"), "spherical"));
  const auto& joints = robot.description.joints;
  ASSERT_EQ(joints.size(), 3u);
  EXPECT_EQ(joints[0].id, "j_x");
  EXPECT_EQ(joints[0].origin.position, Vec3(0, 0, 0.5));
  EXPECT_EQ(joints[2].axis, Vec3::UnitZ());
  EXPECT_EQ(joints[2].child_body, "tip");
  EXPECT_EQ(Link(robot, "tip__x").inertial.mass, 0);
  EXPECT_EQ(Link(robot, "tip").inertial.mass, 1);
}

TEST(UrdfRepairsTest, ChainNamesStayValidNamesForLongLinks) {
  const std::string tip(64, 't');
  std::string urdf = Arm(Inertial("1"), "spherical");
  for (size_t at; (at = urdf.find("\"tip\"")) != std::string::npos;) urdf.replace(at, 5, "\"" + tip + "\"");
  const ImportedRobot robot = Import(urdf);
  for (const BodySpec& link : robot.description.links) EXPECT_LE(link.id.size(), 64u) << link.id;
  EXPECT_EQ(robot.description.links.size(), 4u);  // base, two chain links, the tip: no two share a name
  EXPECT_EQ(robot.description.joints.back().child_body, tip);
}

TEST(UrdfRepairsTest, NamesAreMadeValidWithTheirReferences) {
  const ImportedRobot robot = Import(
      "<robot name=\"r\"><link name=\"my base\">" + Inertial("1") + "</link><link name=\"tip:1\">" + Inertial("1") +
      "</link><joint name=\"j 1\" type=\"fixed\"><parent link=\"my base\"/><child link=\"tip:1\"/></joint></robot>");
  EXPECT_EQ(robot.description.root_link, "my_base");
  EXPECT_EQ(robot.description.joints[0].child_body, "tip_1");
  EXPECT_EQ(robot.description.joints[0].id, "j_1");
  EXPECT_TRUE(Warned(robot, "link name", "renamed 'my_base'"));
}

TEST(UrdfRepairsTest, EveryMissingMeshIsNamedInOneError) {
  const auto mesh = [](const std::string& file) {
    return "<collision><geometry><mesh filename=\"" + file + "\"/></geometry></collision>";
  };
  ExpectInvalid([&] {
    Import("<robot name=\"r\"><link name=\"a\">" + Inertial("1") + mesh("package://p/meshes/a.stl") + mesh("b.obj") +
           "</link></robot>");
  }, {"2 mesh files", "'package://p/meshes/a.stl'", "'b.obj'"});
}

TEST(UrdfRepairsTest, TrailingNulBytesAreIgnored) {
  std::string text = Arm(Inertial("1"));
  text.push_back('\0');
  EXPECT_EQ(Import(text).description.links.size(), 2u);
  ExpectInvalid([&] { Import(text, Strict()); }, {"NUL"});
}

}  // namespace
}  // namespace graspsim
