// ImportMjcf: an MJCF arm and its hand-written URDF twin (joint anchors off the body origin, Euler angles in
// degrees, a capsule, default classes) give the same forward kinematics and mass; ball and free joints; mimic
// joints from <equality>; and one test per rejection asserting the message names the element and the value.
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "import/mjcf_geometry.h"
#include "import/robot_import.h"
#include "world/state.h"

namespace graspsim {
namespace {

constexpr double kTolerance = 1e-12;
constexpr double kDeg = M_PI / 180;

FileLookup Files(const std::map<std::string, std::string>& files) {
  return [files](const std::string& path) -> const std::string* {
    const auto it = files.find(path);
    return it == files.end() ? nullptr : &it->second;
  };
}

ImportedRobot Mjcf(const std::string& text, const FileLookup& files = nullptr, ImportOptions options = {}) {
  return ImportMjcf(text, files, options, Limits());
}

// World pose of every link, from the joints (topological order) and JointMotion.
std::map<std::string, Pose> LinkPoses(const RobotDescription& robot, const std::map<std::string, double>& q) {
  std::map<std::string, Pose> poses{{robot.root_link, Pose{}}};
  for (const JointSpec& joint : robot.joints) {
    double value = q.count(joint.id) != 0 ? q.at(joint.id) : 0.0;
    if (joint.mimic) value = joint.mimic->multiplier * q.at(joint.mimic->joint_id) + joint.mimic->offset;
    poses[joint.child_body] = poses.at(joint.parent_body) * joint.origin * JointMotion(joint, value);
  }
  return poses;
}

const BodySpec& LinkOf(const RobotDescription& robot, const std::string& id) {
  for (const BodySpec& link : robot.links) {
    if (link.id == id) return link;
  }
  throw std::runtime_error("no link " + id);
}

const JointSpec& JointOf(const RobotDescription& robot, const std::string& id) {
  for (const JointSpec& joint : robot.joints) {
    if (joint.id == id) return joint;
  }
  throw std::runtime_error("no joint " + id);
}

double TotalMass(const RobotDescription& robot) {
  double mass = 0;
  for (const BodySpec& link : robot.links) mass += link.inertial.mass;
  return mass;
}

std::string Num(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

std::string Rpy(const Quat& q) {
  const Vec3 ypr = q.toRotationMatrix().eulerAngles(2, 1, 0);  // R = Rz(y) Ry(p) Rx(r)
  return Num(ypr[2]) + " " + Num(ypr[1]) + " " + Num(ypr[0]);
}

std::string Origin(const Vec3& p, const Quat& q) {
  return "<origin xyz=\"" + Num(p.x()) + " " + Num(p.y()) + " " + Num(p.z()) + "\" rpy=\"" + Rpy(q) + "\"/>";
}

// The arm: world (a floor box) → base (hinge "yaw" about z, continuous; explicit inertial) → upper (class limb:
// hinge "shoulder" about y, anchored 5 cm above the body origin, ±90°; a capsule by fromto, mass from the geoms at
// density 500) → lower (slide "elbow" along x anchored 2 cm off, ±0.1 m; a capsule and a box; density 500).
const std::string kArmMjcf = R"(
<mujoco model="arm">
  <compiler angle="degree" inertiafromgeom="auto"/>
  <default>
    <geom density="500"/>
    <default class="limb">
      <geom type="capsule" size="0.03"/>
      <joint axis="0 1 0" range="-90 90" damping="1"/>
    </default>
  </default>
  <worldbody>
    <geom name="floor" type="box" size="0.5 0.5 0.01" pos="0 0 -0.01"/>
    <body name="base" pos="0 0 0.1" euler="0 0 30">
      <inertial pos="0 0 0.05" mass="2" diaginertia="0.01 0.01 0.02"/>
      <geom type="cylinder" size="0.05 0.05"/>
      <joint name="yaw" axis="0 0 1"/>
      <body name="upper" pos="0 0 0.1" euler="10 20 30" childclass="limb">
        <joint name="shoulder" pos="0 0 0.05"/>
        <geom fromto="0 0 0 0.3 0 0"/>
        <body name="lower" pos="0.3 0 0" quat="0.9 0.1 0.2 0.3">
          <joint name="elbow" type="slide" axis="1 0 0" range="-0.1 0.1" pos="0.02 0 0"/>
          <geom fromto="0 0 0 0 0 0.25" size="0.02"/>
          <geom type="box" size="0.02 0.03 0.04" pos="0 0 0.25" euler="0 45 0"/>
          <site name="tip" pos="0 0 0.3"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="shoulder" gear="2" ctrlrange="-5 5"/></actuator>
</mujoco>)";

double CapsuleMass(double r, double half_length, double density) {
  return density * (M_PI * r * r * 2 * half_length + 4.0 / 3.0 * M_PI * r * r * r);
}

// The URDF twin, written from the same numbers by hand: each MJCF joint's anchor is a link ("<body>_anchor")
// holding the body's geometry and inertial, and the MJCF body frame a massless child fixed at -anchor.
std::string ArmUrdf() {
  const Quat upper_q = Quat(Eigen::AngleAxisd(10 * kDeg, Vec3::UnitX()) * Eigen::AngleAxisd(20 * kDeg, Vec3::UnitY()) *
                            Eigen::AngleAxisd(30 * kDeg, Vec3::UnitZ()));
  const Quat lower_q = Quat(0.9, 0.1, 0.2, 0.3).normalized();
  const Quat along_x(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()));  // capsule fromto along +x: z onto x
  const double upper_mass = CapsuleMass(0.03, 0.15, 500);
  const double lower_mass = CapsuleMass(0.02, 0.125, 500) + 500 * 0.04 * 0.06 * 0.08;
  const std::string inertia = "<inertia ixx=\"0.001\" ixy=\"0\" ixz=\"0\" iyy=\"0.001\" iyz=\"0\" izz=\"0.001\"/>";
  const auto capsule = [](const Vec3& centre, const Quat& q, double r, double h) {
    std::string out = "<collision>" + Origin(centre, q) + "<geometry><cylinder radius=\"" + Num(r) + "\" length=\"" +
                      Num(2 * h) + "\"/></geometry></collision>";
    for (double s : {1.0, -1.0}) {
      out += "<collision>" + Origin(centre + q * Vec3(0, 0, s * h), Quat::Identity()) +
             "<geometry><sphere radius=\"" + Num(r) + "\"/></geometry></collision>";
    }
    return out;
  };
  return "<robot name=\"arm\">"
         "<link name=\"world\"><collision>" + Origin(Vec3(0, 0, -0.01), Quat::Identity()) +
         "<geometry><box size=\"1 1 0.02\"/></geometry></collision></link>"
         "<link name=\"base\"><inertial>" + Origin(Vec3(0, 0, 0.05), Quat::Identity()) +
         "<mass value=\"2\"/><inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.02\"/></inertial>"
         "<collision><geometry><cylinder radius=\"0.05\" length=\"0.1\"/></geometry></collision></link>"
         "<joint name=\"yaw\" type=\"continuous\"><parent link=\"world\"/><child link=\"base\"/>" +
         Origin(Vec3(0, 0, 0.1), Quat(Eigen::AngleAxisd(30 * kDeg, Vec3::UnitZ()))) + "<axis xyz=\"0 0 1\"/></joint>"
         "<link name=\"upper_anchor\"><inertial><mass value=\"" + Num(upper_mass) + "\"/>" + inertia + "</inertial>" +
         capsule(Vec3(0.15, 0, -0.05), along_x, 0.03, 0.15) + "</link>"
         "<joint name=\"shoulder\" type=\"revolute\"><parent link=\"base\"/><child link=\"upper_anchor\"/>" +
         Origin(Vec3(0, 0, 0.1) + upper_q * Vec3(0, 0, 0.05), upper_q) +
         "<axis xyz=\"0 1 0\"/><limit lower=\"" + Num(-M_PI / 2) + "\" upper=\"" + Num(M_PI / 2) +
         "\" effort=\"10\" velocity=\"1\"/></joint>"
         "<link name=\"upper\"/>"
         "<joint name=\"upper_frame\" type=\"fixed\"><parent link=\"upper_anchor\"/><child link=\"upper\"/>" +
         Origin(Vec3(0, 0, -0.05), Quat::Identity()) + "</joint>"
         "<link name=\"lower_anchor\"><inertial><mass value=\"" + Num(lower_mass) + "\"/>" + inertia + "</inertial>" +
         capsule(Vec3(-0.02, 0, 0.125), Quat::Identity(), 0.02, 0.125) + "<collision>" +
         Origin(Vec3(-0.02, 0, 0.25), Quat(Eigen::AngleAxisd(45 * kDeg, Vec3::UnitY()))) +
         "<geometry><box size=\"0.04 0.06 0.08\"/></geometry></collision></link>"
         "<joint name=\"elbow\" type=\"prismatic\"><parent link=\"upper\"/><child link=\"lower_anchor\"/>" +
         Origin(Vec3(0.3, 0, 0) + lower_q * Vec3(0.02, 0, 0), lower_q) +
         "<axis xyz=\"1 0 0\"/><limit lower=\"-0.1\" upper=\"0.1\" effort=\"10\" velocity=\"1\"/></joint>"
         "<link name=\"lower\"/>"
         "<joint name=\"lower_frame\" type=\"fixed\"><parent link=\"lower_anchor\"/><child link=\"lower\"/>" +
         Origin(Vec3(-0.02, 0, 0), Quat::Identity()) + "</joint>"
         "</robot>";
}

// World poses of every collision geometry, in link order; a sphere's orientation does not matter (identity).
std::vector<Pose> GeometryPoses(const RobotDescription& robot, const std::map<std::string, Pose>& links) {
  std::vector<Pose> poses;
  for (const BodySpec& link : robot.links) {
    for (const Geometry& g : link.collision) {
      poses.push_back(links.at(link.id) * g.origin);
      if (g.kind == Geometry::Kind::kSphere) poses.back().orientation = Quat::Identity();
    }
  }
  return poses;
}

TEST(MjcfLoaderTest, ArmMatchesItsUrdfTwin) {
  const ImportedRobot mjcf = Mjcf(kArmMjcf);
  const ImportedRobot urdf = ImportUrdf(ArmUrdf(), nullptr, ImportOptions(), Limits());
  EXPECT_EQ(mjcf.description.name, "arm");
  EXPECT_EQ(mjcf.description.root_link, "world");
  EXPECT_EQ(JointOf(mjcf.description, "yaw").type, JointType::kContinuous);
  const JointSpec& shoulder = JointOf(mjcf.description, "shoulder");
  EXPECT_EQ(shoulder.type, JointType::kRevolute);
  EXPECT_NEAR(shoulder.lower, -M_PI / 2, kTolerance);
  EXPECT_NEAR(shoulder.upper, M_PI / 2, kTolerance);
  EXPECT_EQ(shoulder.effort_limit, 10);  // motor: gear 2 × ctrlrange 5
  EXPECT_EQ(JointOf(mjcf.description, "elbow").type, JointType::kPrismatic);

  std::mt19937 random(7);
  std::uniform_real_distribution<double> angle(-1.5, 1.5), slide(-0.1, 0.1);
  for (int trial = 0; trial < 20; ++trial) {
    const std::map<std::string, double> q{{"yaw", 3 * angle(random)}, {"shoulder", angle(random)},
                                          {"elbow", slide(random)}};
    const auto a = LinkPoses(mjcf.description, q);
    const auto b = LinkPoses(urdf.description, q);
    for (const char* body : {"world", "base", "upper", "lower"}) {
      EXPECT_LT((a.at(body).position - b.at(body).position).norm(), kTolerance) << body;
      EXPECT_LT(a.at(body).orientation.angularDistance(b.at(body).orientation), kTolerance) << body;
    }
    const std::vector<Pose> ga = GeometryPoses(mjcf.description, a), gb = GeometryPoses(urdf.description, b);
    ASSERT_EQ(ga.size(), gb.size());
    ASSERT_EQ(ga.size(), 9u);  // floor, base cylinder, capsule (cylinder + 2 spheres) × 2, box
    for (size_t i = 0; i < ga.size(); ++i) {
      EXPECT_LT((ga[i].position - gb[i].position).norm(), kTolerance) << "geometry " << i;
      // A cylinder or sphere may differ by a turn about its own z axis; compare where z points.
      EXPECT_LT((ga[i].orientation * Vec3::UnitZ() - gb[i].orientation * Vec3::UnitZ()).norm(), kTolerance) << i;
    }
  }
  // The bodies' mass (the URDF's world link takes its floor's mass from the geometry; MJCF's world has none).
  EXPECT_NEAR(TotalMass(mjcf.description),
              LinkOf(urdf.description, "base").inertial.mass + LinkOf(urdf.description, "upper_anchor").inertial.mass +
                  LinkOf(urdf.description, "lower_anchor").inertial.mass,
              kTolerance);
  EXPECT_NEAR(LinkOf(mjcf.description, "upper").inertial.mass, CapsuleMass(0.03, 0.15, 500), kTolerance);
  // The capsule's centre of mass is the middle of the fromto segment, in the body frame.
  EXPECT_TRUE(LinkOf(mjcf.description, "upper").inertial.center_of_mass.isApprox(Vec3(0.15, 0, 0), kTolerance));
  const Inertial& base = LinkOf(mjcf.description, "base").inertial;
  EXPECT_EQ(base.mass, 2);
  EXPECT_TRUE(base.center_of_mass.isApprox(Vec3(0, 0, 0.05), kTolerance));
}

TEST(MjcfLoaderTest, CapsuleInertiaIsMuJoCos) {
  // MuJoCo's closed form for a capsule of radius r, half length h along z (user_objects.cc).
  const ImportedRobot robot = Mjcf(
      "<mujoco><worldbody><body name=\"b\"><joint/><geom type=\"capsule\" size=\"0.1 0.2\"/></body>"
      "</worldbody></mujoco>");
  const double r = 0.1, height = 0.4;
  const double vs = 4.0 / 3.0 * M_PI * r * r * r, vc = M_PI * r * r * height;
  const double mass = 1000 * (vs + vc), ms = 1000 * vs, mc = 1000 * vc;
  const double across = mc * (3 * r * r + height * height) / 12 + 2 * ms * r * r / 5 + ms * height * (3 * r + 2 * height) / 8;
  const Inertial& inertial = LinkOf(robot.description, "b").inertial;
  EXPECT_NEAR(inertial.mass, mass, 1e-12);
  EXPECT_NEAR(inertial.inertia(0, 0), across, 1e-12);
  EXPECT_NEAR(inertial.inertia(1, 1), across, 1e-12);
  EXPECT_NEAR(inertial.inertia(2, 2), mc * r * r / 2 + 2 * ms * r * r / 5, 1e-12);
  // A hinge with no range in a file without limited: continuous, axis z by default.
  EXPECT_EQ(JointOf(robot.description, "joint0").type, JointType::kContinuous);
  EXPECT_TRUE(JointOf(robot.description, "joint0").axis.isApprox(Vec3::UnitZ()));
}

TEST(MjcfLoaderTest, BallAndFreeJoints) {
  const ImportedRobot robot = Mjcf(R"(
    <mujoco><compiler angle="radian"/><worldbody>
      <body name="floating" pos="1 2 3" quat="0 0 0 1"><freejoint name="float"/>
        <geom type="sphere" size="0.1"/>
        <body name="ball_child" pos="0 0 0.5"><joint name="ball" type="ball" pos="0 0 -0.1" range="0 1"/>
          <geom type="box" size="0.1 0.1 0.1"/></body>
      </body>
    </worldbody></mujoco>)");
  const RobotDescription& d = robot.description;
  for (const char* id : {"float_px", "float_py", "float_pz", "float_x", "float_y", "float_z", "ball_x", "ball_y",
                         "ball_z"}) {
    EXPECT_NO_THROW(JointOf(d, id)) << id;
  }
  EXPECT_EQ(JointOf(d, "ball_x").type, JointType::kRevolute);
  EXPECT_EQ(JointOf(d, "ball_x").upper, 1);
  // At zero the bodies are where the file draws them.
  auto poses = LinkPoses(d, {});
  EXPECT_LT((poses.at("floating").position - Vec3(1, 2, 3)).norm(), kTolerance);
  EXPECT_LT((poses.at("ball_child").position - Vec3(1, 2, 3.5)).norm(), kTolerance);
  // The ball turns the child about its anchor, 0.1 m below the child's origin.
  poses = LinkPoses(d, {{"float_px", 0.5}, {"ball_x", 0.3}, {"ball_y", -0.2}, {"ball_z", 0.7}});
  const Quat turn = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitX()) * Eigen::AngleAxisd(-0.2, Vec3::UnitY()) *
                         Eigen::AngleAxisd(0.7, Vec3::UnitZ()));
  // The free joint's translations are along the axes of the body's frame at zero (turned half about z).
  const Pose floating = Pose{Vec3(1, 2, 3), Quat(0, 0, 0, 1)} * Pose{Vec3(0.5, 0, 0), Quat::Identity()};
  const Pose expected = floating * Pose{Vec3(0, 0, 0.4), Quat::Identity()} * Pose{Vec3::Zero(), turn} *
                        Pose{Vec3(0, 0, 0.1), Quat::Identity()};
  EXPECT_LT((poses.at("ball_child").position - expected.position).norm(), kTolerance);
  EXPECT_LT(poses.at("ball_child").orientation.angularDistance(expected.orientation), kTolerance);
  // A free joint that inherits limited="true" from its class has no limits (MuJoCo ignores them); one in a child
  // body moves it relative to its parent.
  const ImportedRobot nested = Mjcf(R"(<mujoco><default><joint limited="true"/></default><worldbody>
      <body name="a"><geom size="0.1"/><body name="b" pos="1 0 0"><joint type="free"/><geom size="0.1"/></body></body>
    </worldbody></mujoco>)");
  EXPECT_EQ(JointOf(nested.description, "joint0_x").type, JointType::kContinuous);
  EXPECT_LT((LinkPoses(nested.description, {{"joint0_py", 0.5}}).at("b").position - Vec3(1, 0.5, 0)).norm(), kTolerance);
  // Chain links are massless; the bodies carry the mass.
  EXPECT_EQ(LinkOf(d, "floating__px").inertial.mass, 0);
  EXPECT_GT(LinkOf(d, "ball_child").inertial.mass, 0);
}

TEST(MjcfLoaderTest, SeveralJointsInOneBodyComposeAsMuJoCo) {
  // Two hinges at different anchors: MuJoCo turns the body about each anchor in turn (mj_kinematics).
  const ImportedRobot robot = Mjcf(R"(
    <mujoco><compiler angle="radian"/><worldbody>
      <body name="b" pos="0 0 1"><joint name="a" axis="1 0 0" pos="0 0 0.2"/><joint name="c" axis="0 1 0" pos="0.1 0 0"/>
        <geom type="sphere" size="0.1"/></body>
    </worldbody></mujoco>)");
  const auto poses = LinkPoses(robot.description, {{"a", 0.4}, {"c", -0.9}});
  Pose body{Vec3(0, 0, 1), Quat::Identity()};
  for (const auto& [anchor, rotation] : {std::pair{Vec3(0, 0, 0.2), Quat(Eigen::AngleAxisd(0.4, Vec3::UnitX()))},
                                         std::pair{Vec3(0.1, 0, 0), Quat(Eigen::AngleAxisd(-0.9, Vec3::UnitY()))}}) {
    body = body * Pose{anchor, Quat::Identity()} * Pose{Vec3::Zero(), rotation} * Pose{-anchor, Quat::Identity()};
  }
  EXPECT_LT((poses.at("b").position - body.position).norm(), kTolerance);
  EXPECT_LT(poses.at("b").orientation.angularDistance(body.orientation), kTolerance);
}

TEST(MjcfLoaderTest, OrientationForms) {
  // The same rotation four ways: 90° about z.
  const std::vector<std::string> forms = {"quat=\"0.7071067811865476 0 0 0.7071067811865476\"",
                                          "axisangle=\"0 0 1 90\"", "euler=\"0 0 90\"",
                                          "xyaxes=\"0 1 0 -1 0 0\""};
  for (size_t i = 0; i < forms.size(); ++i) {
    const ImportedRobot robot = Mjcf("<mujoco><worldbody><body name=\"b\" " + forms[i] +
                                     "><geom size=\"0.1\"/></body></worldbody></mujoco>");
    const Quat q = robot.description.joints[0].origin.orientation;
    EXPECT_LT(q.angularDistance(Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()))), 1e-12) << forms[i];
  }
  // zaxis: the shortest arc from +z; eulerseq "ZYX" (fixed axes) against "zyx" (moving axes).
  const ImportedRobot z = Mjcf("<mujoco><worldbody><body zaxis=\"1 0 0\"><geom size=\"0.1\"/></body></worldbody></mujoco>");
  EXPECT_TRUE((z.description.joints[0].origin.orientation * Vec3::UnitZ()).isApprox(Vec3::UnitX(), 1e-12));
  for (const std::string seq : {"zyx", "ZYX"}) {
    const ImportedRobot robot = Mjcf("<mujoco><compiler eulerseq=\"" + seq +
                                     "\"/><worldbody><body euler=\"10 20 30\"><geom size=\"0.1\"/></body>"
                                     "</worldbody></mujoco>");
    const Quat a(Eigen::AngleAxisd(10 * kDeg, Vec3::UnitZ())), b(Eigen::AngleAxisd(20 * kDeg, Vec3::UnitY())),
        c(Eigen::AngleAxisd(30 * kDeg, Vec3::UnitX()));
    const Quat expected = seq == "zyx" ? a * b * c : c * b * a;
    EXPECT_LT(robot.description.joints[0].origin.orientation.angularDistance(expected), 1e-12) << seq;
  }
}

TEST(MjcfLoaderTest, GeomKindsAndVisualGeoms) {
  const ImportedRobot robot = Mjcf(R"(
    <mujoco><default><default class="visual"><geom contype="0" conaffinity="0" group="1"/></default></default>
    <worldbody><geom type="plane" size="0 0 1"/>
      <body name="b"><joint/>
        <geom type="ellipsoid" size="0.1 0.2 0.3"/>
        <geom class="visual" type="sphere" size="0.5"/>
        <geom type="sphere" size="0.05" group="3"/>
        <geom type="hfield" hfield="terrain"/>
      </body></worldbody></mujoco>)");
  const BodySpec& world = LinkOf(robot.description, "world");
  ASSERT_EQ(world.collision.size(), 1u);
  EXPECT_EQ(world.collision[0].kind, Geometry::Kind::kBox);
  EXPECT_TRUE(world.collision[0].box_size.isApprox(Vec3(100, 100, 0.1)));
  EXPECT_NEAR(world.collision[0].origin.position.z(), -0.05, 1e-15);
  const BodySpec& b = LinkOf(robot.description, "b");
  ASSERT_EQ(b.collision.size(), 2u);  // the ellipsoid and the group-3 sphere; not the visual sphere, not the hfield
  EXPECT_EQ(b.collision[0].kind, Geometry::Kind::kMesh);
  EXPECT_EQ(b.collision[0].mesh->TriangleCount(), 320u);
  // Mass from all geoms MuJoCo counts (the visual sphere too): ellipsoid + 2 spheres at 1000 kg/m^3.
  const double expected = 1000 * 4.0 / 3.0 * M_PI * (0.1 * 0.2 * 0.3 + 0.125 + 0.05 * 0.05 * 0.05);
  EXPECT_NEAR(b.inertial.mass, expected, 1e-9);
  bool plane_warned = false, hfield_warned = false;
  for (const ImportWarning& w : robot.warnings) {
    plane_warned |= w.value.find("plane") != std::string::npos;
    hfield_warned |= w.value == "hfield";
  }
  EXPECT_TRUE(plane_warned);
  EXPECT_TRUE(hfield_warned);
}

TEST(MjcfLoaderTest, MeshesIncludesAndMimics) {
  const std::string cube =
      "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv -0.5 0.5 -0.5\nv 0.5 0.5 -0.5\n"
      "v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv -0.5 0.5 0.5\nv 0.5 0.5 0.5\n"
      "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  const std::string included = R"(<mujoco><body name="finger"><joint name="f2" type="slide" range="0 0.04"/>
      <geom type="mesh" mesh="cube"/></body></mujoco>)";
  const ImportedRobot robot = Mjcf(R"(
    <mujoco><compiler meshdir="../assets/meshes"/>
      <asset><mesh file="parts/cube.obj" scale="0.1 0.1 0.1"/></asset>
      <worldbody><body name="hand"><joint name="f1" type="slide" range="0 0.04"/><geom type="mesh" mesh="cube"/>
        <include file="finger.xml"/></body></worldbody>
      <equality><joint joint1="f2" joint2="f1" polycoef="0.001 -1 0 0 0"/></equality>
    </mujoco>)",
                                   Files({{"assets/meshes/parts/cube.obj", cube}, {"finger.xml", included}}));
  const BodySpec& hand = LinkOf(robot.description, "hand");
  ASSERT_EQ(hand.collision.size(), 1u);
  EXPECT_EQ(hand.collision[0].mesh_file, "assets/meshes/parts/cube.obj");
  EXPECT_NEAR(hand.inertial.mass, 1000 * 1e-3, 1e-6);  // a 10 cm cube of water (float32 vertices)
  const JointSpec& f2 = JointOf(robot.description, "f2");
  ASSERT_TRUE(f2.mimic.has_value());
  EXPECT_EQ(f2.mimic->joint_id, "f1");
  EXPECT_EQ(f2.mimic->multiplier, -1);
  EXPECT_EQ(f2.mimic->offset, 0.001);
}

TEST(MjcfLoaderTest, NamesAreSanitisedWithAWarning) {
  const ImportedRobot robot = Mjcf(
      "<mujoco><worldbody><body name=\"left finger:1\"><geom size=\"0.1\"/><body><geom size=\"0.1\"/></body>"
      "</body></worldbody></mujoco>");
  EXPECT_NO_THROW(LinkOf(robot.description, "left_finger_1"));
  EXPECT_NO_THROW(LinkOf(robot.description, "body2"));  // MuJoCo's id of the unnamed body
  bool warned = false;
  for (const ImportWarning& w : robot.warnings) warned |= w.value == "'left finger:1'";
  EXPECT_TRUE(warned);
  ImportOptions strict;
  strict.strict = true;
  EXPECT_THROW(Mjcf("<mujoco><worldbody><body name=\"a b\"/></worldbody></mujoco>", nullptr, strict), Error);
}

void ExpectInvalid(const std::string& mjcf, const std::vector<std::string>& fragments,
                   const FileLookup& files = nullptr) {
  try {
    Mjcf(mjcf, files);
    ADD_FAILURE() << "accepted: " << mjcf;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
    for (const std::string& fragment : fragments) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << "'" << fragment << "' not in: " << e.what();
    }
  }
}

std::string World(const std::string& body) { return "<mujoco><worldbody>" + body + "</worldbody></mujoco>"; }

TEST(MjcfLoaderTest, BadInputNamesTheElementAndValue) {
  ExpectInvalid("<mujoco>\n<worldbody>\n<body>\n</worldbody></mujoco>", {"mjcf: XML error", "line"});
  ExpectInvalid("<robot name=\"x\"/>", {"<robot>", "not <mujoco>"});
  ExpectInvalid(World("<body name=\"x\"><geom type=\"box\" size=\"0.1 -2 0.1\"/></body>"),
                {"body 'x' geom 0 size", "-2"});
  ExpectInvalid(World("<body name=\"x\"><geom name=\"g\" size=\"abc\"/></body>"), {"body 'x' geom 'g' size", "'abc'"});
  ExpectInvalid(World("<body name=\"x\"><joint name=\"j\" type=\"screw\"/></body>"), {"joint 'j' type", "'screw'"});
  ExpectInvalid(World("<body name=\"x\"><joint name=\"j\" axis=\"0 0 0\"/></body>"), {"joint 'j' axis", "zero length"});
  ExpectInvalid(World("<body name=\"x\"><joint name=\"j\" range=\"2 1\"/></body>"), {"joint 'j' range", "2"});
  ExpectInvalid(World("<body name=\"x\"><geom class=\"nope\" size=\"1\"/></body>"), {"class", "'nope'"});
  ExpectInvalid(World("<body name=\"x\" quat=\"0 0 0 0\"/>"), {"body 'x' quat", "zero length"});
  ExpectInvalid(World("<body name=\"x\" quat=\"1 0 0 0\" euler=\"0 0 0\"/>"), {"body 'x'", "quat", "euler"});
  ExpectInvalid(World("<body name=\"x\"><geom type=\"mesh\" mesh=\"m\"/></body>"), {"mesh: 'm'"});
  ExpectInvalid("<mujoco><asset><mesh file=\"a.stl\"/><mesh file=\"b.stl\"/></asset>" +
                    World("<body><geom type=\"mesh\" mesh=\"a\"/><geom type=\"mesh\" mesh=\"b\"/></body>")
                        .substr(8),
                {"not uploaded", "'a.stl'", "'b.stl'"});
  ExpectInvalid(World("<body name=\"x\"><inertial mass=\"-1\" diaginertia=\"1 1 1\"/><joint/></body>"), {"-1"});
  ExpectInvalid("<mujoco><include file=\"missing.xml\"/></mujoco>", {"<include>", "'missing.xml'"});
  ExpectInvalid("<mujoco><compiler angle=\"grad\"/></mujoco>", {"angle", "'grad'"});
  ExpectInvalid(World("<body name=\"x\"><joint name=\"j\" limited=\"true\"/></body>"), {"joint 'j' limited", "no range"});
  ExpectInvalid(std::string("<mujoco>\0</mujoco>", 18), {"NUL"});
}

}  // namespace
}  // namespace graspsim


namespace graspsim {
namespace {

TEST(MjcfLoaderTest, GlobalCoordinatesAsTheirLocalTwin) {
  // MuJoCo 2.3.2 and older (pybullet_data's hopper.xml): body, joint, geom and inertial poses in the world frame.
  const ImportedRobot global = Mjcf(R"(
    <mujoco><compiler coordinate="global" angle="radian"/><worldbody>
      <body name="a" pos="0 0 1" euler="0 0 1.5707963267948966"><joint name="ja" pos="0 0 1.2" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 1 0 0 1.4" size="0.05"/>
        <body name="b" pos="0 0 1.4"><joint name="jb" pos="0.1 0 1.4" axis="1 0 0"/>
          <inertial pos="0 0 1.5" mass="1" diaginertia="0.01 0.01 0.01"/></body>
      </body></worldbody></mujoco>)");
  const ImportedRobot local = Mjcf(R"(
    <mujoco><compiler angle="radian"/><worldbody>
      <body name="a" pos="0 0 1" euler="0 0 1.5707963267948966"><joint name="ja" pos="0 0 0.2" axis="1 0 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.4" size="0.05"/>
        <body name="b" pos="0 0 0.4" euler="0 0 -1.5707963267948966"><joint name="jb" pos="0.1 0 0" axis="1 0 0"/>
          <inertial pos="0 0 0.1" mass="1" diaginertia="0.01 0.01 0.01"/></body>
      </body></worldbody></mujoco>)");
  const std::map<std::string, double> q{{"ja", 0.3}, {"jb", -0.8}};
  const auto a = LinkPoses(global.description, q), b = LinkPoses(local.description, q);
  for (const char* body : {"a", "b"}) {
    EXPECT_LT((a.at(body).position - b.at(body).position).norm(), 1e-12) << body;
    EXPECT_LT(a.at(body).orientation.angularDistance(b.at(body).orientation), 1e-12) << body;
  }
  EXPECT_TRUE(LinkOf(global.description, "b").inertial.center_of_mass.isApprox(Vec3(0, 0, 0.1), 1e-12));
}

}  // namespace
}  // namespace graspsim

namespace graspsim {
namespace {

// Cheap fuzzing in the normal test run (tests/fuzz/mjcf_fuzz.cpp is the real one): random edits of the arm and
// of a model with every joint and geom kind must load or be refused with graspsim::Error, nothing else.
TEST(MjcfLoaderTest, MutatedModelsLoadOrAreRefused) {
  const std::string every_kind = R"(<mujoco><compiler angle="radian" eulerseq="zyx"/>
    <asset><mesh name="tri" vertex="0 0 0 1 0 0 0 1 0 0 0 1" face="0 2 1 0 1 3 0 3 2 1 2 3"/></asset>
    <default><default class="c"><joint type="slide" range="0 1"/><geom type="ellipsoid" size="0.1 0.2 0.3"/></default></default>
    <worldbody><geom type="plane" size="1 1 1"/><frame pos="1 0 0" euler="0 0 1">
      <body name="a" xyaxes="1 0 0 0 1 0"><freejoint/><geom type="mesh" mesh="tri"/>
        <body name="b" childclass="c" zaxis="0 1 0"><joint name="s"/><joint type="ball" pos="0 0 1"/><geom/>
          <body name="d" axisangle="1 0 0 1"><joint name="h" limited="true" range="-1 1"/><inertial mass="1" fullinertia="1 1 1 0 0 0"/>
            <geom type="capsule" fromto="0 0 0 1 1 1" size="0.1"/><geom type="cylinder" size="0.1 0.2" mass="2"/></body></body></body>
    </frame></worldbody>
    <equality><joint joint1="h" joint2="s" polycoef="0 2"/></equality>
    <actuator><motor joint="h" ctrlrange="-1 1"/><position joint="s" forcerange="-3 3"/></actuator></mujoco>)";
  const std::string alphabet = "<>/=\" 01-.e+xyzabc\n";
  std::mt19937 random(11);
  size_t loaded = 0, refused = 0;
  for (const std::string& seed : {kArmMjcf, every_kind}) {
    EXPECT_NO_THROW(Mjcf(seed));
    for (int trial = 0; trial < 1500; ++trial) {
      std::string text = seed;
      for (int edits = 1 + static_cast<int>(random() % 3); edits > 0 && !text.empty(); --edits) {
        const size_t at = random() % text.size();
        switch (random() % 4) {
          case 0: text.erase(at, 1 + random() % 8); break;
          case 1: text[at] = alphabet[random() % alphabet.size()]; break;
          case 2: text.insert(at, text.substr(random() % text.size(), random() % 40)); break;
          default: text.insert(at, 1, alphabet[random() % alphabet.size()]); break;
        }
      }
      try {
        Mjcf(text);
        ++loaded;
      } catch (const Error&) {
        ++refused;
      } catch (const std::exception& e) {
        ADD_FAILURE() << "not a graspsim::Error: " << e.what() << "\n" << text;
      }
    }
  }
  EXPECT_GT(loaded, 100u);
  EXPECT_GT(refused, 100u);
}

}  // namespace
}  // namespace graspsim

namespace graspsim {
namespace {

TEST(MjcfLoaderTest, CompilerBoundsAndTotalMass) {
  const ImportedRobot robot = Mjcf(R"(
    <mujoco><compiler settotalmass="10" boundmass="0.5"/><worldbody>
      <body name="a"><joint/><inertial mass="0.1" diaginertia="1 1 1"/>
        <body name="b"><joint/><inertial mass="3" diaginertia="1 1 1"/></body></body>
    </worldbody></mujoco>)");
  // boundmass lifts a to 0.5 kg, then both scale by 10 / 3.5.
  EXPECT_NEAR(LinkOf(robot.description, "a").inertial.mass, 0.5 * 10 / 3.5, 1e-12);
  EXPECT_NEAR(LinkOf(robot.description, "b").inertial.mass, 3 * 10 / 3.5, 1e-12);
  EXPECT_NEAR(LinkOf(robot.description, "b").inertial.inertia(0, 0), 10 / 3.5, 1e-12);
}

}  // namespace
}  // namespace graspsim

namespace graspsim {
namespace {

TEST(MjcfLoaderTest, StrictLoadingNeedsNoRepair) {
  // The arm needs no repair (its site and motor are notes of what graspsim does not import, not repairs).
  ImportOptions strict;
  strict.strict = true;
  const ImportedRobot robot = Mjcf(kArmMjcf, nullptr, strict);
  EXPECT_EQ(LinkOf(robot.description, "world").inertial.mass, 0);  // welded: massless, even with its floor
  for (const ImportWarning& w : robot.warnings) {
    EXPECT_TRUE(w.element == "mjcf: <site>" || w.element == "mjcf: <actuator>") << w.element << ": " << w.action;
  }
  // A plane needs one: refused.
  EXPECT_THROW(Mjcf("<mujoco><worldbody><geom type=\"plane\" size=\"1 1 1\"/></worldbody></mujoco>", nullptr, strict),
               Error);
}

}  // namespace
}  // namespace graspsim

namespace graspsim {
namespace {

TEST(MjcfLoaderTest, MeshMassIsMuJoCosLegacyIntegral) {
  // A unit cube as 12 triangles; MuJoCo's default ("legacy") counts every pyramid positive, so the cube turned
  // inside out weighs the same, and the cube without its top still weighs (almost) as much.
  const std::vector<Eigen::Vector3f> corners = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                                {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  TriangleMesh cube;
  cube.vertices = corners;
  cube.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                    {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  const import::mjcf::MeshVolume closed = import::mjcf::LegacyMeshVolume(cube);
  EXPECT_NEAR(closed.volume, 1, 1e-12);
  EXPECT_TRUE(closed.centroid.isApprox(Vec3::Constant(0.5), 1e-12));
  EXPECT_TRUE(closed.inertia_per_density.isApprox(Mat3::Identity() / 6, 1e-12)) << closed.inertia_per_density;
  TriangleMesh inside_out = cube;
  for (auto& t : inside_out.triangles) std::swap(t[1], t[2]);
  EXPECT_NEAR(import::mjcf::LegacyMeshVolume(inside_out).volume, 1, 1e-12);
  TriangleMesh open = cube;
  open.triangles.erase(open.triangles.begin() + 2, open.triangles.begin() + 4);
  EXPECT_GT(import::mjcf::LegacyMeshVolume(open).volume, 0.5);
}

}  // namespace
}  // namespace graspsim
