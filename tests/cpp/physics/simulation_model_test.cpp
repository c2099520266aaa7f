// The model/state split of graspsim's engine (physics/simulation_model.h): one SimulationModel per SceneModel,
// shared by every Simulation of it, and no state of a scene kept in it or in a Simulation between steps.
#include "physics/simulation_model.h"

#include <gtest/gtest.h>

#include "physics/pad_stand.h"
#include "physics/simulation.h"
#include "test_bodies.h"

namespace graspsim {
namespace {

// The tactile stand's pad with a box dropped on it from 2 mm, so contacts, bristles and pad readings all change
// from step to step.
std::shared_ptr<const SceneModel> PadScene() {
  auto model = std::make_shared<SceneModel>();
  test_objects::AddPadStand(model.get(), test_objects::StandPad());
  model->bodies.push_back(test_objects::UniformBox("box", Vec3(0.02, 0.03, 0.02), 0.1));
  model->simulation.sleep_time = 0;
  model->Reindex();
  return model;
}

SceneState DroppedFrom(double height) {
  SceneState state;
  state.body_poses = {Pose(), {Vec3(0.001, -0.002, 0.004 + 0.01 + height), Quat::Identity()}};
  return state;
}

TEST(SimulationModelTest, SimulationsOfOneSceneModelShareItsCompiledModel) {
  // Two simulations of one SceneModel object build it once; another SceneModel object (equal or not) gets its own;
  // once no simulation uses it, nothing keeps it alive.
  std::shared_ptr<const SceneModel> model = PadScene();
  std::weak_ptr<const SimulationModel> compiled;
  {
    Simulation first(model), second(model);
    compiled = SharedSimulationModel(model);
    EXPECT_EQ(SharedSimulationModel(model).get(), compiled.lock().get());
    EXPECT_NE(SharedSimulationModel(PadScene()).get(), compiled.lock().get());
  }
  EXPECT_TRUE(compiled.expired());
}

TEST(SimulationModelTest, SimulationsSharingAModelStepTheirOwnStatesAsIfAlone) {
  // Two scenes of one model stepped in turn, by two simulations on the shared model and by one simulation taking
  // both states, end bit for bit where each ends stepped alone on a model of its own: nothing of one scene's step
  // stays in the model or in the simulation for the other's.
  std::shared_ptr<const SceneModel> model = PadScene();
  auto alone = [](double height) {
    Simulation simulation(PadScene());
    SceneState state = DroppedFrom(height);
    simulation.PrepareState(&state);
    for (int i = 0; i < 300; ++i) simulation.Step(&state, 1);
    return state;
  };
  const SceneState a_alone = alone(0.002), b_alone = alone(0.0005);

  Simulation a_simulation(model), b_simulation(model);
  SceneState a = DroppedFrom(0.002), b = DroppedFrom(0.0005), a_shared = a, b_shared = b;
  for (SceneState* state : {&a, &b, &a_shared, &b_shared}) a_simulation.PrepareState(state);
  for (int i = 0; i < 300; ++i) {
    a_simulation.Step(&a, 1);
    b_simulation.Step(&b, 1);
    a_simulation.Step(&a_shared, 1);  // one simulation, both states in turn
    a_simulation.Step(&b_shared, 1);
  }
  for (const SceneState* state : {&a, &a_shared}) {
    EXPECT_EQ(state->body_poses[1].position, a_alone.body_poses[1].position);
    EXPECT_EQ(state->pad_forces[0], a_alone.pad_forces[0]);
  }
  for (const SceneState* state : {&b, &b_shared}) {
    EXPECT_EQ(state->body_poses[1].position, b_alone.body_poses[1].position);
    EXPECT_EQ(state->pad_forces[0], b_alone.pad_forces[0]);
  }
  EXPECT_NE(a.body_poses[1].position, b.body_poses[1].position);  // the two scenes differ
}

}  // namespace
}  // namespace graspsim
