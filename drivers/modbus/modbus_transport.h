// A Modbus master link: read and write holding registers of one unit. The interface keeps device logic free of
// libmodbus so it can be driven by any link; LibmodbusTransport is the real one, over TCP or RTU (serial).
// Every failure throws DeviceError naming the link, the operation and the cause, e.g.
// "modbus rtu /dev/ttyUSB0 unit 9: read 3 registers at 0x07D0: timed out after 200 ms".
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace graspsim::drivers::modbus {

class ModbusTransport {
 public:
  virtual ~ModbusTransport() = default;
  virtual void ReadRegisters(uint16_t address, std::span<uint16_t> out) = 0;  // function 0x03
  virtual void WriteRegisters(uint16_t address, std::span<const uint16_t> values) = 0;  // function 0x10
  virtual std::string Describe() const = 0;
};

struct LinkTimeouts {
  std::chrono::milliseconds response{200};  // whole answer
  std::chrono::milliseconds byte{50};       // gap between bytes of one answer (RTU)
};

struct TcpEndpoint {
  std::string host = "127.0.0.1";
  int port = 502;
  uint8_t unit = 9;
  LinkTimeouts timeouts;
};

// Serial line settings of the Robotiq 2F-85: 115200 baud, 8 data bits, no parity, 1 stop bit, unit 9.
struct RtuEndpoint {
  std::string device;  // e.g. /dev/ttyUSB0, or the slave side of a pseudo-terminal
  int baud = 115200;
  char parity = 'N';
  int data_bits = 8;
  int stop_bits = 1;
  uint8_t unit = 9;
  LinkTimeouts timeouts;
};

// Connects immediately; throws DeviceError(kIo) when the link cannot be opened.
std::unique_ptr<ModbusTransport> ConnectTcp(const TcpEndpoint& endpoint);
std::unique_ptr<ModbusTransport> ConnectRtu(const RtuEndpoint& endpoint);

}  // namespace graspsim::drivers::modbus
