// The physics engines a scene can run on, behind one interface (the seed's Physics Abstraction Layer): the world
// model is compiled once per engine (a new model, a new engine), the scene's state is the one SceneState, and
// a step reads the state in, advances it and writes it back with the contacts it found.
//   - graspsim (physics/simulation.h): soft penalty + LuGre contacts at surface samples, Featherstone
//     multibody, four integrators; every capability (tactile pads, joint wrenches, sleeping, drives). Its
//     compiled model is shared by all simulations of one SceneModel (physics/simulation_model.h).
//   - MuJoCo (physics/mujoco_engine.cpp, Debian's libmujoco 2.2.2): its soft constraints (default solref and
//     solimp), elliptic friction cones, mesh geometry by its convex hull; drives by graspsim's motor model.
//   - Bullet (physics/bullet_engine.cpp, Debian's libbullet 3.24, double precision): rigid contacts by sequential
//     impulses, Featherstone btMultiBody robots, convex hulls of moving meshes; drives by graspsim's motor model.
// Tactile pads on MuJoCo and Bullet: physics/pad_readout.h. A capability an engine lacks is refused with FAILED_PRECONDITION naming it (CheckEngineSupports).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "collision/contact_finder.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim {

struct StepStats {
  size_t contacts = 0;      // contact points in the last sub-step
  size_t awake_bodies = 0;  // free bodies integrated in the last sub-step
};

class PhysicsEngine {
 public:
  virtual ~PhysicsEngine() = default;
  virtual const SceneModel& model() const = 0;
  // Sizes a state's velocity, sleep and sensor arrays for this model (new entries zero).
  virtual void PrepareState(SceneState* state) const = 0;
  // What a step call records at its end besides the motion: the sensors' readings (joint wrenches, pad forces)
  // and the contact list viewers draw (SceneState::contacts). kSkip leaves them as they were, for a caller that
  // steps again before anything reads them (the work cycle between its control periods and frames); an engine
  // that gets them for free may record them anyway.
  enum class Readings { kRecord, kSkip };
  // Advances `steps` steps. On divergence throws Error(kFailedPrecondition) naming what diverged and leaves
  // *state as it was before the call.
  virtual StepStats Step(SceneState* state, int steps, Readings readings) = 0;
  StepStats Step(SceneState* state, int steps) { return Step(state, steps, Readings::kRecord); }
  // The contact points and their forces (on body_a, world, N) of the last sub-step.
  virtual const std::vector<ContactPoint>& contacts() const = 0;
  virtual const std::vector<Vec3>& contact_forces() const = 0;
};

// "graspsim", "mujoco", "bullet".
std::string EngineName(PhysicsEngineKind kind);

// Throws Error(kFailedPrecondition) naming the first capability of `model` that engine `kind` lacks.
void CheckEngineSupports(const SceneModel& model, PhysicsEngineKind kind);

// Sizes a state for an engine that keeps no sleep, pad or joint-wrench state of its own (MuJoCo, Bullet): those
// read as awake, empty and zero.
void PrepareStateWithoutExtras(const SceneModel& model, SceneState* state);

// The engine model.simulation.engine names, compiled for `model` (CheckEngineSupports first).
std::shared_ptr<PhysicsEngine> MakePhysicsEngine(std::shared_ptr<const SceneModel> model);

}  // namespace graspsim
