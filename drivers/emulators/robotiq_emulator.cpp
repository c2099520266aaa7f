#include "drivers/emulators/robotiq_emulator.h"

#include <fcntl.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <vector>

#include <modbus.h>

#include "drivers/modbus/modbus_frame.h"

namespace graspsim::drivers::emulators {
namespace {

using robotiq::kCommandAddress;
using robotiq::kRegisterCount;
using robotiq::kStatusAddress;

constexpr int kMapSize = kStatusAddress + kRegisterCount - kCommandAddress;

bool InBlock(int address, int count, int block) {
  return count >= 1 && address >= block && address + count <= block + kRegisterCount;
}

uint16_t U16(const uint8_t* bytes) { return static_cast<uint16_t>(bytes[0] << 8 | bytes[1]); }

}  // namespace

RobotiqEmulator::RobotiqEmulator(RobotiqModel::Options options) : model_(options) {
  // Registers exist at 0x03E8.. and 0x07D0..; Handle() refuses addresses between the two blocks.
  mapping_ = modbus_mapping_new_start_address(0, 0, 0, 0, kCommandAddress, kMapSize, kCommandAddress, kMapSize);
  if (mapping_ == nullptr) throw std::runtime_error("robotiq emulator: cannot allocate the register map");
}

std::unique_ptr<RobotiqEmulator> RobotiqEmulator::StartTcp(RobotiqModel::Options options, int port) {
  std::unique_ptr<RobotiqEmulator> emulator(new RobotiqEmulator(options));
  emulator->ctx_ = modbus_new_tcp("127.0.0.1", port);
  emulator->listen_fd_ = modbus_tcp_listen(emulator->ctx_, 1);
  if (emulator->listen_fd_ < 0) throw std::runtime_error("robotiq emulator: cannot listen on 127.0.0.1");
  sockaddr_in address{};
  socklen_t size = sizeof(address);
  getsockname(emulator->listen_fd_, reinterpret_cast<sockaddr*>(&address), &size);
  emulator->port_ = ntohs(address.sin_port);
  emulator->thread_ = std::thread([e = emulator.get()] { e->Run(); });
  return emulator;
}

std::unique_ptr<RobotiqEmulator> RobotiqEmulator::StartRtu(RobotiqModel::Options options) {
  std::unique_ptr<RobotiqEmulator> emulator(new RobotiqEmulator(options));
  emulator->rtu_ = true;
  const int master = posix_openpt(O_RDWR | O_NOCTTY);
  if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) {
    throw std::runtime_error("robotiq emulator: cannot open a pseudo-terminal");
  }
  emulator->client_fd_ = master;
  emulator->device_ = ptsname(master);
  emulator->pty_slave_fd_ = open(emulator->device_.c_str(), O_RDWR | O_NOCTTY);
  if (emulator->pty_slave_fd_ < 0) throw std::runtime_error("robotiq emulator: cannot open " + emulator->device_);
  termios raw{};
  tcgetattr(emulator->pty_slave_fd_, &raw);
  cfmakeraw(&raw);  // binary frames: no echo, no CR/LF translation (the driver's libmodbus sets the same)
  tcsetattr(emulator->pty_slave_fd_, TCSANOW, &raw);
  // libmodbus RTU on this end too: the context never opens a device, it is handed the master fd.
  emulator->ctx_ = modbus_new_rtu(emulator->device_.c_str(), 115200, 'N', 8, 1);
  modbus_set_slave(emulator->ctx_, robotiq::kDefaultUnit);
  modbus_set_socket(emulator->ctx_, master);
  emulator->thread_ = std::thread([e = emulator.get()] { e->Run(); });
  return emulator;
}

RobotiqEmulator::~RobotiqEmulator() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (client_fd_ >= 0) close(client_fd_);
  if (listen_fd_ >= 0) close(listen_fd_);
  if (pty_slave_fd_ >= 0) close(pty_slave_fd_);
  if (ctx_ != nullptr) modbus_free(ctx_);  // not modbus_close: the fds are closed above
  modbus_mapping_free(mapping_);
}

void RobotiqEmulator::InjectFault(ReplyFault fault, int count, uint8_t exception_code) {
  std::lock_guard lock(mutex_);
  fault_ = fault;
  fault_count_ = count;
  exception_code_ = exception_code;
}

robotiq::Command RobotiqEmulator::command() const { std::lock_guard lock(mutex_); return model_.command(); }
robotiq::Status RobotiqEmulator::status() const { std::lock_guard lock(mutex_); return model_.status(); }
bool RobotiqEmulator::moving() const { std::lock_guard lock(mutex_); return model_.moving(); }
double RobotiqEmulator::opening_mm() const { std::lock_guard lock(mutex_); return model_.opening_mm(); }
void RobotiqEmulator::set_object(std::optional<double> opening_mm) {
  std::lock_guard lock(mutex_);
  model_.set_object(opening_mm);
}

void RobotiqEmulator::raise_fault(uint8_t gFLT) {
  std::lock_guard lock(mutex_);
  model_.raise_fault(gFLT);
}

void RobotiqEmulator::Run() {
  std::vector<uint8_t> query(MODBUS_TCP_MAX_ADU_LENGTH);
  auto last = std::chrono::steady_clock::now();
  while (!stop_) {
    fd_set readable;
    FD_ZERO(&readable);
    int top = -1;
    for (int fd : {listen_fd_, client_fd_}) {
      if (fd < 0) continue;
      FD_SET(fd, &readable);
      top = std::max(top, fd);
    }
    timeval tick{0, 2000};  // 2 ms: the physics step and the stop-flag poll
    const int ready = select(top + 1, &readable, nullptr, nullptr, &tick);
    const auto now = std::chrono::steady_clock::now();
    {
      std::lock_guard lock(mutex_);
      model_.Step(std::chrono::duration<double>(now - last).count());
    }
    last = now;
    if (ready <= 0) continue;
    if (listen_fd_ >= 0 && FD_ISSET(listen_fd_, &readable)) {
      if (client_fd_ >= 0) close(client_fd_);  // one master at a time, like the gripper's TCP adapter
      client_fd_ = modbus_tcp_accept(ctx_, &listen_fd_);
      continue;
    }
    if (client_fd_ >= 0 && FD_ISSET(client_fd_, &readable)) {
      modbus_set_socket(ctx_, client_fd_);
      const int length = modbus_receive(ctx_, query.data());
      if (length > 0) {
        Handle(query.data(), length);
      } else if (length < 0 && !rtu_) {
        close(client_fd_);  // the master hung up (or sent garbage): wait for the next connection
        client_fd_ = -1;
      }
    }
  }
}

void RobotiqEmulator::Handle(const uint8_t* query, int length) {
  requests_++;
  const int offset = modbus_get_header_length(ctx_);
  const uint8_t function = query[offset];
  const int address = U16(query + offset + 1);
  const int count = U16(query + offset + 3);

  ReplyFault fault = ReplyFault::kNone;
  uint8_t exception_code = 0;
  {
    std::lock_guard lock(mutex_);
    if (fault_count_ > 0) {
      fault = fault_;
      exception_code = exception_code_;
      if (--fault_count_ == 0) fault_ = ReplyFault::kNone;
    }
  }
  if (fault == ReplyFault::kException) {
    modbus_reply_exception(ctx_, query, exception_code);
    return;
  }

  const bool write = function == modbus::kWriteMultipleRegisters;
  const bool read = function == modbus::kReadHoldingRegisters || function == modbus::kReadInputRegisters;
  if (!write && !read) {
    modbus_reply_exception(ctx_, query, MODBUS_EXCEPTION_ILLEGAL_FUNCTION);
    return;
  }
  const bool legal = write ? InBlock(address, count, kCommandAddress)
                           : InBlock(address, count, kCommandAddress) || InBlock(address, count, kStatusAddress);
  if (!legal) {
    modbus_reply_exception(ctx_, query, MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS);
    return;
  }

  std::lock_guard lock(mutex_);
  const robotiq::Registers status = model_.StatusRegisters();
  for (int i = 0; i < kRegisterCount; ++i) {
    const int slot = kStatusAddress - kCommandAddress + i;
    mapping_->tab_registers[slot] = mapping_->tab_input_registers[slot] = status[i];
  }
  if (fault == ReplyFault::kNone) {
    modbus_reply(ctx_, query, length, mapping_);
  } else {
    // The request still takes effect: what is lost or broken is only the answer.
    if (write) {
      const int first = address - kCommandAddress;
      for (int i = 0; i < count; ++i) mapping_->tab_registers[first + i] = U16(query + offset + 6 + 2 * i);
    }
    SendFaulty(query, fault);
  }
  if (write) {
    robotiq::Registers command{};
    for (int i = 0; i < kRegisterCount; ++i) command[i] = mapping_->tab_registers[i];
    model_.WriteCommand(command);
  }
}

bool RobotiqEmulator::SendFaulty(const uint8_t* query, ReplyFault fault) {
  if (fault == ReplyFault::kNoReply) return true;
  const int offset = modbus_get_header_length(ctx_);
  const uint8_t function = query[offset];
  const uint16_t address = U16(query + offset + 1);
  const uint16_t count = U16(query + offset + 3);
  // kWrongCount: one register fewer than asked. kBadCrc: the right answer with a broken checksum.
  const uint16_t answered = fault == ReplyFault::kWrongCount ? static_cast<uint16_t>(count - 1) : count;
  std::vector<uint8_t> pdu;
  if (function == modbus::kWriteMultipleRegisters) {
    pdu = modbus::WriteRegistersResponse(address, answered);
  } else {
    std::vector<uint16_t> values(answered);
    const int first = address - kCommandAddress;
    for (int i = 0; i < answered; ++i) values[i] = mapping_->tab_registers[first + i];
    pdu = modbus::ReadRegistersResponse(function, values);
  }
  std::vector<uint8_t> frame;
  if (rtu_) {
    frame = modbus::RtuFrame(query[0], pdu);
    if (fault == ReplyFault::kBadCrc) frame.back() ^= 0xFF;
  } else {
    frame = modbus::TcpFrame(U16(query), query[6], pdu);
  }
  if (fault == ReplyFault::kTruncated) frame.resize(frame.size() / 2);
  return write(client_fd_, frame.data(), frame.size()) == static_cast<ssize_t>(frame.size());
}

}  // namespace graspsim::drivers::emulators
