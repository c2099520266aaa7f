// The gateway's Modbus decoding (drivers/modbus/modbus_frame.h ParseRtuFrame) and the Robotiq 2F-85 register map
// it carries (drivers/robotiq/robotiq_registers.h). The first byte is the unit the frame must be addressed to,
// the rest one RTU frame. Checked beyond "no crash":
//   - ParseRtuFrame(unit, RtuFrame(unit, pdu)) gives back pdu for any non-empty pdu (here: the input's bytes; a
//     PDU holds at least its function code);
//   - a read-registers answer (function 0x03/0x04, byte count, 3 registers) decodes as Robotiq status and command,
//     and encoding what was decoded and decoding again gives the same fields.
#include <span>

#include "drivers/modbus/modbus_frame.h"
#include "drivers/robotiq/robotiq_registers.h"
#include "fuzz_common.h"

namespace modbus = graspsim::drivers::modbus;
namespace robotiq = graspsim::drivers::robotiq;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const uint8_t unit = data[0];
  const std::span<const uint8_t> frame(data + 1, size - 1);

  const auto pdu = modbus::ParseRtuFrame(unit, frame);
  const auto again = modbus::ParseRtuFrame(unit, modbus::RtuFrame(unit, frame));
  if (!frame.empty() && (!again || !std::equal(again->begin(), again->end(), frame.begin(), frame.end()))) {
    graspsim::fuzz::Broken("ParseRtuFrame(RtuFrame(pdu)) != pdu");
  }
  if (!pdu) return 0;
  const std::vector<uint8_t>& p = *pdu;
  if (p.size() == 2 + 2 * robotiq::kRegisterCount &&
      (p[0] == modbus::kReadHoldingRegisters || p[0] == modbus::kReadInputRegisters) &&
      p[1] == 2 * robotiq::kRegisterCount) {
    robotiq::Registers registers;
    for (int i = 0; i < robotiq::kRegisterCount; ++i) registers[i] = uint16_t(p[2 + 2 * i] << 8 | p[3 + 2 * i]);
    const robotiq::Status status = robotiq::DecodeStatus(registers);
    if (robotiq::DecodeStatus(robotiq::EncodeStatus(status)) != status) {
      graspsim::fuzz::Broken("robotiq status does not survive encode/decode");
    }
    (void)robotiq::FaultName(status.gFLT);
    const robotiq::Command command = robotiq::DecodeCommand(registers);
    if (robotiq::DecodeCommand(robotiq::EncodeCommand(command)) != command) {
      graspsim::fuzz::Broken("robotiq command does not survive encode/decode");
    }
  }
  return 0;
}
