// The one packed-array codec of the gRPC edge (rpc/packed_arrays.h): values go out as their little-endian bytes
// back to back and come back equal; a bytes field that is not a whole number of elements is refused naming the
// field, its length and the element; rows and float32 points pack as the wire documents.
#include "rpc/packed_arrays.h"

#include <array>
#include <cmath>

#include <gtest/gtest.h>

#include "core/math.h"
#include "test_util.h"

namespace graspsim::rpc {
namespace {

using test_util::ExpectError;

TEST(PackedArrays, ValuesGoOutLittleEndianAndComeBackEqual) {
  EXPECT_EQ(Pack(std::vector<uint32_t>{1, 0x01020304}), std::string("\x01\x00\x00\x00\x04\x03\x02\x01", 8));
  EXPECT_EQ(Pack(std::vector<uint16_t>{0x0fff}), std::string("\xff\x0f", 2));
  const std::vector<double> poses = {0.5, -1e-300, NAN, INFINITY, 7};
  const std::vector<double> back = Unpack<double>("body_poses", Pack(poses));
  ASSERT_EQ(back.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_TRUE(back[i] == poses[i] || (std::isnan(back[i]) && std::isnan(poses[i]))) << i;
  }
  using Triangle = std::array<uint32_t, 3>;
  const std::vector<Triangle> triangles = {{0, 1, 2}, {2, 3, 0}};
  EXPECT_EQ(Unpack<Triangle>("triangles", Pack(triangles)), triangles);
  const std::vector<Eigen::Vector3f> vertices = {{1, 2, 3}, {-0.5f, 0, 1e-7f}};
  EXPECT_EQ(Pack(vertices).size(), 24u);
  EXPECT_EQ(Unpack<Eigen::Vector3f>("vertices", Pack(vertices)), vertices);
  EXPECT_TRUE(Pack(std::vector<float>{}).empty());
  EXPECT_TRUE(Unpack<float>("depth", "").empty());
}

TEST(PackedArrays, AFieldThatIsNotWholeElementsIsNamed) {
  ExpectError([] { Unpack<double>("joint_positions", std::string(12, '\0')); }, ErrorCode::kInvalidArgument,
              {"joint_positions: 12 bytes is not a multiple of 8 (float64)"});
  ExpectError([] { Unpack<Eigen::Vector3f>("object.mesh.vertices", std::string(13, '\0'), "three float32 per vertex"); },
              ErrorCode::kInvalidArgument, {"object.mesh.vertices: 13 bytes is not a multiple of 12 (three float32 per vertex)"});
  ExpectError([] { UnpackFloat32Xyz<Vec3>("cloud.points", std::string(8, '\0')); }, ErrorCode::kInvalidArgument,
              {"cloud.points: 8 bytes", "(float32 x y z per point)"});
  EXPECT_EQ(PackedCount("depth", 16, 4, "float32"), 4u);
}

TEST(PackedArrays, RowsAndPointsPackAsTheWireSays) {
  const std::vector<Eigen::VectorXd> rows = {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 5, 6)};
  EXPECT_EQ(Unpack<double>("waypoints", PackRows(rows)), (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_TRUE(PackRows(std::vector<Eigen::VectorXd>{}).empty());
  const std::vector<Vec3> points = {Vec3(0.1, 0.2, 0.3), Vec3(-1, 0, 1e3)};
  const std::string packed = PackFloat32Xyz(points);
  EXPECT_EQ(packed.size(), 24u);
  EXPECT_EQ(Unpack<float>("points", packed), (std::vector<float>{0.1f, 0.2f, 0.3f, -1, 0, 1e3f}));
  const std::vector<Vec3> back = UnpackFloat32Xyz<Vec3>("points", packed);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_LT((back[0] - points[0]).norm(), 1e-7);
  EXPECT_EQ(back[1], points[1]);
}

}  // namespace
}  // namespace graspsim::rpc
