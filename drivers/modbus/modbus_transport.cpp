// libmodbus masters. libmodbus reports everything through errno: ETIMEDOUT for a missing answer, MODBUS_ENOBASE
// + code for an exception answer, EMBBADCRC / EMBBADDATA / EMBMDATA / EMBBADSLAVE / EMBBADEXC / EMBUNKEXC for
// answers that do not parse. Those map onto DeviceFailure here, once.
#include "drivers/modbus/modbus_transport.h"

#include <cerrno>
#include <cstdio>
#include <sstream>

#include <modbus.h>

#include "drivers/common/device_error.h"

namespace graspsim::drivers::modbus {
namespace {

DeviceFailure Classify(int error) {
  if (error == ETIMEDOUT) return DeviceFailure::kTimeout;
  if (error > MODBUS_ENOBASE && error <= EMBXGTAR) return DeviceFailure::kDeviceException;
  if (error == EMBBADCRC || error == EMBBADDATA || error == EMBMDATA || error == EMBBADSLAVE ||
      error == EMBBADEXC || error == EMBUNKEXC) {
    return DeviceFailure::kMalformedFrame;
  }
  return DeviceFailure::kIo;
}

std::string Hex(uint16_t value) {
  char text[8];
  std::snprintf(text, sizeof(text), "0x%04X", value);
  return text;
}

class LibmodbusTransport : public ModbusTransport {
 public:
  LibmodbusTransport(modbus_t* ctx, std::string name, LinkTimeouts timeouts) : ctx_(ctx), name_(std::move(name)) {
    timeouts_ = timeouts;
  }
  ~LibmodbusTransport() override {
    modbus_close(ctx_);
    modbus_free(ctx_);
  }

  void Connect(uint8_t unit) {
    modbus_set_slave(ctx_, unit);
    const auto set = [](auto setter, modbus_t* ctx, std::chrono::milliseconds t) {
      setter(ctx, static_cast<uint32_t>(t.count() / 1000), static_cast<uint32_t>(t.count() % 1000 * 1000));
    };
    set(modbus_set_response_timeout, ctx_, timeouts_.response);
    set(modbus_set_byte_timeout, ctx_, timeouts_.byte);
    if (modbus_connect(ctx_) != 0) Fail("connect", errno);
  }

  void ReadRegisters(uint16_t address, std::span<uint16_t> out) override {
    const int n = modbus_read_registers(ctx_, address, static_cast<int>(out.size()), out.data());
    if (n != static_cast<int>(out.size())) {
      Fail("read " + std::to_string(out.size()) + " registers at " + Hex(address), n < 0 ? errno : EMBBADDATA);
    }
  }

  void WriteRegisters(uint16_t address, std::span<const uint16_t> values) override {
    const int n = modbus_write_registers(ctx_, address, static_cast<int>(values.size()), values.data());
    if (n != static_cast<int>(values.size())) {
      Fail("write " + std::to_string(values.size()) + " registers at " + Hex(address), n < 0 ? errno : EMBBADDATA);
    }
  }

  std::string Describe() const override { return name_; }

 private:
  [[noreturn]] void Fail(const std::string& operation, int error) {
    const DeviceFailure failure = Classify(error);
    std::ostringstream message;
    message << name_ << ": " << operation << ": ";
    if (failure == DeviceFailure::kTimeout) {
      message << "timed out after " << timeouts_.response.count() << " ms";
    } else if (failure == DeviceFailure::kDeviceException) {
      message << "modbus exception " << (error - MODBUS_ENOBASE) << " (" << modbus_strerror(error) << ")";
    } else {
      message << modbus_strerror(error);
    }
    throw DeviceError(failure, message.str());
  }

  modbus_t* ctx_;
  std::string name_;
  LinkTimeouts timeouts_;
};

}  // namespace

std::unique_ptr<ModbusTransport> ConnectTcp(const TcpEndpoint& endpoint) {
  modbus_t* ctx = modbus_new_tcp(endpoint.host.c_str(), endpoint.port);
  std::string name = "modbus tcp " + endpoint.host + ":" + std::to_string(endpoint.port) + " unit " +
                     std::to_string(endpoint.unit);
  if (ctx == nullptr) throw DeviceError(DeviceFailure::kIo, name + ": cannot create context");
  auto transport = std::make_unique<LibmodbusTransport>(ctx, std::move(name), endpoint.timeouts);
  transport->Connect(endpoint.unit);
  return transport;
}

std::unique_ptr<ModbusTransport> ConnectRtu(const RtuEndpoint& endpoint) {
  modbus_t* ctx = modbus_new_rtu(endpoint.device.c_str(), endpoint.baud, endpoint.parity, endpoint.data_bits,
                                 endpoint.stop_bits);
  std::string name = "modbus rtu " + endpoint.device + " unit " + std::to_string(endpoint.unit);
  if (ctx == nullptr) throw DeviceError(DeviceFailure::kIo, name + ": invalid serial settings");
  auto transport = std::make_unique<LibmodbusTransport>(ctx, std::move(name), endpoint.timeouts);
  transport->Connect(endpoint.unit);
  return transport;
}

}  // namespace graspsim::drivers::modbus
