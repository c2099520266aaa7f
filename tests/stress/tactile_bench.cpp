// graspsim_tactile_bench: the in-process figures of `tests/bench/run tactile` as one JSON object (stdout; progress
// on stderr). Wall times are reported, never judged.
//
//   "static_load": per time step dt ∈ {1e-4, 3e-4, 1e-3, 3e-3, 5e-3} s × pad subdivision s ∈ {1, 2, 4}: a 0.2 kg box
//                  (3 × 6 cm, covering the whole pad) resting on a DSA 9205-like pad (6 × 14 texels, 3.4 mm
//                  pitch, 4 mm foam) on a welded stand, as in tests/cpp/physics/tactile_contact_test.cpp; after
//                  1 s of simulated time the relative error of the elements' normal-force sum against m g, and the
//                  wall time of that second (its realtime factor).
//   "grasp":       the built-in schunk_pg70 (two DSA 9205 pads, 84 elements each) pointing down over a table, its
//                  fingers closed on a 5 cm, 0.1 kg cube by the PG70 drive (velocity mode, 1 A current limit, as in
//                  tests/bench/physics.py); then 2000 timed steps at dt = 1 ms: ms per step, the rays the pads cast
//                  per step (TactileRayCaster::last_ray_count of a caster on the same model and poses), rays per
//                  second of whole steps, and rays per second of the cast alone (the same Cast timed separately:
//                  the Simulation's own caster is private).
//   "cycle":       the work cycle (workcycle/work_cycle.h) in process, no gRPC: the built-in
//                  schunk_pg70_on_z_axis over the table and the 5 cm, 0.1 kg cube, full coverage, 50 frames/s, a
//                  hold that makes the cycle the paper's 45 s; per time step dt ∈ {1, 2, 5} ms: wall time, realtime
//                  factor, lift and slip of the cube (hold), and the pads' sum mismatch over the hold.
//   "cells":       the cells (texels) of the 6 × 14 pad that report a load (DSACON32 intensity > 0) with a box
//                  pressed on it by its weight, against the texels whose centres lie under the box: the 3 × 6 cm
//                  box covering the pad, and a 2 cm cube on its centre.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "cpp/physics/pad_stand.h"
#include "core/error.h"
#include "physics/actuators.h"
#include "physics/simulation.h"
#include "stress/sweep.h"
#include "tactile/ray_caster.h"
#include "tactile/tactile_frame.h"
#include "workcycle/work_cycle.h"
#include "import/robot_import.h"
#include "world/loaders.h"
#include "world/scene.h"

namespace graspsim {
namespace {

constexpr double kG = 9.81;

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A welded stand carrying a pad facing up at the origin and a free box lying on its foam (the set-up of
// tactile_contact_test.cpp).
struct PadWorld {
  std::shared_ptr<SceneModel> model = std::make_shared<SceneModel>();
  SceneState state;

  PadWorld(unsigned subdivision, double box_mass, const Vec3& box_size, double time_step) {
    const TactileArraySpec pad = test_objects::StandPad(subdivision);
    test_objects::AddPadStand(model.get(), pad);
    model->bodies.push_back(test_objects::UniformBox("box", box_size, box_mass));
    model->simulation.sleep_time = 0;
    model->simulation.time_step = time_step;
    model->Reindex();
    // The box's bottom face 1 µm into the foam: it settles from there.
    state.body_poses = {Pose(), {Vec3(0, 0, pad.thickness + box_size.z() / 2 - 1e-6), Quat::Identity()}};
  }
  double NormalForce() const {
    double sum = 0;
    for (const Vec3& f : state.pad_forces.at(0)) sum -= f.z();
    return sum;
  }
};

std::string Escape(const std::string& text) {
  std::string out;
  for (char ch : text) out += (ch == '"' || ch == '\\') ? '\'' : (ch == '\n' ? ' ' : ch);
  return out;
}

// One static-load point: 1 s of simulated time, error of the final normal-force sum against m g.
std::string StaticLoad(double dt, unsigned subdivision) {
  const double mass = 0.2;
  PadWorld world(subdivision, mass, Vec3(0.03, 0.06, 0.02), dt);
  Simulation simulation(world.model);
  simulation.PrepareState(&world.state);
  const long steps = std::lround(1.0 / dt);
  std::string error;
  const auto start = std::chrono::steady_clock::now();
  try {
    simulation.Step(&world.state, static_cast<int>(steps));
  } catch (const Error& e) {
    error = e.what();
  }
  const double seconds = Since(start);
  const double rel_error = std::abs(world.NormalForce() / (mass * kG) - 1);
  std::cerr << "static load dt=" << dt << " s=" << subdivision << ": error " << rel_error << " in " << seconds
            << " s " << error << "\n";
  std::ostringstream out;
  out.precision(6);
  out << "{\"dt\":" << dt << ",\"subdivision\":" << subdivision << ",\"elements\":" << 84 * subdivision * subdivision
      << ",\"steps\":" << steps << ",\"rel_error\":" << rel_error << ",\"seconds\":" << seconds
      << ",\"realtime_factor\":" << 1.0 / seconds << ",\"error\":\"" << Escape(error) << "\"}";
  return out.str();
}

// The built-in PG70 closed on a 5 cm cube: ms per step and rays per second.
std::string Grasp() {
  const double table_top = 0.0, cube = 0.05, timed_steps = 2000;
  Scene scene("bench", "tactile bench", Limits{});
  const RobotDescription pg70 =
      LoadUrdf(BuiltinModelUrdf("schunk_pg70"), [](const std::string&) { return nullptr; }, Limits{});
  // Half a turn about x: the approach axis (+z) points down; fingertips 1 cm above the table (physics.py).
  scene.AddRobot("pg70", "builtin:schunk_pg70", pg70, Pose{Vec3(0, 0, table_top + 0.01 + 0.157), Quat(0, 1, 0, 0)});
  scene.AddObject(stress::TableBody(), Pose{Vec3(0, 0, table_top), Quat::Identity()});
  scene.AddObject(stress::CubeBody("cube", cube, 0.1), Pose{Vec3(0, 0, table_top + cube / 2), Quat::Identity()});
  scene.SetJointPositions({{"pg70/finger_left_joint", 0.03}});
  const SceneView view = scene.View();
  auto model = std::make_shared<SceneModel>(*view.model);
  model->simulation.time_step = 1e-3;
  model->simulation.integrator = Integrator::kLinearlyImplicitEuler;
  SceneState state = view.state;
  Simulation simulation(model);
  simulation.PrepareState(&state);
  simulation.Step(&state, 300);  // the cube settles on the table
  const size_t finger = model->joint_index.at("pg70/finger_left_joint");
  JointActuator& drive = state.actuators[finger];
  drive.motor = Pg70DriveParams();
  drive.command = {ActuatorMode::kVelocity, -0.02, 1.0};  // closing at 20 mm/s, 1 A ≈ 57 N per finger
  simulation.Step(&state, 1000);

  TactileRayCaster caster(*model);
  std::vector<PadHit> hits;
  uint64_t rays = 0, hit_count = 0;
  double step_seconds = 0, cast_seconds = 0;
  StepStats stats;
  for (int i = 0; i < timed_steps; ++i) {
    auto start = std::chrono::steady_clock::now();
    stats = simulation.Step(&state, 1);
    step_seconds += Since(start);
    hits.clear();
    start = std::chrono::steady_clock::now();
    caster.Cast(state.body_poses, &hits);
    cast_seconds += Since(start);
    rays += caster.last_ray_count();
    hit_count += hits.size();
  }
  double left = 0, right = 0;
  for (size_t pad = 0; pad < model->tactile_arrays.size(); ++pad) {
    const TactileFrame frame = ReadTactileArray(*model, state, pad);
    (pad == 0 ? left : right) = static_cast<double>(frame.intensity_sum);
  }
  const double ms_per_step = step_seconds / timed_steps * 1e3;
  std::cerr << "grasp: " << ms_per_step << " ms/step, " << rays / timed_steps << " rays/step, "
            << hit_count / timed_steps << " hits/step, cast " << cast_seconds / timed_steps * 1e6 << " us/step, "
            << stats.contacts << " contacts; pad sums " << left << " / " << right << "\n";
  std::ostringstream out;
  out.precision(6);
  out << "{\"steps\":" << timed_steps << ",\"dt\":" << model->simulation.time_step
      << ",\"ms_per_step\":" << ms_per_step << ",\"realtime_factor\":" << 1e-3 / (ms_per_step * 1e-3)
      << ",\"rays_per_step\":" << rays / timed_steps << ",\"hits_per_step\":" << hit_count / timed_steps
      << ",\"rays_per_s_of_step\":" << rays / step_seconds << ",\"cast_us_per_step\":"
      << cast_seconds / timed_steps * 1e6 << ",\"rays_per_s_of_cast\":" << rays / cast_seconds
      << ",\"contacts\":" << stats.contacts << ",\"awake_bodies\":" << stats.awake_bodies
      << ",\"pad_sums\":[" << left << "," << right << "],\"finger_mm\":"
      << state.joint_positions[finger] * 1e3 << "}";
  return out.str();
}

// Texels reporting a load under a box pressed on the pad by its weight, and texels whose centres it covers.
std::string Cells(const char* name, const Vec3& box, double mass) {
  PadWorld world(1, mass, box, 1e-3);
  Simulation simulation(world.model);
  simulation.PrepareState(&world.state);
  simulation.Step(&world.state, 1000);
  const TactileFrame frame = ReadTactileArray(*world.model, world.state, 0);
  const TactileArraySpec& pad = world.model->tactile_arrays[0];
  int reporting = 0, covered = 0;
  for (unsigned r = 0; r < frame.rows; ++r) {
    for (unsigned c = 0; c < frame.cols; ++c) {
      reporting += frame.intensities[r * frame.cols + c] > 0;
      const double x = (c + 0.5 - pad.cols / 2.0) * pad.pitch, y = (r + 0.5 - pad.rows / 2.0) * pad.pitch;
      covered += std::abs(x) < box.x() / 2 && std::abs(y) < box.y() / 2;
    }
  }
  std::cerr << "cells (" << name << "): " << reporting << " of " << frame.rows * frame.cols << " report, "
            << covered << " covered; sum " << frame.intensity_sum << "\n";
  std::ostringstream out;
  out.precision(6);
  out << "{\"box\":\"" << name << "\",\"size\":[" << box.x() << "," << box.y() << "," << box.z() << "],\"mass\":"
      << mass << ",\"cells\":" << frame.rows * frame.cols << ",\"cells_reporting\":" << reporting
      << ",\"cells_covered\":" << covered << ",\"intensity_sum\":" << frame.intensity_sum
      << ",\"normal_force\":" << -frame.force_sum.z() << "}";
  return out.str();
}

// The 45 s work cycle at time step dt, in process.
std::string Cycle(double dt, double coverage = 1, double setpoint = 60000) {
  const double table_top = 0.75, cube = 0.05, base_z = 1.05, cycle_seconds = 45, rest_seconds = 3.4;
  Scene scene("bench", "tactile cycle bench", Limits{});
  // The built-in table and cube as the server's AddObject builds them (rpc/scene_service.cpp).
  for (const char* name : {"table", "cube_5cm"}) {
    RobotDescription urdf = LoadUrdf(BuiltinModelUrdf(name), nullptr, Limits{});
    BodySpec body;
    body.id = name == std::string("table") ? "table" : "cube";
    body.collision = std::move(urdf.links.front().collision);
    body.inertial = urdf.links.front().inertial;
    body.motion = body.id == "table" ? BodyMotion::kStatic : BodyMotion::kFree;
    scene.AddObject(body, Pose{Vec3(0, 0, body.id == "table" ? 0 : table_top + cube / 2), Quat::Identity()});
  }
  scene.AddRobot("cell", "builtin:schunk_pg70_on_z_axis",
                 LoadUrdf(BuiltinModelUrdf("schunk_pg70_on_z_axis"), nullptr, Limits{}),
                 Pose{Vec3(0, 0, base_z), Quat::Identity()});
  const SceneView view = scene.View();
  auto model = std::make_shared<SceneModel>(*view.model);
  model->simulation.time_step = dt;
  SceneState state = view.state;
  Simulation simulation(model);
  WorkCycleRequest request;
  request.gripper_id = "cell";
  request.object_id = "cube";
  request.hold_time = cycle_seconds - rest_seconds;
  request.coverage = coverage;
  request.tactile_setpoint = setpoint;
  WorkCycle cycle(model, state, request);
  std::vector<WorkCycleFrame> frames;
  const double start_time = state.time;
  const auto start = std::chrono::steady_clock::now();
  std::string error;
  try {
    while (!cycle.done()) cycle.Advance(&simulation, &state, 1000, &frames);
  } catch (const Error& e) {
    error = e.what();
  }
  const double seconds = Since(start), simulated = state.time - start_time;
  if (getenv("DEBUG_FRAMES")) {
    for (const WorkCycleFrame& f : frames) {
      if (f.stage == WorkCycleStage::kHold && f.time > 6) continue;
      std::cerr << StageName(f.stage) << " t=" << f.time << " sums " << f.pads[0].intensity_sum << "/" << f.pads[1].intensity_sum
                << " finger " << f.gripper.finger_distance << " cube z " << f.object_pose.position.z() << " axis " << f.axis_position
                << " limit " << f.current_limit << " current " << f.gripper.motor_current << "\n";
    }
  }
  // Over the hold: the cube's height against the axis (slip), the pads' mismatch; lift from the grasp's end.
  double grasp_z = NAN, hold_first = NAN, hold_last = NAN, axis_first = NAN, axis_last = NAN, mismatch = 0;
  for (const WorkCycleFrame& frame : frames) {
    if (frame.stage == WorkCycleStage::kGrasp) grasp_z = frame.object_pose.position.z();
    if (frame.stage != WorkCycleStage::kHold) continue;
    const double z = frame.object_pose.position.z();
    if (std::isnan(hold_first)) hold_first = z, axis_first = frame.axis_position;
    hold_last = z, axis_last = frame.axis_position;
    const double left = double(frame.pads[0].intensity_sum), right = double(frame.pads[1].intensity_sum);
    mismatch = std::max(mismatch, std::abs(left - right) / std::max((left + right) / 2, 1e-12));
  }
  const double lift = hold_last - grasp_z, slip = (axis_last - axis_first) - (hold_last - hold_first);
  std::cerr << "cycle dt=" << dt << ": " << simulated << " s simulated in " << seconds << " s (" << simulated / seconds
            << " x), lift " << lift * 1e3 << " mm, slip " << slip * 1e3 << " mm, mismatch " << mismatch << " "
            << error << "\n";
  std::ostringstream out;
  out.precision(6);
  out << "{\"dt\":" << dt << ",\"simulated_s\":" << simulated << ",\"seconds\":" << seconds
      << ",\"realtime_factor\":" << simulated / seconds << ",\"lift_mm\":" << lift * 1e3 << ",\"slip_mm\":"
      << slip * 1e3 << ",\"hold_mismatch_max\":" << mismatch << ",\"frames\":" << frames.size()
      << ",\"error\":\"" << Escape(error) << "\"}";
  return out.str();
}

}  // namespace
}  // namespace graspsim

int main(int argc, char** argv) {
  using namespace graspsim;
  // "graspsim_tactile_bench cycle [dt [coverage [set-point]]]": only the in-process work cycle (for profiling).
  if (argc > 1 && std::string(argv[1]) == "cycle") {
    std::cout << Cycle(argc > 2 ? std::stod(argv[2]) : 1e-3, argc > 3 ? std::stod(argv[3]) : 1,
                       argc > 4 ? std::stod(argv[4]) : 60000)
              << std::endl;
    return 0;
  }
  std::ostringstream out;
  out << "{\"static_load\":[";
  bool first = true;
  for (double dt : {1e-4, 3e-4, 1e-3, 3e-3, 5e-3}) {
    for (unsigned subdivision : {1u, 2u, 4u}) {
      out << (first ? "" : ",") << StaticLoad(dt, subdivision);
      first = false;
    }
  }
  out << "],\"grasp\":" << Grasp();
  out << ",\"cycle\":[" << Cycle(1e-3) << "," << Cycle(2e-3) << "," << Cycle(5e-3) << "]";
  out << ",\"cells\":[" << Cells("covering", Vec3(0.03, 0.06, 0.02), 0.2) << ","
      << Cells("cube_2cm", Vec3(0.02, 0.02, 0.02), 0.2) << "]}";
  std::cout << out.str() << std::endl;
  return 0;
}
