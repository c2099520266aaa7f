// ROS 2 messages in CDR (recording/ros2_messages.h), byte for byte against small cases worked out by hand from the
// CDR rules rosbag2 stores (XCDR1, little endian): a 4-byte encapsulation header 00 01 00 00; every primitive
// aligned to its own size counted from the end of that header; a string is a uint32 length that counts its NUL,
// the bytes and the NUL; a sequence is a uint32 count and the elements. Offsets in the comments are from the end of
// the header. (The Python suite reads whole recorded bags with rosbags, an independent decoder; this is the
// byte-exact regression.)
#include "recording/ros2_messages.h"

#include <cstdint>
#include <initializer_list>
#include <string>

#include <gtest/gtest.h>

namespace graspsim::recording::ros2 {
namespace {

std::string Bytes(std::initializer_list<uint8_t> bytes) { return std::string(bytes.begin(), bytes.end()); }

std::string Hex(const std::string& bytes) {
  static const char kDigits[] = "0123456789abcdef";
  std::string out;
  for (size_t i = 0; i < bytes.size(); ++i) {
    const auto b = static_cast<uint8_t>(bytes[i]);
    out += (i % 8 == 4) ? " | " : " ";  // "|" after the header, then every 8 bytes
    out += kDigits[b >> 4];
    out += kDigits[b & 15];
  }
  return out;
}

#define EXPECT_BYTES(actual, expected) EXPECT_EQ(Hex(actual), Hex(expected))

TEST(Ros2Messages, TFMessageOfOneTransform) {
  Transform t;
  t.parent = "w";
  t.child = "b";
  t.pose.position = Vec3(1, 2, 3);
  t.pose.orientation = Quat(0.5, -0.5, 0.5, -0.5);  // w x y z; written x y z w
  const std::string expected = Bytes({
      0x00, 0x01, 0x00, 0x00,                          // CDR_LE
      0x01, 0x00, 0x00, 0x00,                          // 0: transforms: 1
      0x01, 0x00, 0x00, 0x00,                          // 4: header.stamp.sec 1
      0x02, 0x00, 0x00, 0x00,                          // 8: header.stamp.nanosec 2
      0x02, 0x00, 0x00, 0x00, 'w', 0x00,               // 12: header.frame_id "w" (length 2 with the NUL)
      0x00, 0x00,                                      // 18: pad to 4
      0x02, 0x00, 0x00, 0x00, 'b', 0x00,               // 20: child_frame_id "b"
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00,              // 26: pad to 8
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xf0, 0x3f,  // 32: translation.x 1.0
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x40,  // 40: translation.y 2.0
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0x40,  // 48: translation.z 3.0
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xe0, 0xbf,  // 56: rotation.x -0.5
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xe0, 0x3f,  // 64: rotation.y 0.5
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xe0, 0xbf,  // 72: rotation.z -0.5
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xe0, 0x3f,  // 80: rotation.w 0.5
  });
  EXPECT_BYTES(EncodeTFMessage({1, 2}, {t}), expected);
  EXPECT_BYTES(EncodeTFMessage({1, 2}, {}), Bytes({0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}));
}

TEST(Ros2Messages, JointStatePadsBeforeEachSequenceOfDoubles) {
  const std::string expected = Bytes({
      0x00, 0x01, 0x00, 0x00,                          // CDR_LE
      0x03, 0x00, 0x00, 0x00,                          // 0: header.stamp.sec 3
      0x00, 0x65, 0xcd, 0x1d,                          // 4: header.stamp.nanosec 500000000 = 0x1dcd6500
      0x01, 0x00, 0x00, 0x00, 0x00,                    // 8: header.frame_id "" (length 1: the NUL)
      0x00, 0x00, 0x00,                                // 13: pad to 4
      0x01, 0x00, 0x00, 0x00,                          // 16: name: 1
      0x06, 0x00, 0x00, 0x00, 'j', 'o', 'i', 'n', 't', 0x00,  // 20: "joint"
      0x00, 0x00,                                      // 30: pad to 4
      0x01, 0x00, 0x00, 0x00,                          // 32: position: 1
      0x00, 0x00, 0x00, 0x00,                          // 36: pad to 8
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xd0, 0x3f,  // 40: 0.25
      0x00, 0x00, 0x00, 0x00,                          // 48: velocity: 0
      0x01, 0x00, 0x00, 0x00,                          // 52: effort: 1
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xf0, 0xbf,  // 56: -1.0 (already aligned)
  });
  EXPECT_BYTES(EncodeJointState({3, 500000000}, {"joint"}, {0.25}, {}, {-1.0}), expected);
}

TEST(Ros2Messages, Float32MultiArrayOfTwoRowsOfThree) {
  const std::string expected = Bytes({
      0x00, 0x01, 0x00, 0x00,                    // CDR_LE
      0x02, 0x00, 0x00, 0x00,                    // 0: layout.dim: 2
      0x05, 0x00, 0x00, 0x00, 'r', 'o', 'w', 's', 0x00,  // 4: dim[0].label "rows"
      0x00, 0x00, 0x00,                          // 13: pad to 4
      0x02, 0x00, 0x00, 0x00,                    // 16: dim[0].size 2
      0x06, 0x00, 0x00, 0x00,                    // 20: dim[0].stride 6 (rows x cols)
      0x05, 0x00, 0x00, 0x00, 'c', 'o', 'l', 's', 0x00,  // 24: dim[1].label "cols"
      0x00, 0x00, 0x00,                          // 33: pad to 4
      0x03, 0x00, 0x00, 0x00,                    // 36: dim[1].size 3
      0x03, 0x00, 0x00, 0x00,                    // 40: dim[1].stride 3
      0x00, 0x00, 0x00, 0x00,                    // 44: layout.data_offset 0
      0x06, 0x00, 0x00, 0x00,                    // 48: data: 6
      0x00, 0x00, 0x80, 0x3f,                    // 52: 1.0f
      0x00, 0x00, 0x00, 0x40,                    // 56: 2.0f
      0x00, 0x00, 0x40, 0x40,                    // 60: 3.0f
      0x00, 0x00, 0x80, 0x40,                    // 64: 4.0f
      0x00, 0x00, 0xa0, 0x40,                    // 68: 5.0f
      0x00, 0x00, 0x20, 0xc0,                    // 72: -2.5f
  });
  EXPECT_BYTES(EncodeFloat32MultiArray(2, 3, {1.0f, 2.0f, 3.0f, 4.0f, 5.0f, -2.5f}), expected);
}

TEST(Ros2Messages, WrenchStampedAlignsTheForceToEight) {
  const std::string expected = Bytes({
      0x00, 0x01, 0x00, 0x00,                          // CDR_LE
      0x07, 0x00, 0x00, 0x00,                          // 0: header.stamp.sec 7
      0x01, 0x00, 0x00, 0x00,                          // 4: header.stamp.nanosec 1
      0x03, 0x00, 0x00, 0x00, 'f', 't', 0x00,          // 8: header.frame_id "ft"
      0x00,                                            // 15: pad to 8
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xf0, 0x3f,  // 16: force.x 1.0
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x40,  // 24: force.y 2.0
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0x40,  // 32: force.z 3.0
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xf0, 0xbf,  // 40: torque.x -1.0
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xe0, 0x3f,  // 48: torque.y 0.5
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // 56: torque.z 0.0
  });
  EXPECT_BYTES(EncodeWrenchStamped({7, 1}, "ft", Vec3(1, 2, 3), Vec3(-1, 0.5, 0)), expected);
}

TEST(Ros2Messages, StampOfSplitsSecondsIntoWholeAndNanoseconds) {
  const auto expect = [](double seconds, int32_t sec, uint32_t nanosec) {
    const Stamp stamp = StampOf(seconds);
    EXPECT_EQ(stamp.sec, sec) << seconds;
    EXPECT_EQ(stamp.nanosec, nanosec) << seconds;
  };
  expect(0, 0, 0);
  expect(1.5, 1, 500000000);
  expect(0.017, 0, 17000000);
  expect(2.9999999999, 3, 0);  // rounds up to the next whole second, not to nanosec 1e9
  expect(-0.25, -1, 750000000);  // builtin_interfaces/Time: nanosec counts forward from sec
}

}  // namespace
}  // namespace graspsim::recording::ros2
