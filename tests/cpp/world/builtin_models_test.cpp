// The built-in models load, and their numbers agree with the datasheets and with their own geometry.
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "import/robot_import.h"
#include "world/loaders.h"

namespace graspsim {
namespace {

RobotDescription LoadBuiltin(const std::string& name) {
  return LoadUrdf(BuiltinModelUrdf(name), nullptr, Limits());
}

const JointSpec& FindJoint(const RobotDescription& robot, const std::string& id) {
  const auto it = std::find_if(robot.joints.begin(), robot.joints.end(), [&](const auto& j) { return j.id == id; });
  if (it == robot.joints.end()) throw std::runtime_error("no joint " + id);
  return *it;
}

const TactileArraySpec& FindPad(const RobotDescription& robot, const std::string& id) {
  const auto it = std::find_if(robot.tactile_arrays.begin(), robot.tactile_arrays.end(),
                               [&](const auto& t) { return t.id == id; });
  if (it == robot.tactile_arrays.end()) throw std::runtime_error("no tactile array " + id);
  return *it;
}

// Inertia of a uniform box of full edge lengths `size` about its centre, kg m^2.
Mat3 BoxInertia(double mass, const Vec3& size) {
  const Vec3 s2 = size.cwiseProduct(size);
  return (mass / 12 * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y())).asDiagonal();
}

TEST(BuiltinModelsTest, ListsTheModels) {
  const std::vector<BuiltinModelInfo>& models = BuiltinModels();
  ASSERT_EQ(models.size(), 14u);  // 6 hands and objects, 2 arms, 2 x 3 arms with a hand
  EXPECT_EQ(models[0].name, "schunk_pg70");
  EXPECT_EQ(models[0].kind, "robot");
  EXPECT_EQ(models[1].name, "table");
  EXPECT_EQ(models[1].kind, "object");
  EXPECT_TRUE(models[1].is_static);
  EXPECT_EQ(models[2].name, "cube_5cm");
  EXPECT_EQ(models[2].kind, "object");
  EXPECT_FALSE(models[2].is_static);
  EXPECT_EQ(models[3].name, "schunk_pg70_on_z_axis");  // tests/cpp/workcycle checks its kinematics
  EXPECT_EQ(models[3].kind, "robot");
  EXPECT_EQ(models[4].name, "barrett_bh8_282");  // the grasp hands: tests/cpp/grasp checks their kinematics
  EXPECT_EQ(models[5].name, "schunk_sdh2");
  EXPECT_EQ(models[6].name, "kuka_kr5_sixx_r850");  // the arms: tests/cpp/motion checks their kinematics
  EXPECT_EQ(models[7].name, "mitsubishi_pa10");
  EXPECT_EQ(models[8].name, "kuka_kr5_sixx_r850_barrett");
  EXPECT_EQ(models[13].name, "mitsubishi_pa10_pg70");
  for (const BuiltinModelInfo& model : models) {
    EXPECT_FALSE(model.description.empty());
    const RobotDescription robot = LoadBuiltin(model.name);
    EXPECT_EQ(robot.name, model.name);
  }
}

TEST(BuiltinModelsTest, UnknownNameIsNotFound) {
  try {
    BuiltinModelUrdf("ur5");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotFound);
    EXPECT_STREQ(e.what(), "builtin model 'ur5' is not known; known: barrett_bh8_282, cube_5cm, kuka_kr5_sixx_r850, "
                           "kuka_kr5_sixx_r850_barrett, kuka_kr5_sixx_r850_pg70, kuka_kr5_sixx_r850_sdh2, "
                           "mitsubishi_pa10, mitsubishi_pa10_barrett, mitsubishi_pa10_pg70, mitsubishi_pa10_sdh2, "
                           "schunk_pg70, schunk_pg70_on_z_axis, schunk_sdh2, table");
  }
}

TEST(BuiltinModelsTest, Pg70KinematicsFromTheDatasheet) {
  const RobotDescription pg70 = LoadBuiltin("schunk_pg70");
  ASSERT_EQ(pg70.links.size(), 3u);
  EXPECT_EQ(pg70.root_link, "base_link");
  EXPECT_EQ(pg70.links[0].inertial.mass, 1.4);
  ASSERT_EQ(pg70.joints.size(), 2u);
  const JointSpec& left = FindJoint(pg70, "finger_left_joint");
  const JointSpec& right = FindJoint(pg70, "finger_right_joint");
  for (const JointSpec* joint : {&left, &right}) {
    EXPECT_EQ(joint->type, JointType::kPrismatic);
    EXPECT_EQ(joint->lower, 0);
    EXPECT_EQ(joint->upper, 0.035);  // stroke per finger
    EXPECT_EQ(joint->velocity_limit, 0.082);
    EXPECT_EQ(joint->effort_limit, 200);
  }
  ASSERT_TRUE(right.mimic.has_value());
  EXPECT_EQ(right.mimic->joint_id, "finger_left_joint");
  EXPECT_EQ(right.mimic->multiplier, 1);
  EXPECT_EQ(right.mimic->offset, 0);
  EXPECT_TRUE(left.axis.isApprox(Vec3::UnitY(), 1e-12));  // opening moves the fingers apart along y
  EXPECT_TRUE(right.axis.isApprox(-Vec3::UnitY(), 1e-12));
}

TEST(BuiltinModelsTest, Pg70PadsFaceEachOtherAFewMillimetresApartWhenClosed) {
  const RobotDescription pg70 = LoadBuiltin("schunk_pg70");
  ASSERT_EQ(pg70.tactile_arrays.size(), 2u);
  const TactileArraySpec& left = FindPad(pg70, "pad_left");
  const TactileArraySpec& right = FindPad(pg70, "pad_right");
  EXPECT_EQ(left.body_id, "finger_left");
  EXPECT_EQ(right.body_id, "finger_right");
  for (const TactileArraySpec* pad : {&left, &right}) {
    EXPECT_EQ(pad->rows, 14u);
    EXPECT_EQ(pad->cols, 6u);
    EXPECT_EQ(pad->pitch, 0.0034);
    EXPECT_EQ(pad->thickness, 0.004);
  }
  // At position 0 each pad frame in base_link is joint origin * pad origin (the joint adds no displacement).
  const Pose left_pad = FindJoint(pg70, "finger_left_joint").origin * left.origin;
  const Pose right_pad = FindJoint(pg70, "finger_right_joint").origin * right.origin;
  const Vec3 left_normal = left_pad.orientation * Vec3::UnitZ();
  const Vec3 right_normal = right_pad.orientation * Vec3::UnitZ();
  EXPECT_TRUE(left_normal.isApprox(-Vec3::UnitY(), 1e-12));
  EXPECT_TRUE(right_normal.isApprox(Vec3::UnitY(), 1e-12));
  const Vec3 left_surface = left_pad.position + left.thickness * left_normal;
  const Vec3 right_surface = right_pad.position + right.thickness * right_normal;
  const double gap = left_surface.y() - right_surface.y();
  EXPECT_GE(gap, 0);
  EXPECT_LE(gap, 0.005);
  // Pads are centred on each other and on the gripper's approach axis.
  EXPECT_NEAR(left_surface.x(), right_surface.x(), 1e-12);
  EXPECT_NEAR(left_surface.z(), right_surface.z(), 1e-12);
  // Rows run along the finger (z), cols across it (x).
  EXPECT_TRUE((left_pad.orientation * Vec3::UnitY()).isApprox(Vec3::UnitZ(), 1e-12));
  EXPECT_TRUE((right_pad.orientation * Vec3::UnitY()).isApprox(Vec3::UnitZ(), 1e-12));
}

TEST(BuiltinModelsTest, CubeInertiaIsMassTimesEdgeSquaredOverSix) {
  const RobotDescription cube = LoadBuiltin("cube_5cm");
  ASSERT_EQ(cube.links.size(), 1u);
  const BodySpec& body = cube.links[0];
  EXPECT_EQ(body.id, "cube_5cm");
  EXPECT_EQ(body.inertial.mass, 0.1);
  ASSERT_EQ(body.collision.size(), 1u);
  EXPECT_TRUE(body.collision[0].box_size.isApprox(Vec3::Constant(0.05), 1e-15));
  EXPECT_TRUE(body.collision[0].origin.position.isZero());
  const Mat3 expected = Mat3::Identity() * (0.1 * 0.05 * 0.05 / 6);
  EXPECT_LT((body.inertial.inertia - expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_TRUE(body.inertial.center_of_mass.isZero());
}

TEST(BuiltinModelsTest, TableTopAt75CentimetresAndInertiaMatchesItsBoxes) {
  const RobotDescription table = LoadBuiltin("table");
  ASSERT_EQ(table.links.size(), 1u);
  const BodySpec& body = table.links[0];
  ASSERT_EQ(body.collision.size(), 5u);
  // The top is the box with the largest footprint.
  const auto top = std::max_element(body.collision.begin(), body.collision.end(), [](const auto& a, const auto& b) {
    return a.box_size.x() * a.box_size.y() < b.box_size.x() * b.box_size.y();
  });
  EXPECT_TRUE(top->box_size.isApprox(Vec3(1.2, 0.8, 0.04), 1e-15));
  EXPECT_NEAR(top->origin.position.z() + top->box_size.z() / 2, 0.75, 1e-9);
  for (const Geometry& box : body.collision) EXPECT_GE(box.origin.position.z() - box.box_size.z() / 2, -1e-12);

  // 20 kg spread uniformly over the boxes: centre of mass and inertia about it by the parallel-axis theorem.
  const double mass = 20;
  double volume = 0;
  for (const Geometry& box : body.collision) volume += box.box_size.prod();
  Vec3 center = Vec3::Zero();
  for (const Geometry& box : body.collision) center += mass * box.box_size.prod() / volume * box.origin.position;
  center /= mass;
  Mat3 inertia = Mat3::Zero();
  for (const Geometry& box : body.collision) {
    const double m = mass * box.box_size.prod() / volume;
    const Vec3 d = box.origin.position - center;
    inertia += BoxInertia(m, box.box_size) + m * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
  }
  EXPECT_EQ(body.inertial.mass, mass);
  EXPECT_TRUE(body.inertial.center_of_mass.isApprox(center, 1e-9));
  EXPECT_LT((body.inertial.inertia - inertia).cwiseAbs().maxCoeff(), 1e-9 * inertia.norm());
}

TEST(BuiltinModelsTest, Pg70InertiasMatchTheirBoxes) {
  const RobotDescription pg70 = LoadBuiltin("schunk_pg70");
  for (const BodySpec& link : pg70.links) {
    ASSERT_EQ(link.collision.size(), 1u) << link.id;
    const Geometry& box = link.collision[0];
    EXPECT_TRUE(link.inertial.center_of_mass.isApprox(box.origin.position, 1e-12)) << link.id;
    const Mat3 expected = BoxInertia(link.inertial.mass, box.box_size);
    EXPECT_LT((link.inertial.inertia - expected).cwiseAbs().maxCoeff(), 1e-9 * expected.norm()) << link.id;
  }
}

}  // namespace
}  // namespace graspsim
