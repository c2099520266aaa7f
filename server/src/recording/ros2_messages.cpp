#include "recording/ros2_messages.h"

#include <cmath>
#include <cstring>

namespace graspsim::recording::ros2 {
namespace {

#define ROS2_SEPARATOR "================================================================================\n"
#define ROS2_HEADER                                                                     \
  ROS2_SEPARATOR "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n" \
  ROS2_SEPARATOR "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
#define ROS2_VECTOR3 ROS2_SEPARATOR "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"

// CDR: a 4-byte encapsulation header (CDR_LE), then each primitive aligned to its size, counted from the end of
// the header; strings are a uint32 length that counts the terminating NUL, the bytes, the NUL; sequences a
// uint32 count and the elements.
class Cdr {
 public:
  Cdr() { out_.assign({'\0', '\1', '\0', '\0'}); }
  template <typename T>
  void Put(T v) {
    while ((out_.size() - 4) % sizeof(T)) out_.push_back('\0');
    char bytes[sizeof(T)];
    std::memcpy(bytes, &v, sizeof(T));  // x86-64 and aarch64 are little endian, like CDR_LE
    out_.append(bytes, sizeof(T));
  }
  void PutString(const std::string& s) {
    Put<uint32_t>(static_cast<uint32_t>(s.size() + 1));
    out_.append(s);
    out_.push_back('\0');
  }
  void PutHeader(const Stamp& stamp, const std::string& frame_id) {
    Put<int32_t>(stamp.sec);
    Put<uint32_t>(stamp.nanosec);
    PutString(frame_id);
  }
  void PutVec3(const Vec3& v) {
    for (int i = 0; i < 3; ++i) Put<double>(v[i]);
  }
  void PutDoubles(const std::vector<double>& values) {
    Put<uint32_t>(static_cast<uint32_t>(values.size()));
    for (double v : values) Put<double>(v);
  }
  std::string Take() { return std::move(out_); }

 private:
  std::string out_;
};

}  // namespace

const MessageType kTFMessage{
    "tf2_msgs/msg/TFMessage",
    "geometry_msgs/TransformStamped[] transforms\n" ROS2_SEPARATOR
    "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\nTransform transform\n"
    ROS2_HEADER ROS2_SEPARATOR "MSG: geometry_msgs/Transform\nVector3 translation\nQuaternion rotation\n"
    ROS2_VECTOR3 ROS2_SEPARATOR "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"};
const MessageType kJointState{
    "sensor_msgs/msg/JointState",
    "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n" ROS2_HEADER};
const MessageType kFloat32MultiArray{
    "std_msgs/msg/Float32MultiArray",
    "MultiArrayLayout layout\nfloat32[] data\n" ROS2_SEPARATOR
    "MSG: std_msgs/MultiArrayLayout\nMultiArrayDimension[] dim\nuint32 data_offset\n" ROS2_SEPARATOR
    "MSG: std_msgs/MultiArrayDimension\nstring label\nuint32 size\nuint32 stride\n"};
const MessageType kWrenchStamped{
    "geometry_msgs/msg/WrenchStamped",
    "std_msgs/Header header\nWrench wrench\n" ROS2_HEADER ROS2_SEPARATOR
    "MSG: geometry_msgs/Wrench\nVector3 force\nVector3 torque\n" ROS2_VECTOR3};

const MessageType kPointCloud2{
    "sensor_msgs/msg/PointCloud2",
    "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool is_bigendian\n"
    "uint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n" ROS2_HEADER ROS2_SEPARATOR
    "MSG: sensor_msgs/PointField\nuint8 INT8 = 1\nuint8 UINT8 = 2\nuint8 INT16 = 3\nuint8 UINT16 = 4\n"
    "uint8 INT32 = 5\nuint8 UINT32 = 6\nuint8 FLOAT32 = 7\nuint8 FLOAT64 = 8\nstring name\nuint32 offset\n"
    "uint8 datatype\nuint32 count\n"};

Stamp StampOf(double seconds) {
  const double whole = std::floor(seconds);
  Stamp stamp{static_cast<int32_t>(whole), static_cast<uint32_t>(std::llround((seconds - whole) * 1e9))};
  if (stamp.nanosec >= 1000000000u) {
    ++stamp.sec;
    stamp.nanosec -= 1000000000u;
  }
  return stamp;
}

std::string EncodeTFMessage(const Stamp& stamp, const std::vector<Transform>& transforms) {
  Cdr cdr;
  cdr.Put<uint32_t>(static_cast<uint32_t>(transforms.size()));
  for (const Transform& t : transforms) {
    cdr.PutHeader(stamp, t.parent);
    cdr.PutString(t.child);
    cdr.PutVec3(t.pose.position);
    const Quat& q = t.pose.orientation;
    for (double v : {q.x(), q.y(), q.z(), q.w()}) cdr.Put<double>(v);
  }
  return cdr.Take();
}

std::string EncodeJointState(const Stamp& stamp, const std::vector<std::string>& names,
                             const std::vector<double>& positions, const std::vector<double>& velocities,
                             const std::vector<double>& efforts) {
  Cdr cdr;
  cdr.PutHeader(stamp, "");
  cdr.Put<uint32_t>(static_cast<uint32_t>(names.size()));
  for (const std::string& name : names) cdr.PutString(name);
  cdr.PutDoubles(positions);
  cdr.PutDoubles(velocities);
  cdr.PutDoubles(efforts);
  return cdr.Take();
}

std::string EncodeFloat32MultiArray(unsigned rows, unsigned cols, const std::vector<float>& data) {
  Cdr cdr;
  cdr.Put<uint32_t>(2);
  cdr.PutString("rows");
  cdr.Put<uint32_t>(rows);
  cdr.Put<uint32_t>(rows * cols);
  cdr.PutString("cols");
  cdr.Put<uint32_t>(cols);
  cdr.Put<uint32_t>(cols);
  cdr.Put<uint32_t>(0);  // data_offset
  cdr.Put<uint32_t>(static_cast<uint32_t>(data.size()));
  for (float v : data) cdr.Put<float>(v);
  return cdr.Take();
}

std::string EncodePointCloud2(const Stamp& stamp, const std::string& frame_id, const std::vector<Vec3>& points) {
  constexpr uint8_t kFloat32 = 7;
  Cdr cdr;
  cdr.PutHeader(stamp, frame_id);
  cdr.Put<uint32_t>(1);  // height: unorganized
  cdr.Put<uint32_t>(static_cast<uint32_t>(points.size()));
  cdr.Put<uint32_t>(3);
  const char* names[] = {"x", "y", "z"};
  for (uint32_t i = 0; i < 3; ++i) {
    cdr.PutString(names[i]);
    cdr.Put<uint32_t>(4 * i);
    cdr.Put<uint8_t>(kFloat32);
    cdr.Put<uint32_t>(1);
  }
  cdr.Put<uint8_t>(0);  // is_bigendian
  cdr.Put<uint32_t>(12);
  cdr.Put<uint32_t>(static_cast<uint32_t>(12 * points.size()));
  cdr.Put<uint32_t>(static_cast<uint32_t>(12 * points.size()));
  for (const Vec3& p : points) {
    for (int i = 0; i < 3; ++i) {
      const float v = static_cast<float>(p[i]);
      char bytes[4];
      std::memcpy(bytes, &v, 4);
      for (char b : bytes) cdr.Put<uint8_t>(static_cast<uint8_t>(b));
    }
  }
  cdr.Put<uint8_t>(1);  // is_dense
  return cdr.Take();
}

std::string EncodeWrenchStamped(const Stamp& stamp, const std::string& frame_id, const Vec3& force,
                                const Vec3& torque) {
  Cdr cdr;
  cdr.PutHeader(stamp, frame_id);
  cdr.PutVec3(force);
  cdr.PutVec3(torque);
  return cdr.Take();
}

}  // namespace graspsim::recording::ros2
