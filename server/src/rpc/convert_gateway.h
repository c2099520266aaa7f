// Translation between graspsim.v1 gateway messages and the hub's plain values (gateway/gateway_types.h).
// FromProto validates at the boundary and throws Error naming the field and the bad value.
#pragma once

#include "gateway/gateway_types.h"
#include "graspsim/v1/gateway.pb.h"

namespace graspsim::rpc {

gateway::DeviceInfo DeviceFromProto(const v1::Device& device);
gateway::DeviceReading ReadingFromProto(const v1::DeviceReading& reading);
gateway::CommandResult ResultFromProto(const v1::CommandResult& result);
// A scripter's command: needs device_id and one command; values must be finite (the gateway checks limits).
gateway::Command CommandFromProto(const v1::DeviceCommand& command);
gateway::Move MoveFromProto(const std::string& field, const v1::Move& move);

void ToProto(const gateway::DeviceInfo& device, v1::Device* out);
void ToProto(const gateway::DeviceReading& reading, v1::DeviceReading* out);
void ToProto(const gateway::CommandResult& result, v1::CommandResult* out);
void ToProto(const gateway::Command& command, v1::DeviceCommand* out);

}  // namespace graspsim::rpc
