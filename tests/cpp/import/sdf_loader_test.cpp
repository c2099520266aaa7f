// ImportSdf: a small arm written with SDF's frame semantics (relative_to, a <frame>, a joint pose in its child's
// frame, an axis expressed in the model frame) against its URDF twin, whose numbers were worked out by hand
// (tests/cpp/import/sdf_twin.py prints them); worlds and model_name; the joints and shapes graspsim builds from its
// own; one test per rejection asserting the code and that the message names the element and the value.
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "import/robot_import.h"

namespace graspsim {
namespace {

constexpr double kTolerance = 1e-12;

std::string Inertial(const std::string& mass, const std::string& extra = "") {
  return "<inertial>" + extra + "<mass>" + mass +
         "</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>";
}

const std::string kSdfArm = R"(<?xml version="1.0"?>
<sdf version="1.8">
  <model name="arm">
    <frame name="mount"><pose>0 0 0.1 0 0 0.3</pose></frame>
    <link name="base">
      <pose relative_to="mount">0.05 0 0 0 0 0</pose>
      )" + Inertial("2") + R"(
      <collision name="c"><geometry><box><size>0.1 0.2 0.3</size></box></geometry></collision>
    </link>
    <joint name="shoulder" type="revolute">
      <pose relative_to="base">0 0 0.5 0 0 1.5707963267948966</pose>
      <parent>base</parent><child>upper</child>
      <axis><xyz>0 0 1</xyz><limit><lower>-1</lower><upper>1</upper></limit></axis>
    </joint>
    <link name="upper">
      <pose relative_to="shoulder"/>
      <inertial><pose>0.1 0 0 0 0 1.5707963267948966</pose><mass>1.5</mass>
        <inertia><ixx>1</ixx><ixy>0.1</ixy><iyy>2</iyy><izz>3</izz></inertia></inertial>
      <collision name="c"><geometry><cylinder><radius>0.02</radius><length>0.3</length></cylinder></geometry>
      </collision>
    </link>
    <link name="lower">
      <pose relative_to="upper">0.3 0 0 0 0.2 0</pose>
      )" + Inertial("1") + R"(
      <collision name="c"><pose relative_to="elbow">0 0 0.05 0 0 0</pose>
        <geometry><box><size>0.02 0.02 0.1</size></box></geometry></collision>
    </link>
    <joint name="elbow" type="revolute">
      <pose>0.01 0.02 0 0.1 0 0</pose>
      <parent>upper</parent><child>lower</child>
      <axis><xyz>1 1 0</xyz><limit><lower>-2</lower><upper>2</upper></limit></axis>
    </joint>
    <link name="tool"><pose relative_to="lower">0 0 0.1 0 0 0</pose></link>
    <joint name="tool_joint" type="fixed"><parent>lower</parent><child>tool</child></joint>
    <link name="slider">
      <pose relative_to="lower">0 -0.05 0 0 0 0</pose>
      )" + Inertial("0.5") + R"(
      <collision name="c"><geometry><sphere><radius>0.03</radius></sphere></geometry></collision>
    </link>
    <joint name="slide" type="prismatic">
      <parent>lower</parent><child>slider</child>
      <axis><xyz expressed_in="__model__">0 1 0</xyz><limit><lower>-0.1</lower><upper>0.1</upper></limit></axis>
    </joint>
  </model>
</sdf>)";

// The twin. SDF's elbow frame is not its child link's frame, so graspsim moves a massless link
// "lower__joint_frame" (the joint frame) and fixes "lower" to it; the twin spells that out.
const std::string kUrdfLimit = R"(<limit lower="-1" upper="1" effort="0" velocity="0"/>)";
const std::string kUrdfArm = R"(<robot name="arm">
  <link name="base">
    <inertial><mass value="2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><box size="0.1 0.2 0.3"/></geometry></collision>
  </link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.5" rpy="0 0 1.5707963267948966"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="0" velocity="0"/></joint>
  <link name="upper">
    <inertial><origin xyz="0.1 0 0" rpy="0 0 1.5707963267948966"/><mass value="1.5"/>
      <inertia ixx="1" ixy="0.1" ixz="0" iyy="2" iyz="0" izz="3"/></inertial>
    <collision><geometry><cylinder radius="0.02" length="0.3"/></geometry></collision>
  </link>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="lower__joint_frame"/>
    <origin xyz="0.30980066577841237 0.020000000000000011 -0.0019866933079506488"
            rpy="0.099999999999999992 0.20000000000000001 -5.6640183928657481e-17"/>
    <axis xyz="1 1 0"/><limit lower="-2" upper="2" effort="0" velocity="0"/></joint>
  <link name="lower__joint_frame"/>
  <joint name="elbow__frame" type="fixed"><parent link="lower__joint_frame"/><child link="lower"/>
    <origin xyz="-0.010000000000000009 -0.019900083305560513 0.0019966683329365464"
            rpy="-0.099999999999999992 0 -2.0816681711721685e-17"/></joint>
  <link name="lower">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision>
      <origin xyz="0.010000000000000009 0.015008329167658603 0.049750208263901294"
              rpy="0.099999999999999992 0 -5.5511151231257827e-17"/>
      <geometry><box size="0.02 0.02 0.1"/></geometry></collision>
  </link>
  <joint name="tool_joint" type="fixed"><parent link="lower"/><child link="tool"/>
    <origin xyz="2.7755575615628914e-17 0 0.10000000000000009" rpy="0 0 -5.5511151231257827e-17"/></joint>
  <link name="tool"/>
  <joint name="slide" type="prismatic"><parent link="lower"/><child link="slider"/>
    <origin xyz="0 -0.049999999999999989 0" rpy="0 0 -5.5511151231257827e-17"/>
    <axis xyz="0.93629336358419923 -0.29552020666133949 0.18979606097868743"/>
    <limit lower="-0.1" upper="0.1" effort="0" velocity="0"/></joint>
  <link name="slider">
    <inertial><mass value="0.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
</robot>)";

const FileLookup kNoFiles = [](const std::string&) -> const std::string* { return nullptr; };

ImportedRobot Sdf(const std::string& text, const ImportOptions& options = {}) {
  return ImportSdf(text, kNoFiles, options, Limits{});
}

// Every body's frame relative to the root, joints at `q` (by joint id; absent = 0).
std::map<std::string, Pose> Fk(const RobotDescription& d, const std::map<std::string, double>& q) {
  std::map<std::string, Pose> poses{{d.root_link, Pose{}}};
  for (const JointSpec& joint : d.joints) {
    const auto it = q.find(joint.id);
    const double value = it == q.end() ? 0 : it->second;
    Pose motion;
    if (joint.type == JointType::kPrismatic) motion.position = joint.axis * value;
    if (joint.type == JointType::kRevolute || joint.type == JointType::kContinuous) {
      motion.orientation = Quat(Eigen::AngleAxisd(value, joint.axis));
    }
    poses[joint.child_body] = poses.at(joint.parent_body) * joint.origin * motion;
  }
  return poses;
}

const BodySpec& Body(const RobotDescription& d, const std::string& id) {
  for (const BodySpec& body : d.links) {
    if (body.id == id) return body;
  }
  throw std::runtime_error("no body " + id);
}

const JointSpec* FindJoint(const RobotDescription& d, const std::string& id) {
  for (const JointSpec& joint : d.joints) {
    if (joint.id == id) return &joint;
  }
  return nullptr;
}

void ExpectNear(const Pose& a, const Pose& b, const std::string& what) {
  EXPECT_LT((a.position - b.position).norm(), kTolerance) << what;
  EXPECT_LT(a.orientation.angularDistance(b.orientation), kTolerance) << what;
}

TEST(SdfLoader, ArmMatchesItsUrdfTwin) {
  const ImportedRobot sdf = Sdf(kSdfArm);
  const ImportedRobot urdf = ImportUrdf(kUrdfArm, kNoFiles, ImportOptions{}, Limits{});
  ASSERT_EQ(sdf.description.root_link, "base");
  ASSERT_EQ(sdf.description.links.size(), urdf.description.links.size());
  ASSERT_EQ(sdf.description.joints.size(), urdf.description.joints.size());
  for (size_t i = 0; i < urdf.description.joints.size(); ++i) {
    const JointSpec& u = urdf.description.joints[i];
    const JointSpec* s = FindJoint(sdf.description, u.id);
    ASSERT_NE(s, nullptr) << u.id;
    EXPECT_EQ(s->type, u.type) << u.id;
    EXPECT_EQ(s->parent_body, u.parent_body) << u.id;
    EXPECT_EQ(s->child_body, u.child_body) << u.id;
    EXPECT_LT((s->axis - u.axis).norm(), kTolerance) << u.id;
    EXPECT_EQ(s->lower, u.lower) << u.id;
    EXPECT_EQ(s->upper, u.upper) << u.id;
  }
  std::mt19937 random(19);
  for (int trial = 0; trial < 50; ++trial) {
    std::map<std::string, double> q;
    for (const JointSpec& joint : urdf.description.joints) {
      q[joint.id] = std::uniform_real_distribution<double>(joint.lower, joint.upper)(random);
    }
    const auto fk_sdf = Fk(sdf.description, q), fk_urdf = Fk(urdf.description, q);
    for (const auto& [link, pose] : fk_urdf) ExpectNear(fk_sdf.at(link), pose, link);
  }
  for (const std::string link : {"base", "upper", "lower", "tool", "slider"}) {
    const BodySpec &s = Body(sdf.description, link), &u = Body(urdf.description, link);
    EXPECT_NEAR(s.inertial.mass, u.inertial.mass, kTolerance) << link;
    EXPECT_LT((s.inertial.center_of_mass - u.inertial.center_of_mass).norm(), kTolerance) << link;
    EXPECT_LT((s.inertial.inertia - u.inertial.inertia).norm(), kTolerance) << link;
    ASSERT_EQ(s.collision.size(), u.collision.size()) << link;
    for (size_t k = 0; k < s.collision.size(); ++k) {
      EXPECT_EQ(s.collision[k].kind, u.collision[k].kind) << link;
      ExpectNear(s.collision[k].origin, u.collision[k].origin, link + " collision");
      EXPECT_LT((s.collision[k].box_size - u.collision[k].box_size).norm(), kTolerance) << link;
      EXPECT_EQ(s.collision[k].radius, u.collision[k].radius) << link;
      EXPECT_EQ(s.collision[k].length, u.collision[k].length) << link;
    }
  }
  EXPECT_EQ(Body(sdf.description, "lower__joint_frame").inertial.mass, 0);
}

const std::string kWorld = R"(<sdf version="1.7"><world name="w">
  <model name="first"><static>true</static><link name="a">)" + Inertial("1") + R"(</link></model>
  <model name="second"><pose>1 2 3 0 0 0</pose>
    <link name="b">)" + Inertial("1") + R"(</link>
    <link name="c"><pose>0 0 1 0 0 0</pose>)" + Inertial("1") + R"(</link>
    <joint name="fix" type="fixed"><parent>world</parent><child>b</child></joint>
    <joint name="hinge" type="continuous"><parent>b</parent><child>c</child><axis><xyz>0 1 0</xyz></axis></joint>
  </model>
</world></sdf>)";

TEST(SdfLoader, WorldLoadsTheFirstOrTheNamedModel) {
  const ImportedRobot first = Sdf(kWorld);
  EXPECT_EQ(first.description.name, "first");
  EXPECT_EQ(first.description.root_link, "a");
  EXPECT_TRUE(first.warnings.empty());  // static: no warning about the fixed base
  ImportOptions options;
  options.model_name = "second";
  const ImportedRobot second = Sdf(kWorld, options);
  EXPECT_EQ(second.description.name, "second");
  EXPECT_EQ(second.description.root_link, "b");  // welded to the world
  ASSERT_EQ(second.description.joints.size(), 1u);
  EXPECT_EQ(second.description.joints[0].type, JointType::kContinuous);
  EXPECT_LT((second.description.joints[0].origin.position - Vec3(0, 0, 1)).norm(), kTolerance);
  EXPECT_TRUE(second.warnings.empty());
  options.model_name = "third";
  try {
    Sdf(kWorld, options);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("'third'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'first', 'second'"), std::string::npos) << e.what();
  }
}

TEST(SdfLoader, JointsAndShapesGraspsimBuildsFromItsOwn) {
  const std::string text = R"(<sdf version="1.7"><model name="m">
    <link name="base">)" + Inertial("1") + R"(
      <collision name="cap"><geometry><capsule><radius>0.1</radius><length>0.4</length></capsule></geometry></collision>
      <collision name="egg"><geometry><ellipsoid><radii>0.1 0.2 0.3</radii></ellipsoid></geometry></collision>
      <collision name="floor"><geometry><plane><normal>0 0 1</normal><size>2 3</size></plane></geometry></collision>
    </link>
    <link name="u">)" + Inertial("1") + R"(</link>
    <joint name="cardan" type="universal"><parent>base</parent><child>u</child>
      <axis><xyz>1 0 0</xyz></axis><axis2><xyz>0 1 0</xyz></axis2></joint>
    <link name="b">)" + Inertial("1") + R"(</link>
    <joint name="shoulder" type="ball"><parent>u</parent><child>b</child></joint>
    <link name="loose">)" + Inertial("1") + R"(</link>
    <model name="inner"><pose>0 0 2 0 0 0</pose>
      <link name="l">)" + Inertial("1") + R"(</link>
    </model>
    <joint name="to_inner" type="fixed"><parent>b</parent><child>inner::l</child></joint>
  </model></sdf>)";
  const ImportedRobot robot = Sdf(text);
  const RobotDescription& d = robot.description;
  const BodySpec& base = Body(d, "base");
  ASSERT_EQ(base.collision.size(), 5u);  // capsule = cylinder + 2 spheres, ellipsoid, plane
  EXPECT_EQ(base.collision[0].kind, Geometry::Kind::kCylinder);
  EXPECT_EQ(base.collision[0].length, 0.4);
  EXPECT_EQ(base.collision[1].kind, Geometry::Kind::kSphere);
  EXPECT_NEAR(base.collision[1].origin.position.z(), 0.2, kTolerance);
  EXPECT_EQ(base.collision[3].kind, Geometry::Kind::kMesh);
  ASSERT_NE(base.collision[3].mesh, nullptr);
  float max_z = 0;
  for (const auto& v : base.collision[3].mesh->vertices) max_z = std::max(max_z, v.z());
  EXPECT_NEAR(max_z, 0.3, 1e-6);
  EXPECT_EQ(base.collision[4].kind, Geometry::Kind::kBox);
  EXPECT_LT((base.collision[4].box_size - Vec3(2, 3, 0.1)).norm(), kTolerance);
  EXPECT_NEAR(base.collision[4].origin.position.z(), -0.05, kTolerance);
  // universal: two revolute joints through a massless link
  const JointSpec* first = FindJoint(d, "cardan__axis1");
  const JointSpec* second = FindJoint(d, "cardan__axis2");
  ASSERT_NE(first, nullptr);
  ASSERT_NE(second, nullptr);
  EXPECT_EQ(first->child_body, second->parent_body);
  EXPECT_EQ(second->child_body, "u");
  EXPECT_LT((second->axis - Vec3::UnitY()).norm(), kTolerance);
  EXPECT_EQ(Body(d, first->child_body).inertial.mass, 0);
  // ball: three revolute joints (AppendBallJoint), unlimited; with the universal joint's two, five
  size_t continuous = 0;
  for (const JointSpec& joint : d.joints) continuous += joint.type == JointType::kContinuous;
  EXPECT_EQ(continuous, 5u);
  const auto fk_zero = Fk(d, {});
  EXPECT_LT(fk_zero.at("b").position.norm(), kTolerance);
  // nested model flattened; its link 2 m up
  const auto fk = Fk(d, {});
  ASSERT_EQ(fk.count("inner.l"), 1u);
  EXPECT_LT((fk.at("inner.l").position - Vec3(0, 0, 2)).norm(), kTolerance);
  // the link no joint reaches is fixed to the root, with a warning; the plane and the free base warn too
  const JointSpec* weld = FindJoint(d, "loose__fixed");
  ASSERT_NE(weld, nullptr);
  EXPECT_EQ(weld->parent_body, "base");
  bool warned_loose = false, warned_plane = false;
  for (const ImportWarning& w : robot.warnings) {
    warned_loose = warned_loose || w.element.find("'loose'") != std::string::npos;
    warned_plane = warned_plane || w.element.find("plane") != std::string::npos;
  }
  EXPECT_TRUE(warned_loose);
  EXPECT_TRUE(warned_plane);
}

TEST(SdfLoader, JointToTheWorldThatMovesKeepsItsMotion) {
  const std::string text = R"(<sdf version="1.7"><world name="w"><model name="lift"><pose>0 0 1 0 0 0</pose>
    <link name="carriage">)" + Inertial("1") + R"(</link>
    <joint name="z" type="prismatic"><parent>world</parent><child>carriage</child>
      <axis><xyz>0 0 1</xyz><limit><lower>0</lower><upper>0.5</upper></limit></axis></joint>
  </model></world></sdf>)";
  const RobotDescription d = Sdf(text).description;
  EXPECT_EQ(d.root_link, "world");
  ASSERT_EQ(d.joints.size(), 1u);
  EXPECT_EQ(d.joints[0].type, JointType::kPrismatic);
  EXPECT_LT((d.joints[0].origin.position - Vec3(0, 0, 1)).norm(), kTolerance);  // the model's pose in the world
}

TEST(SdfLoader, StrictLoadingRefusesRepairs) {
  ImportOptions strict;
  strict.strict = true;
  const std::string plane = R"(<sdf version="1.7"><model name="m"><static>true</static><link name="l">)" +
                            Inertial("1") +
                            R"(<collision name="p"><geometry><plane><normal>0 0 1</normal><size>1 1</size></plane>
                            </geometry></collision></link></model></sdf>)";
  EXPECT_NO_THROW(Sdf(plane));
  EXPECT_THROW(Sdf(plane, strict), Error);
}

// What pybullet_data's files do that libsdformat reports as errors and PyBullet loads: a link named "world" (reserved
// in SDF) that the base is jointed to, collisions sharing a name, a model name with a space, two models of one name.
TEST(SdfLoader, PyBulletsQuirksLoadAsPyBulletLoadsThem) {
  const std::string text = R"(<sdf version="1.6"><world name="default">
    <model name="Pod Two">
      <link name="world"/>
      <link name="base">)" + Inertial("1") + R"(
        <collision name="c"><geometry><box><size>1 1 1</size></box></geometry></collision>
        <collision name="c"><pose>0 0 2 0 0 0</pose><geometry><box><size>1 1 1</size></box></geometry></collision>
      </link>
      <joint name="lift" type="prismatic"><parent>world</parent><child>base</child>
        <axis><xyz>0 0 1</xyz><limit><lower>0</lower><upper>1</upper></limit></axis></joint>
    </model>
    <model name="Pod Two"><link name="other"/></model>
  </world></sdf>)";
  const ImportedRobot robot = Sdf(text);
  EXPECT_EQ(robot.description.name, "Pod_Two");
  EXPECT_EQ(robot.description.root_link, "world");
  ASSERT_EQ(robot.description.joints.size(), 1u);
  EXPECT_EQ(robot.description.joints[0].parent_body, "world");
  const BodySpec& base = Body(robot.description, "base");
  ASSERT_EQ(base.collision.size(), 2u);
  EXPECT_NEAR(base.collision[1].origin.position.z(), 2, kTolerance);
  std::string elements;
  for (const ImportWarning& w : robot.warnings) elements += w.element + " " + w.value + "\n";
  EXPECT_NE(elements.find("collision 'c' (name repeated)"), std::string::npos) << elements;
  EXPECT_NE(elements.find("model 'Pod Two' name 'Pod Two'"), std::string::npos) << elements;
  EXPECT_NE(elements.find("model with name[Pod Two] already exists"), std::string::npos) << elements;
  EXPECT_EQ(elements.find("not static"), std::string::npos) << elements;  // the "world" link holds it
}

TEST(SdfLoader, NestedCanonicalLinkIsTheRoot) {
  const std::string text = R"(<sdf version="1.8"><model name="outer" canonical_link="inner::core">
    <link name="side"><pose>1 0 0 0 0 0</pose>)" + Inertial("1") + R"(</link>
    <model name="inner"><pose>0 0 1 0 0 0</pose><link name="core">)" + Inertial("1") + R"(</link></model>
  </model></sdf>)";
  const RobotDescription d = Sdf(text).description;
  EXPECT_EQ(d.root_link, "inner.core");
  const auto fk = Fk(d, {});
  EXPECT_LT((fk.at("side").position - Vec3(1, 0, -1)).norm(), kTolerance);
}

void ExpectInvalid(const std::string& text, const std::vector<std::string>& fragments,
                   const FileLookup& files = kNoFiles) {
  try {
    ImportSdf(text, files, ImportOptions{}, Limits{});
    FAIL() << "accepted: " << text;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
    for (const std::string& fragment : fragments) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << "'" << fragment << "' not in: " << e.what();
    }
  }
}

std::string Model(const std::string& body) {
  return R"(<sdf version="1.7"><model name="m"><link name="a">)" + Inertial("1") + "</link>" + body +
         "</model></sdf>";
}

TEST(SdfLoader, BadInputIsRefusedNamingElementAndValue) {
  ExpectInvalid("", {"sdf: XML error"});
  ExpectInvalid("<sdf version=\"1.7\">\n<model name=\"m\">\n<link name=\"a\"></model></sdf>",
                {"sdf: XML error at line 3"});
  ExpectInvalid("<sdf version=\"1.7\"><world name=\"w\"/></sdf>", {"sdf: the file has no <model>"});
  ExpectInvalid("<!-- <sdf> --><robot name=\"r\"><link name=\"a\"/></robot>", {"<robot>", "send it as urdf"});
  ExpectInvalid(Model(R"(<link name="b"><collision name="c"><geometry><box><size>1 -2 3</size></box></geometry>
      </collision></link>)"),
                {"sdf: model 'm' link 'b' collision 'c' box size", "-2"});
  ExpectInvalid(Model(R"(<link name="b"/><joint name="s" type="screw"><parent>a</parent><child>b</child>
      <axis><xyz>0 0 1</xyz></axis></joint>)"),
                {"joint 's'", "screw"});
  ExpectInvalid(Model(R"(<link name="b"/><joint name="p" type="prismatic"><parent>a</parent><child>b</child>
      <axis><xyz>0 0 1</xyz><limit><lower>1</lower><upper>-1</upper></limit></axis></joint>)"),
                {"joint 'p'", "lower 1", "upper -1"});
  ExpectInvalid(Model(R"(<link name="b"/><link name="c"/>
      <joint name="j1" type="fixed"><parent>a</parent><child>c</child></joint>
      <joint name="j2" type="fixed"><parent>b</parent><child>c</child></joint>)"),
                {"link 'c'", "'j1'", "'j2'"});
  ExpectInvalid(Model(R"(<link name="b"><collision name="c"><geometry><mesh><uri>model://m/meshes/x.stl</uri></mesh>
      </geometry></collision><collision name="d"><geometry><mesh><uri>package://p/y.obj</uri></mesh></geometry>
      </collision></link>)"),
                {"not uploaded", "x.stl", "y.obj"});
  ExpectInvalid(R"(<sdf version="1.7"><world name="w"><include><uri>model://table</uri></include></world></sdf>)",
                {"<include>", "'model://table'"});
  ExpectInvalid(Model(R"(<link name="b"/><joint name="j" type="revolute"><parent>a</parent><child>nowhere</child>
      <axis><xyz>0 0 1</xyz></axis></joint>)"),
                {"nowhere"});
}

// libsdformat spends about 1.6 ms per <link> (it copies the element's schema): counted before parsing.
TEST(SdfLoader, ElementCountsAreBoundedBeforeParsing) {
  Limits limits;
  limits.max_bodies_per_scene = 4;
  std::string links;
  for (int i = 0; i < 5; ++i) links += "<link name=\"l" + std::to_string(i) + "\"/>";
  try {
    ImportSdf("<sdf version=\"1.7\"><model name=\"m\">" + links + "</model></sdf>", kNoFiles, {}, limits);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kResourceExhausted);
    EXPECT_NE(std::string(e.what()).find("5 <link> elements, above the limit of 4"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace graspsim
