// A Robotiq 2F-85 on a real Modbus link, served by libmodbus in a thread of its own: as a Modbus TCP server on
// 127.0.0.1 (a free port chosen by the kernel), or as an RTU device (unit 9) on the master side of a
// pseudo-terminal pair whose slave side the driver opens like a serial port. Behaviour comes from RobotiqModel,
// advanced by the time elapsed between loop turns. Only the registers of the 2F-85 exist: any other address
// answers ILLEGAL DATA ADDRESS, any other function ILLEGAL FUNCTION, as the device does.
//
// Fault injection for the tests, applied to the next `count` requests:
//   kNoReply      the request takes effect but no answer is sent (a lost answer: the master times out)
//   kException    no effect; a Modbus exception answer with the given code
//   kWrongCount   the request takes effect; the answer is well framed but its register count is wrong
//   kBadCrc       (RTU) the request takes effect; the answer's CRC is corrupted
//   kTruncated    the request takes effect; only the first half of the answer is sent (the master times out
//                 waiting for the rest)
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "drivers/emulators/robotiq_model.h"

typedef struct _modbus modbus_t;
typedef struct _modbus_mapping_t modbus_mapping_t;

namespace graspsim::drivers::emulators {

enum class ReplyFault { kNone, kNoReply, kException, kWrongCount, kBadCrc, kTruncated };

class RobotiqEmulator {
 public:
  // port 0: a free port chosen by the kernel (see port()).
  static std::unique_ptr<RobotiqEmulator> StartTcp(RobotiqModel::Options options, int port = 0);
  static std::unique_ptr<RobotiqEmulator> StartRtu(RobotiqModel::Options options);
  ~RobotiqEmulator();

  int port() const { return port_; }                           // TCP
  const std::string& device() const { return device_; }        // RTU: the pty slave path for the driver
  void InjectFault(ReplyFault fault, int count = 1, uint8_t exception_code = 4);

  robotiq::Command command() const;
  robotiq::Status status() const;
  bool moving() const;
  double opening_mm() const;
  void set_object(std::optional<double> opening_mm);
  void raise_fault(uint8_t gFLT);
  int requests_served() const { return requests_.load(); }

 private:
  explicit RobotiqEmulator(RobotiqModel::Options options);
  void Run();
  void Handle(const uint8_t* query, int length);
  bool SendFaulty(const uint8_t* query, ReplyFault fault);

  mutable std::mutex mutex_;  // guards model_ and the fault injection
  RobotiqModel model_;
  ReplyFault fault_ = ReplyFault::kNone;
  int fault_count_ = 0;
  uint8_t exception_code_ = 4;

  bool rtu_ = false;
  modbus_t* ctx_ = nullptr;
  modbus_mapping_t* mapping_ = nullptr;
  int listen_fd_ = -1;   // TCP
  int client_fd_ = -1;   // TCP connection or pty master
  int pty_slave_fd_ = -1;  // held open so the master never sees a hang-up between driver sessions
  int port_ = 0;
  std::string device_;
  std::atomic<bool> stop_{false};
  std::atomic<int> requests_{0};
  std::thread thread_;
};

}  // namespace graspsim::drivers::emulators
