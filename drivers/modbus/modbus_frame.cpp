#include "drivers/modbus/modbus_frame.h"

namespace graspsim::drivers::modbus {
namespace {

void PutU16(std::vector<uint8_t>& out, uint16_t value) {
  out.push_back(static_cast<uint8_t>(value >> 8));
  out.push_back(static_cast<uint8_t>(value & 0xFF));
}

}  // namespace

uint16_t Crc16(std::span<const uint8_t> bytes) {
  uint16_t crc = 0xFFFF;
  for (uint8_t byte : bytes) {
    crc ^= byte;
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) ? static_cast<uint16_t>((crc >> 1) ^ 0xA001) : crc >> 1;
  }
  return crc;
}

std::vector<uint8_t> ReadRegistersRequest(uint8_t function, uint16_t address, uint16_t count) {
  std::vector<uint8_t> pdu{function};
  PutU16(pdu, address);
  PutU16(pdu, count);
  return pdu;
}

std::vector<uint8_t> ReadRegistersResponse(uint8_t function, std::span<const uint16_t> values) {
  std::vector<uint8_t> pdu{function, static_cast<uint8_t>(2 * values.size())};
  for (uint16_t value : values) PutU16(pdu, value);
  return pdu;
}

std::vector<uint8_t> WriteRegistersRequest(uint16_t address, std::span<const uint16_t> values) {
  std::vector<uint8_t> pdu{kWriteMultipleRegisters};
  PutU16(pdu, address);
  PutU16(pdu, static_cast<uint16_t>(values.size()));
  pdu.push_back(static_cast<uint8_t>(2 * values.size()));
  for (uint16_t value : values) PutU16(pdu, value);
  return pdu;
}

std::vector<uint8_t> WriteRegistersResponse(uint16_t address, uint16_t count) {
  std::vector<uint8_t> pdu{kWriteMultipleRegisters};
  PutU16(pdu, address);
  PutU16(pdu, count);
  return pdu;
}

std::vector<uint8_t> ExceptionResponse(uint8_t function, uint8_t exception_code) {
  return {static_cast<uint8_t>(function | 0x80), exception_code};
}

std::vector<uint8_t> RtuFrame(uint8_t unit, std::span<const uint8_t> pdu) {
  std::vector<uint8_t> frame{unit};
  frame.insert(frame.end(), pdu.begin(), pdu.end());
  const uint16_t crc = Crc16(frame);
  frame.push_back(static_cast<uint8_t>(crc & 0xFF));  // RTU sends the CRC low byte first
  frame.push_back(static_cast<uint8_t>(crc >> 8));
  return frame;
}

std::optional<std::vector<uint8_t>> ParseRtuFrame(uint8_t unit, std::span<const uint8_t> frame) {
  if (frame.size() < 4 || frame[0] != unit) return std::nullopt;
  const uint16_t crc = Crc16(frame.first(frame.size() - 2));
  if (frame[frame.size() - 2] != (crc & 0xFF) || frame[frame.size() - 1] != (crc >> 8)) return std::nullopt;
  return std::vector<uint8_t>(frame.begin() + 1, frame.end() - 2);
}

std::vector<uint8_t> TcpFrame(uint16_t transaction, uint8_t unit, std::span<const uint8_t> pdu) {
  std::vector<uint8_t> frame;
  PutU16(frame, transaction);
  PutU16(frame, 0);  // protocol identifier: 0 is Modbus
  PutU16(frame, static_cast<uint16_t>(pdu.size() + 1));
  frame.push_back(unit);
  frame.insert(frame.end(), pdu.begin(), pdu.end());
  return frame;
}

}  // namespace graspsim::drivers::modbus
