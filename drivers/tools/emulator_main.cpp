// graspsim-emulator: the gripper emulators as a process, for `make demo`, for bringing up the gateway without
// hardware, and for poking at them with any Modbus or CAN tool. Runs until SIGINT or SIGTERM.
//   graspsim-emulator robotiq-tcp [--port=N] [--object-mm=W]   Modbus TCP on 127.0.0.1 (N = 0: a free port)
//   graspsim-emulator robotiq-rtu [--object-mm=W]              Modbus RTU, unit 9, on a new pseudo-terminal
//   graspsim-emulator pg70 --can=IFACE [--id=N] [--object-mm=W]  SMP on a SocketCAN interface (e.g. vcan0)
//   graspsim-emulator pg70 --fd=FD [--id=N] [--object-mm=W]      SMP on an inherited descriptor carrying can_frame
//                                                                packets (a socketpair end; graspsim-gateway's pg70-fd)
// The first line on stdout says where it listens (port, pty path or interface), for scripts to read.
#include <linux/can.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "drivers/can/can_transport.h"
#include "drivers/common/device_error.h"
#include "drivers/emulators/pg70_emulator.h"
#include "drivers/emulators/robotiq_emulator.h"

namespace {

std::atomic<bool> g_stop{false};

std::optional<std::string> Flag(int argc, char** argv, const std::string& name) {
  const std::string prefix = "--" + name + "=";
  for (int i = 2; i < argc; ++i) {
    if (std::strncmp(argv[i], prefix.c_str(), prefix.size()) == 0) return std::string(argv[i] + prefix.size());
  }
  return std::nullopt;
}

int Usage() {
  std::fprintf(stderr,
               "usage: graspsim-emulator robotiq-tcp [--port=N] [--object-mm=W]\n"
               "       graspsim-emulator robotiq-rtu [--object-mm=W]\n"
               "       graspsim-emulator pg70 --can=IFACE|--fd=FD [--id=N] [--object-mm=W]\n");
  return 2;
}

void WaitForSignal() {
  std::signal(SIGINT, [](int) { g_stop = true; });
  std::signal(SIGTERM, [](int) { g_stop = true; });
  while (!g_stop) std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

}  // namespace

int main(int argc, char** argv) {
  using namespace graspsim::drivers;
  if (argc < 2) return Usage();
  const std::string kind = argv[1];
  const auto object = Flag(argc, argv, "object-mm");
  try {
    if (kind == "robotiq-tcp" || kind == "robotiq-rtu") {
      emulators::RobotiqModel::Options options;
      if (object) options.object_opening_mm = std::stod(*object);
      std::unique_ptr<emulators::RobotiqEmulator> emulator;
      if (kind == "robotiq-tcp") {
        emulator = emulators::RobotiqEmulator::StartTcp(options, std::stoi(Flag(argc, argv, "port").value_or("0")));
        std::printf("robotiq-tcp 127.0.0.1:%d unit 9\n", emulator->port());
      } else {
        emulator = emulators::RobotiqEmulator::StartRtu(options);
        std::printf("robotiq-rtu %s unit 9 115200 8N1\n", emulator->device().c_str());
      }
      std::fflush(stdout);
      WaitForSignal();
      return 0;
    }
    if (kind == "pg70") {
      const auto interface = Flag(argc, argv, "can");
      const auto fd = Flag(argc, argv, "fd");
      if (!interface == !fd) return Usage();
      emulators::Pg70Emulator::Options options;
      options.module_id = static_cast<uint8_t>(std::stoi(Flag(argc, argv, "id").value_or("12")));
      if (object) options.object_width_mm = std::stod(*object);
      const can_filter to_module{static_cast<canid_t>(pg70::smp::kToModule + options.module_id), CAN_SFF_MASK};
      emulators::Pg70Emulator emulator(fd ? std::stoi(*fd) : can::OpenSocketCan(*interface, &to_module, 1), options);
      std::printf("pg70 %s module %d\n", fd ? ("fd " + *fd).c_str() : interface->c_str(), options.module_id);
      std::fflush(stdout);
      WaitForSignal();
      return 0;
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "graspsim-emulator: %s\n", error.what());
    return 1;
  }
  return Usage();
}
