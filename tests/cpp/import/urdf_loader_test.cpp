// LoadUrdf: a small arm whose poses, axes and inertias are known by hand, mesh lookup, the tactile extension,
// and one test per rejection rule asserting the code and that the message names the offending thing.
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "import/robot_import.h"
#include "world/loaders.h"

namespace graspsim {
namespace {

constexpr double kTolerance = 1e-12;
constexpr double kHalfPi = 1.5707963267948966;

std::string InertialXml(const std::string& mass = "1", const std::string& origin = "") {
  return "<inertial>" + origin + "<mass value=\"" + mass +
         "\"/><inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial>";
}

std::string Link(const std::string& name, const std::string& body = InertialXml()) {
  return "<link name=\"" + name + "\">" + body + "</link>";
}

std::string Joint(const std::string& name, const std::string& type, const std::string& parent,
                  const std::string& child, const std::string& body = "") {
  return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"" + parent + "\"/><child link=\"" +
         child + "\"/>" + body + "</joint>";
}

std::string Robot(const std::string& body) { return "<robot name=\"test\">" + body + "</robot>"; }

const std::string kLimit = "<limit lower=\"-1\" upper=\"1\" effort=\"10\" velocity=\"2\"/>";

// base → shoulder (revolute, yaw pi/2, unnormalised axis) → upper → elbow (continuous) → lower (frame only).
// upper's inertial frame is yawed by pi/2, so its tensor [[1, 0.1, 0], [0.1, 2, 0], [0, 0, 3]] appears in the
// body frame with x and y exchanged and the product of inertia negated: [[2, -0.1, 0], [-0.1, 1, 0], [0, 0, 3]].
const std::string kArm = Robot(
    Link("base", InertialXml("2") + "<collision><geometry><box size=\"0.1 0.2 0.3\"/></geometry></collision>"
                                 "<collision><origin xyz=\"0 0 0.2\"/><geometry><sphere radius=\"0.05\"/>"
                                 "</geometry></collision>") +
    Joint("elbow", "continuous", "upper", "lower", "<origin xyz=\"0.3 0 0\"/><axis xyz=\"1 1 0\"/>") +
    Link("upper",
         "<inertial><origin xyz=\"0.1 0 0\" rpy=\"0 0 1.5707963267948966\"/><mass value=\"1.5\"/>"
         "<inertia ixx=\"1\" ixy=\"0.1\" ixz=\"0\" iyy=\"2\" iyz=\"0\" izz=\"3\"/></inertial>"
         "<collision><geometry><cylinder radius=\"0.02\" length=\"0.3\"/></geometry></collision>") +
    Link("lower", "") +
    Joint("shoulder", "revolute", "base", "upper",
          "<origin xyz=\"0 0 0.5\" rpy=\"0 0 1.5707963267948966\"/><axis xyz=\"0 0 2\"/>" + kLimit));

// An 8-vertex, 12-triangle cube of edge 1 centred on the origin.
const std::string kCubeObj =
    "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv -0.5 0.5 -0.5\nv 0.5 0.5 -0.5\n"
    "v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv -0.5 0.5 0.5\nv 0.5 0.5 0.5\n"
    "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";

FileLookup Files(const std::map<std::string, std::string>& files) {
  return [files](const std::string& path) -> const std::string* {
    const auto it = files.find(path);
    return it == files.end() ? nullptr : &it->second;
  };
}

void ExpectRejected(const std::string& urdf, ErrorCode code, const std::vector<std::string>& fragments,
                    const FileLookup& files = nullptr) {
  try {
    LoadUrdf(urdf, files, Limits());
    ADD_FAILURE() << "accepted: " << urdf;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    for (const std::string& fragment : fragments) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << "'" << fragment << "' not in: " << e.what();
    }
  }
}

void ExpectInvalid(const std::string& urdf, const std::vector<std::string>& fragments) {
  ExpectRejected(urdf, ErrorCode::kInvalidArgument, fragments);
}

TEST(UrdfLoaderTest, ArmInTopologicalOrder) {
  const RobotDescription arm = LoadUrdf(kArm, nullptr, Limits());
  EXPECT_EQ(arm.name, "test");
  EXPECT_EQ(arm.root_link, "base");
  ASSERT_EQ(arm.links.size(), 3u);
  EXPECT_EQ(arm.links[0].id, "base");
  EXPECT_EQ(arm.links[1].id, "upper");
  EXPECT_EQ(arm.links[2].id, "lower");
  ASSERT_EQ(arm.joints.size(), 2u);
  EXPECT_EQ(arm.joints[0].id, "shoulder");
  EXPECT_EQ(arm.joints[1].id, "elbow");
  for (const BodySpec& link : arm.links) EXPECT_EQ(link.motion, BodyMotion::kArticulated);
}

TEST(UrdfLoaderTest, JointOriginAxisAndLimits) {
  const RobotDescription arm = LoadUrdf(kArm, nullptr, Limits());
  const JointSpec& shoulder = arm.joints[0];
  EXPECT_EQ(shoulder.type, JointType::kRevolute);
  EXPECT_EQ(shoulder.parent_body, "base");
  EXPECT_EQ(shoulder.child_body, "upper");
  EXPECT_TRUE(shoulder.origin.position.isApprox(Vec3(0, 0, 0.5), kTolerance));
  EXPECT_LT(shoulder.origin.orientation.angularDistance(QuatFromRpy(0, 0, kHalfPi)), kTolerance);
  EXPECT_TRUE((shoulder.origin.orientation * Vec3::UnitX()).isApprox(Vec3::UnitY(), kTolerance));
  EXPECT_TRUE(shoulder.axis.isApprox(Vec3::UnitZ(), kTolerance));  // given as (0, 0, 2)
  EXPECT_EQ(shoulder.lower, -1);
  EXPECT_EQ(shoulder.upper, 1);
  EXPECT_EQ(shoulder.effort_limit, 10);
  EXPECT_EQ(shoulder.velocity_limit, 2);

  const JointSpec& elbow = arm.joints[1];
  EXPECT_EQ(elbow.type, JointType::kContinuous);
  EXPECT_TRUE(elbow.axis.isApprox(Vec3(1, 1, 0) / std::sqrt(2.0), kTolerance));
  EXPECT_FALSE(elbow.mimic.has_value());
}

TEST(UrdfLoaderTest, GeneralOriginMatchesQuatFromRpy) {
  const RobotDescription robot = LoadUrdf(
      Robot(Link("a") + Link("b") + Joint("j", "fixed", "a", "b", "<origin xyz=\"1 2 3\" rpy=\"0.3 -0.2 0.7\"/>")),
      nullptr, Limits());
  EXPECT_LT(robot.joints[0].origin.orientation.angularDistance(QuatFromRpy(0.3, -0.2, 0.7)), kTolerance);
}

TEST(UrdfLoaderTest, InertiaRotatedIntoBodyFrame) {
  const RobotDescription arm = LoadUrdf(kArm, nullptr, Limits());
  const Inertial& upper = arm.links[1].inertial;
  EXPECT_EQ(upper.mass, 1.5);
  EXPECT_TRUE(upper.center_of_mass.isApprox(Vec3(0.1, 0, 0), kTolerance));
  Mat3 expected;
  expected << 2, -0.1, 0, -0.1, 1, 0, 0, 0, 3;
  EXPECT_LT((upper.inertia - expected).cwiseAbs().maxCoeff(), kTolerance) << upper.inertia;
}

TEST(UrdfLoaderTest, GeneralInertialRotation) {
  const std::string urdf = Robot(Link(
      "a", "<inertial><origin rpy=\"0.3 -0.2 0.7\"/><mass value=\"1\"/>"
           "<inertia ixx=\"0.5\" ixy=\"0.01\" ixz=\"-0.02\" iyy=\"0.6\" iyz=\"0.03\" izz=\"0.7\"/></inertial>"));
  Mat3 tensor;
  tensor << 0.5, 0.01, -0.02, 0.01, 0.6, 0.03, -0.02, 0.03, 0.7;
  const Mat3 rotation = QuatFromRpy(0.3, -0.2, 0.7).toRotationMatrix();
  const Mat3 expected = rotation * tensor * rotation.transpose();
  const Inertial inertial = LoadUrdf(urdf, nullptr, Limits()).links[0].inertial;
  EXPECT_LT((inertial.inertia - expected).cwiseAbs().maxCoeff(), kTolerance);
}

TEST(UrdfLoaderTest, CollisionGeometryAllElementsKept) {
  const RobotDescription arm = LoadUrdf(kArm, nullptr, Limits());
  const BodySpec& base = arm.links[0];
  ASSERT_EQ(base.collision.size(), 2u);
  EXPECT_EQ(base.collision[0].kind, Geometry::Kind::kBox);
  EXPECT_TRUE(base.collision[0].box_size.isApprox(Vec3(0.1, 0.2, 0.3), kTolerance));
  EXPECT_EQ(base.collision[1].kind, Geometry::Kind::kSphere);
  EXPECT_EQ(base.collision[1].radius, 0.05);
  EXPECT_TRUE(base.collision[1].origin.position.isApprox(Vec3(0, 0, 0.2), kTolerance));
  const Geometry& cylinder = arm.links[1].collision.at(0);
  EXPECT_EQ(cylinder.kind, Geometry::Kind::kCylinder);
  EXPECT_EQ(cylinder.radius, 0.02);
  EXPECT_EQ(cylinder.length, 0.3);
}

TEST(UrdfLoaderTest, FrameOnlyLinkGetsOneGram) {
  const RobotDescription arm = LoadUrdf(kArm, nullptr, Limits());  // a reference into the temporary dangled (ASan)
  const Inertial& lower = arm.links[2].inertial;
  EXPECT_EQ(lower.mass, 1e-3);
  EXPECT_GT(lower.inertia.diagonal().minCoeff(), 0);
}

TEST(UrdfLoaderTest, MeshFoundThroughPackageAndFilePrefixes) {
  const std::string urdf = Robot(
      Link("a", InertialXml() + "<collision><geometry><mesh filename=\"package://my_robot/meshes/cube.obj\" "
                             "scale=\"0.1 0.1 0.1\"/></geometry></collision>") +
      Link("b", InertialXml() + "<collision><geometry><mesh filename=\"file:///home/u/cube.obj\" "
                             "scale=\"0.1 0.1 0.1\"/></geometry></collision>") +
      Joint("j", "fixed", "a", "b"));
  // "package://my_robot/meshes/cube.obj" is found as "meshes/cube.obj"; "file:///home/u/cube.obj" is not an
  // uploaded path, but its basename is.
  const RobotDescription robot =
      LoadUrdf(urdf, Files({{"meshes/cube.obj", kCubeObj}, {"cube.obj", kCubeObj}}), Limits());
  const Geometry& a = robot.links[0].collision.at(0);
  EXPECT_EQ(a.kind, Geometry::Kind::kMesh);
  EXPECT_EQ(a.mesh_file, "meshes/cube.obj");
  ASSERT_NE(a.mesh, nullptr);
  EXPECT_EQ(a.mesh->TriangleCount(), 12u);
  Eigen::Vector3f min, max;
  MeshBounds(*a.mesh, &min, &max);
  EXPECT_NEAR(min.x(), -0.05, 1e-6);
  EXPECT_NEAR(max.z(), 0.05, 1e-6);
  const Geometry& b = robot.links[1].collision.at(0);
  EXPECT_EQ(b.mesh_file, "cube.obj");
  ASSERT_NE(b.mesh, nullptr);
  EXPECT_EQ(b.mesh->TriangleCount(), 12u);
}

TEST(UrdfLoaderTest, MeshUsedTwiceIsLoadedOnce) {
  const std::string collision =
      "<collision><geometry><mesh filename=\"package://p/cube.obj\"/></geometry></collision>";
  const std::string urdf = Robot(Link("a", InertialXml() + collision) + Link("b", InertialXml() + collision) +
                                 Joint("j", "fixed", "a", "b"));
  const RobotDescription robot = LoadUrdf(urdf, Files({{"cube.obj", kCubeObj}}), Limits());
  EXPECT_EQ(robot.links[0].collision[0].mesh, robot.links[1].collision[0].mesh);
}

TEST(UrdfLoaderTest, PrismaticMimicAndTactileArray) {
  const std::string urdf = Robot(
      Link("base") + Link("left") + Link("right") +
      Joint("slide", "prismatic", "base", "left", "<axis xyz=\"0 1 0\"/>" + kLimit) +
      Joint("follow", "prismatic", "base", "right",
            "<axis xyz=\"0 -1 0\"/>" + kLimit + "<mimic joint=\"slide\" multiplier=\"2\" offset=\"0.1\"/>") +
      "<tactile_array name=\"pad\" link=\"left\" rows=\"14\" cols=\"6\" pitch=\"0.0034\" thickness=\"0.004\">"
      "<origin xyz=\"0 0.005 0.03\" rpy=\"1.5707963267948966 0 0\"/></tactile_array>");
  const RobotDescription robot = LoadUrdf(urdf, nullptr, Limits());
  const JointSpec& follow = robot.joints.at(1);
  EXPECT_EQ(follow.type, JointType::kPrismatic);
  ASSERT_TRUE(follow.mimic.has_value());
  EXPECT_EQ(follow.mimic->joint_id, "slide");
  EXPECT_EQ(follow.mimic->multiplier, 2);
  EXPECT_EQ(follow.mimic->offset, 0.1);
  ASSERT_EQ(robot.tactile_arrays.size(), 1u);
  const TactileArraySpec& pad = robot.tactile_arrays[0];
  EXPECT_EQ(pad.id, "pad");
  EXPECT_EQ(pad.body_id, "left");
  EXPECT_EQ(pad.rows, 14u);
  EXPECT_EQ(pad.cols, 6u);
  EXPECT_EQ(pad.pitch, 0.0034);
  EXPECT_EQ(pad.thickness, 0.004);
  EXPECT_TRUE(pad.origin.position.isApprox(Vec3(0, 0.005, 0.03), kTolerance));
  EXPECT_TRUE((pad.origin.orientation * Vec3::UnitZ()).isApprox(-Vec3::UnitY(), kTolerance));
}

// ---- Rejections ---------------------------------------------------------------------------------------------

TEST(UrdfLoaderTest, RejectsMalformedXmlWithItsLine) {
  ExpectInvalid("<robot name=\"r\">\n  <link name=\"a\">\n</robot>", {"XML error", "line 3", "column"});
  ExpectInvalid("<robot name=\"r\"><link name=\"a\"/></robot><extra", {"XML error"});
  ExpectInvalid("", {"XML error"});
  ExpectInvalid("<model name=\"r\"/>", {"<robot>"});
}

TEST(UrdfLoaderTest, RejectsTextThatIsNotUtf8BeforeTinyXmlReadsPastItsEnd) {
  // The fuzz input that made TinyXML read past the string (tests/fuzz/regressions/urdf_tinyxml_read_past_end)
  // ends in "\xd6\xd6...": lead bytes of two-byte sequences without their continuation.
  ExpectInvalid("<robot name=\"r\"><link name=\"a\xd6\xd6\xd6\"/></robot>", {"urdf", "not UTF-8", "byte 29"});
  ExpectInvalid(std::string("<robot name=\"r\">\0</robot>", 24), {"NUL", "byte 16"});
  ExpectInvalid("<robot name=\"r\xe2\x82\"/>", {"not UTF-8", "byte 14"});  // cut short at the end
  // Well-formed multi-byte text passes the check (and fails later only for what it says).
  ExpectInvalid("<robot name=\"r\xc3\xa9\">\n  <link name=\"a\">\n</robot>", {"XML error", "line 3"});
}

TEST(UrdfLoaderTest, RejectsMissingParentLink) {
  ExpectInvalid(Robot(Link("a") + Joint("j", "fixed", "ghost", "a")), {"'j'", "'ghost'"});
}

TEST(UrdfLoaderTest, RejectsJointCycle) {
  // Every link is a child: no root at all.
  ExpectInvalid(Robot(Link("a") + Link("b") + Link("c") + Joint("ab", "fixed", "a", "b") +
                      Joint("bc", "fixed", "b", "c") + Joint("ca", "fixed", "c", "a")),
                {"cycle", "'ab'", "'bc'", "'ca'"});
  // A tree plus a cycle beside it.
  ExpectInvalid(Robot(Link("base") + Link("a") + Link("b") + Joint("ab", "fixed", "a", "b") +
                      Joint("ba", "fixed", "b", "a")),
                {"cycle", "'ab'", "'ba'"});
}

TEST(UrdfLoaderTest, RejectsTwoRootsAndTwoParents) {
  ExpectInvalid(Robot(Link("a") + Link("b")), {"root", "'a'", "'b'"});
  ExpectInvalid(Robot(Link("a") + Link("b") + Link("c") + Joint("ac", "fixed", "a", "c") +
                      Joint("bc", "fixed", "b", "c")),
                {"'c'", "'ac'", "'bc'"});
}

TEST(UrdfLoaderTest, RejectsUnknownMeshFile) {
  ExpectRejected(
      Robot(Link("a", InertialXml() + "<collision><geometry><mesh filename=\"package://p/meshes/gone.stl\"/>"
                                   "</geometry></collision>")),
      ErrorCode::kInvalidArgument, {"mesh file the model names was not uploaded: 'package://p/meshes/gone.stl'"},
      Files({{"other.stl", "x"}}));
}

TEST(UrdfLoaderTest, RejectsZeroAndNegativeMass) {
  ExpectInvalid(Robot(Link("heavy", InertialXml("0"))), {"'heavy'", "mass", ": 0 "});
  ExpectInvalid(Robot(Link("heavy", InertialXml("-1"))), {"'heavy'", "mass", "-1"});
}

TEST(UrdfLoaderTest, RejectsNonFiniteNumbers) {
  ExpectInvalid(Robot(Link("a") + Link("b") + Joint("j", "fixed", "a", "b", "<origin xyz=\"nan 0 0\"/>")),
                {"[j]", "nan"});
  ExpectInvalid(Robot(Link("a") + Link("b") + Joint("j", "fixed", "a", "b", "<origin rpy=\"0 inf 0\"/>")),
                {"[j]", "inf"});
  ExpectInvalid(Robot(Link("a", InertialXml("nan"))), {"[a]"});
}

TEST(UrdfLoaderTest, RejectsInertiaNotPositiveDefinite) {
  ExpectInvalid(Robot(Link("wobbly", "<inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" "
                                     "iyy=\"1\" iyz=\"0\" izz=\"-1\"/></inertial>")),
                {"'wobbly'", "positive definite"});
  ExpectInvalid(Robot(Link("flat", "<inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" "
                                   "iyy=\"1\" iyz=\"0\" izz=\"5\"/></inertial>")),
                {"'flat'", "triangle inequality"});
}

TEST(UrdfLoaderTest, RejectsCollisionWithoutInertial) {
  ExpectInvalid(Robot(Link("a", "<collision><geometry><sphere radius=\"0.1\"/></geometry></collision>")),
                {"'a'", "<inertial>"});
}

TEST(UrdfLoaderTest, RejectsPrismaticWithoutLimits) {
  ExpectInvalid(Robot(Link("a") + Link("b") + Joint("slide", "prismatic", "a", "b", "<axis xyz=\"1 0 0\"/>")),
                {"slide", "limits"});
}

TEST(UrdfLoaderTest, RejectsLowerAboveUpper) {
  ExpectInvalid(Robot(Link("a") + Link("b") +
                      Joint("bent", "revolute", "a", "b",
                            "<limit lower=\"0.5\" upper=\"0.2\" effort=\"1\" velocity=\"1\"/>")),
                {"'bent'", "0.5", "0.2"});
}

TEST(UrdfLoaderTest, RejectsZeroAxis) {
  ExpectInvalid(Robot(Link("a") + Link("b") + Joint("spin", "continuous", "a", "b", "<axis xyz=\"0 0 0\"/>")),
                {"'spin'", "axis", "zero length"});
}

TEST(UrdfLoaderTest, RejectsFloatingAndPlanarJoints) {
  ExpectInvalid(Robot(Link("a") + Link("b") + Joint("free", "floating", "a", "b")), {"'free'", "floating"});
  ExpectInvalid(Robot(Link("a") + Link("b") + Joint("flat", "planar", "a", "b", kLimit)), {"'flat'", "planar"});
}

TEST(UrdfLoaderTest, RejectsMimicOfMissingJoint) {
  ExpectInvalid(Robot(Link("a") + Link("b") +
                      Joint("copy", "continuous", "a", "b", "<mimic joint=\"ghost\" multiplier=\"1\"/>")),
                {"'copy'", "'ghost'", "does not exist"});
}

TEST(UrdfLoaderTest, RejectsTactileArrayOnMissingLink) {
  ExpectInvalid(Robot(Link("a") + "<tactile_array name=\"pad\" link=\"ghost\" rows=\"2\" cols=\"2\" "
                                  "pitch=\"0.003\" thickness=\"0.004\"/>"),
                {"'pad'", "'ghost'"});
}

TEST(UrdfLoaderTest, RejectsBadTactileArrayNumbers) {
  const auto pad = [](const std::string& rows, const std::string& pitch, const std::string& thickness) {
    return Robot(Link("a") + "<tactile_array name=\"pad\" link=\"a\" rows=\"" + rows + "\" cols=\"6\" pitch=\"" +
                 pitch + "\" thickness=\"" + thickness + "\"/>");
  };
  ExpectInvalid(pad("0", "0.003", "0.004"), {"'pad' rows", "'0'"});
  ExpectInvalid(pad("-3", "0.003", "0.004"), {"'pad' rows", "'-3'"});
  ExpectInvalid(pad("2.5", "0.003", "0.004"), {"'pad' rows", "'2.5'"});
  ExpectInvalid(pad("14", "0", "0.004"), {"'pad' pitch", "0"});
  ExpectInvalid(pad("14", "0.003", "-0.004"), {"'pad' thickness", "-0.004"});
  ExpectInvalid(pad("14", "nan", "0.004"), {"'pad' pitch", "nan"});
}

TEST(UrdfLoaderTest, TactileArraySensingMeshOptions) {
  const auto pad = [](const std::string& extra) {
    return Robot(Link("a") + "<tactile_array name=\"pad\" link=\"a\" rows=\"14\" cols=\"6\" pitch=\"0.0034\" "
                             "thickness=\"0.004\" " + extra + "/>");
  };
  const TactileArraySpec plain = LoadUrdf(pad(""), nullptr, Limits()).tactile_arrays.at(0);
  EXPECT_EQ(plain.subdivision, 1u);
  EXPECT_EQ(plain.placement, PadElementPlacement::kVertices);
  EXPECT_EQ(plain.bend_radius_x, 0);
  EXPECT_EQ(plain.bend_radius_y, 0);
  const TactileArraySpec curved =
      LoadUrdf(pad("subdivision=\"2\" elements=\"face_centres\" bend_radius=\"0.01 0\""), nullptr, Limits())
          .tactile_arrays.at(0);
  EXPECT_EQ(curved.subdivision, 2u);
  EXPECT_EQ(curved.placement, PadElementPlacement::kFaceCentres);
  EXPECT_EQ(curved.bend_radius_x, 0.01);
  EXPECT_EQ(curved.bend_radius_y, 0);
  EXPECT_EQ(curved.ElementCount(), 14u * 6 * 8);
  ExpectInvalid(pad("subdivision=\"0\""), {"'pad' subdivision", "'0'"});
  ExpectInvalid(pad("subdivision=\"17\""), {"'pad' subdivision", "'17'", "16"});
  ExpectInvalid(pad("elements=\"edges\""), {"'pad' elements", "'edges'", "face_centres"});
  ExpectInvalid(pad("bend_radius=\"0.01\""), {"'pad' bend_radius", "2 number"});
  // 6 × 3.4 mm = 20.4 mm wide: a radius below 20.4 / π = 6.49 mm would wrap more than a quarter turn each way.
  ExpectInvalid(pad("bend_radius=\"0.005 0\""), {"'pad' bend_radius", "0.005", "along x", "width / pi"});
  ExpectInvalid(pad("bend_radius=\"0 -1\""), {"'pad' bend_radius", "-1", "along y"});
}

TEST(UrdfLoaderTest, RejectsGeometryUrdfdomCouldNotParse) {
  // urdfdom logs the error but returns the model without the collision element: it must not be dropped silently.
  ExpectInvalid(Robot(Link("a", InertialXml() + "<collision><geometry><box size=\"1 1\"/></geometry></collision>")),
                {"[a]"});
}

}  // namespace
}  // namespace graspsim
