// Tactile pads as soft contacts (PAPERS.md part B, experiments 1 and 2): a load resting on a horizontal pad is
// carried by the pad's elements, whose normal forces add up to m g; an object dragged over the pad meets the
// LuGre steady-state friction of the pad's law.
#include <cmath>
#include <cstdlib>
#include <fstream>

#include <gtest/gtest.h>

#include "physics/pad_stand.h"
#include "physics/simulation.h"

namespace graspsim {
namespace {

constexpr double kG = 9.81;

// A welded "sensor stand" (a robot with one link and no joints, no collision geometry) carrying a DSA 9205-like
// pad facing up at the origin, and a free box lying on the foam.
struct PadWorld {
  std::shared_ptr<SceneModel> model = std::make_shared<SceneModel>();
  SceneState state;

  PadWorld(unsigned subdivision, double box_mass, const Vec3& box_size)
      : PadWorld(test_objects::StandPad(subdivision), box_mass, box_size) {}
  PadWorld(const TactileArraySpec& pad, double box_mass, const Vec3& box_size) {
    test_objects::AddPadStand(model.get(), pad);
    model->bodies.push_back(test_objects::UniformBox("box", box_size, box_mass));
    model->simulation.sleep_time = 0;
    model->Reindex();
    // The box's bottom face 1 µm into the foam: it settles from there.
    state.body_poses = {Pose(), {Vec3(0, 0, pad.thickness + box_size.z() / 2 - 1e-6), Quat::Identity()}};
    state.joint_positions.clear();
  }
  Simulation Start() {
    Simulation simulation(model);
    simulation.PrepareState(&state);
    return simulation;
  }
  Vec3 PadForce() const {
    Vec3 sum = Vec3::Zero();
    for (const Vec3& f : state.pad_forces.at(0)) sum += f;
    return sum;
  }
  size_t LoadedElements() const {
    size_t n = 0;
    for (const Vec3& f : state.pad_forces.at(0)) n += f.z() < 0;
    return n;
  }
};

TEST(TactileContactTest, StaticLoadIsCarriedByThePadAtEveryResolution) {
  // 0.2 kg on the pad, the box (3 × 6 cm) covering all of it: after settling the elements' normal forces add up
  // to m g within 0.5 %, and every element is loaded.
  for (unsigned subdivision : {1u, 2u, 4u}) {
    PadWorld world(subdivision, 0.2, Vec3(0.03, 0.06, 0.02));
    Simulation simulation = world.Start();
    simulation.Step(&world.state, 1000);
    const Vec3 force = world.PadForce();
    EXPECT_NEAR(-force.z() / (0.2 * kG), 1.0, 5e-3) << "subdivision " << subdivision;
    EXPECT_NEAR(std::hypot(force.x(), force.y()), 0, 1e-6 * kG);
    EXPECT_EQ(world.LoadedElements(), 84u * subdivision * subdivision);
    // The pad's stiffness is that of the undivided pad at every resolution: the same penetration.
    const double depth = 0.004 + 0.01 - world.state.body_poses[1].position.z();
    EXPECT_NEAR(depth / (0.2 * kG / (84 * 1e3)), 1.0, 0.01) << "subdivision " << subdivision;
  }
}

TEST(TactileContactTest, StaticLoadIsCarriedByFaceCentreAndCurvedPads) {
  // Elements at the triangles' centres (two per texel) and a curved fingertip (the pad wrapped around y at 5 cm):
  // the load still adds up to m g within 0.5 %. On the flat pad every element carries it; on the curved one only
  // the two columns next to the apex reach the box's flat face (the next ones fall 0.26 mm away).
  TactileArraySpec faces = test_objects::StandPad();
  faces.placement = PadElementPlacement::kFaceCentres;
  TactileArraySpec curved = test_objects::StandPad();
  curved.bend_radius_x = 0.05;
  struct Case {
    const char* name;
    TactileArraySpec pad;
    size_t loaded;
  };
  for (const Case& c : {Case{"face centres", faces, 168}, Case{"curved", curved, 28}}) {
    PadWorld world(c.pad, 0.1, Vec3(0.03, 0.06, 0.01));
    Simulation simulation = world.Start();
    simulation.Step(&world.state, 2000);
    const Vec3 force = world.PadForce();
    EXPECT_NEAR(-force.z() / (0.1 * kG), 1.0, 5e-3) << c.name;
    EXPECT_NEAR(std::hypot(force.x(), force.y()), 0, 1e-3 * kG) << c.name;
    EXPECT_EQ(world.LoadedElements(), c.loaded) << c.name;
  }
}

// The tangential force a box dragged over the pad at `speed` meets once the bristles have settled. The box is
// heavy (1e5 kg) under weak gravity (9.81 N on the pad) so one step's friction cannot change the imposed speed.
double DragForce(double speed) {
  const double mass = 1e5, normal = 1.0 * kG;
  PadWorld world(1, mass, Vec3(0.3, 0.06, 0.02));  // long enough to cover the pad over the whole drag
  world.model->simulation.gravity = Vec3(0, 0, -normal / mass);
  world.model->simulation.integrator = Integrator::kSemiImplicitEuler;
  world.state.body_poses[1].position.z() = 0.004 + 0.01 - normal / (84 * 1e3);  // at rest on the foam
  world.state.body_poses[1].position.x() = -0.05;
  Simulation simulation = world.Start();
  // 1 cm of slide: 20 bristle lengths g/σ0 of the soft foam (0.5 mm per element), so z has settled to 1e-8.
  const int steps = static_cast<int>(std::max(0.05, 1e-2 / speed) / 1e-3);
  for (int i = 0; i < steps; ++i) {
    world.state.body_velocities[1] = {Vec3(speed, 0, world.state.body_velocities[1].linear.z()), Vec3::Zero()};
    simulation.Step(&world.state, 1);
  }
  return world.PadForce().x();  // the pad is dragged along +x by the box
}

TEST(TactileContactTest, DraggedObjectTracesTheStribeckCurveOfThePadLaw) {
  // The pad's law (PAPERS.md part B): μs 0.9, μd 0.6, v_s 1 mm/s, c_t 0: F = g(v) = N (μd + (μs − μd) e^{−v²/vs²}).
  const double normal = kG, mu_s = 0.9, mu_d = 0.6, v_s = 1e-3;
  for (double speed : {1e-4, 5e-4, 1e-3, 2e-3, 1e-2, 1e-1}) {
    const double expected = normal * (mu_d + (mu_s - mu_d) * std::exp(-speed * speed / (v_s * v_s)));
    EXPECT_NEAR(DragForce(speed) / expected, 1.0, 0.01) << "v = " << speed << " m/s";
  }
}

// Writes the pad's Stribeck curve (speed, measured force, LuGre steady state) as CSV for docs/tactile.md's plot:
//   GRASPSIM_STRIBECK_CSV=build/pad-stribeck.csv build/bin/graspsim_tests
//     --gtest_filter='TactileContact*WriteStribeckCurve' --gtest_also_run_disabled_tests  (one command)
//   build/venv/bin/python tests/stress/plot_pad_stribeck.py build/pad-stribeck.csv docs/tactile-stribeck.png
TEST(TactileContactTest, DISABLED_WriteStribeckCurve) {
  const char* path = std::getenv("GRASPSIM_STRIBECK_CSV");
  ASSERT_NE(path, nullptr) << "set GRASPSIM_STRIBECK_CSV";
  std::ofstream out(path);
  out << "speed_m_s,force_n,lugre_n\n";
  const double normal = kG, mu_s = 0.9, mu_d = 0.6, v_s = 1e-3;
  for (int i = 0; i <= 16; ++i) {
    const double speed = std::pow(10.0, -4 + 4.0 * i / 16);
    const double expected = normal * (mu_d + (mu_s - mu_d) * std::exp(-speed * speed / (v_s * v_s)));
    out << speed << "," << DragForce(speed) << "," << expected << "\n";
  }
}

}  // namespace
}  // namespace graspsim
