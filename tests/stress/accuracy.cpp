// The analytic checks of accuracy.h; the set-ups are those of simulation_test.cpp, with the time step and the
// integrator free.
#include "stress/accuracy.h"

#include <chrono>
#include <cmath>

#include "core/error.h"
#include "physics/simulation.h"
#include "stress/sweep.h"

namespace graspsim::stress {
namespace {

constexpr double kG = 9.81;

struct World {
  std::shared_ptr<SceneModel> model = std::make_shared<SceneModel>();
  SceneState state;
  void Add(BodySpec body, const Vec3& position) {
    model->bodies.push_back(std::move(body));
    state.body_poses.push_back({position, Quat::Identity()});
  }
};

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Accuracy SettleAccuracy(Integrator integrator, double time_step) {
  World world;
  SimulationParams& params = world.model->simulation;
  params.integrator = integrator;
  params.time_step = time_step;
  params.contact.stiffness = 1e4;
  params.contact.damping = 20;
  params.sleep_time = 0;
  params.sample_spacing = 0.05;  // the pole alone touches (see simulation_test.cpp)
  const double m = 0.5, r = 0.03;
  world.Add(TableBody(), Vec3::Zero());
  world.Add(SphereBody("ball", r, m), Vec3(0, 0, r));
  world.model->Reindex();
  Simulation simulation(world.model);
  simulation.PrepareState(&world.state);
  Accuracy out;
  out.steps = std::lround(3.0 / time_step);
  const auto start = std::chrono::steady_clock::now();
  double deepest = 0;
  try {
    for (long i = 0; i < out.steps; ++i) {
      simulation.Step(&world.state, 1);
      deepest = std::max(deepest, r - world.state.body_poses[1].position.z());
    }
  } catch (const Error& error) {
    out.error = error.what();
  }
  out.seconds = Since(start);
  if (out.error.empty() && simulation.contacts().size() != 1) out.error = "contacts != 1";
  const double k = 1e4 / 2, c = 20.0 / 2, d_s = m * kG / k;
  const double zeta = c / (2 * std::sqrt(k * m));
  out.rel_error = std::abs((r - world.state.body_poses[1].position.z()) / d_s - 1);
  out.peak_rel_error = std::abs(deepest / (d_s * (1 + std::exp(-zeta * M_PI / std::sqrt(1 - zeta * zeta)))) - 1);
  return out;
}

Accuracy StribeckAccuracy(Integrator integrator, double time_step) {
  const double mu_s = 0.6, mu_d = 0.4, v_s = 1e-2, c_t = 0.05, normal = 1.0 * kG;
  Accuracy out;
  for (double speed : {1e-4, 1e-3, 1e-2, 1e-1, 1.0}) {
    // A 1e5 kg slider under weak gravity (normal force 9.81 N): friction barely changes its velocity in a step,
    // so the slip is the imposed speed (simulation_test.cpp, SteadyFriction).
    World world;
    SimulationParams& params = world.model->simulation;
    const double m = 1e5, r = 0.03;
    params.integrator = integrator;
    params.time_step = time_step;
    params.gravity = Vec3(0, 0, -normal / m);
    params.sample_spacing = 0.05;
    params.contact.stiffness = 1e4;
    params.contact.damping = 50;
    params.contact.viscous_friction = c_t;
    params.contact.stribeck_velocity = v_s;
    params.sleep_time = 0;
    world.Add(TableBody(), Vec3::Zero());
    world.Add(SphereBody("slider", r, m), Vec3(-0.5, 0, r - normal / 5e3));
    world.model->Reindex();
    Simulation simulation(world.model);
    simulation.PrepareState(&world.state);
    const long steps = std::lround(std::max(0.5, 3e-3 / speed) / time_step);  // ≥ 5 bristle lengths of slip
    const auto start = std::chrono::steady_clock::now();
    try {
      for (long i = 0; i < steps; ++i) {
        world.state.body_velocities[1] = {Vec3(speed, 0, world.state.body_velocities[1].linear.z()), Vec3::Zero()};
        simulation.Step(&world.state, 1);
      }
    } catch (const Error& error) {
      out.error = error.what();
    }
    out.seconds += Since(start);
    out.steps += steps;
    if (out.error.empty() && simulation.contacts().size() != 1) out.error = "contacts != 1 at v = " + std::to_string(speed);
    if (!out.error.empty()) break;
    const double g = normal * (mu_d + (mu_s - mu_d) * std::exp(-speed * speed / (v_s * v_s)));
    const double friction = -simulation.contact_forces().at(0).x();
    const double error = std::abs(friction / (g + c_t * speed) - 1);
    if (error > out.rel_error) out.worst_speed = speed;
    out.rel_error = std::max(out.rel_error, error);
  }
  return out;
}

}  // namespace graspsim::stress
