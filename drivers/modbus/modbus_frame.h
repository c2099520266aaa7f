// Modbus application data units, built and checked without any I/O. libmodbus does the framing on the live link;
// these functions exist so tests can compare against the byte sequences printed in device manuals and so the
// emulators can send deliberately broken answers (bad CRC, wrong counts) that libmodbus would never produce.
// References: Modbus Application Protocol V1.1b3 (PDUs, exception codes), Modbus over Serial Line V1.02 (RTU:
// unit, PDU, CRC-16 polynomial 0xA001 reflected, low byte first), Modbus Messaging on TCP/IP V1.0b (MBAP header:
// transaction id, protocol id 0, length of unit + PDU).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace graspsim::drivers::modbus {

inline constexpr uint8_t kReadHoldingRegisters = 0x03;
inline constexpr uint8_t kReadInputRegisters = 0x04;
inline constexpr uint8_t kWriteMultipleRegisters = 0x10;

uint16_t Crc16(std::span<const uint8_t> bytes);

// PDUs (function code first). Register values are big-endian on the wire.
std::vector<uint8_t> ReadRegistersRequest(uint8_t function, uint16_t address, uint16_t count);
std::vector<uint8_t> ReadRegistersResponse(uint8_t function, std::span<const uint16_t> values);
std::vector<uint8_t> WriteRegistersRequest(uint16_t address, std::span<const uint16_t> values);
std::vector<uint8_t> WriteRegistersResponse(uint16_t address, uint16_t count);
std::vector<uint8_t> ExceptionResponse(uint8_t function, uint8_t exception_code);

// Serial line: unit, PDU, CRC low byte, CRC high byte.
std::vector<uint8_t> RtuFrame(uint8_t unit, std::span<const uint8_t> pdu);
// The PDU of an RTU frame addressed to `unit` with a valid CRC; nullopt for anything else.
std::optional<std::vector<uint8_t>> ParseRtuFrame(uint8_t unit, std::span<const uint8_t> frame);
// TCP: MBAP (transaction, protocol 0, length, unit) then the PDU.
std::vector<uint8_t> TcpFrame(uint16_t transaction, uint8_t unit, std::span<const uint8_t> pdu);

}  // namespace graspsim::drivers::modbus
