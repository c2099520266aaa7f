// The test set-up of the tactile experiments (tests/cpp/physics, tests/stress/tactile_bench.cpp): a welded
// "sensor stand" — a robot with one link, no joints and no collision geometry, so only its pad touches anything —
// carrying a pad facing up at the origin; boxes to lay on it are test_objects::UniformBox (test_bodies.h).
#pragma once

#include <string>

#include "cpp/test_bodies.h"
#include "world/model.h"

namespace graspsim::test_objects {

// A DSA 9205-sized pad (14 × 6 texels at 3.4 mm, 4 mm of foam) on the stand's link, facing up at the origin.
inline TactileArraySpec StandPad(unsigned subdivision = 1) {
  TactileArraySpec pad;
  pad.id = "stand/pad";
  pad.body_id = "stand/base";
  pad.rows = 14;
  pad.cols = 6;
  pad.pitch = 0.0034;
  pad.thickness = 0.004;
  pad.subdivision = subdivision;
  return pad;
}

// Appends the stand (body "stand/base", robot "stand") carrying `pad` to `model` (Reindex is the caller's).
inline void AddPadStand(SceneModel* model, const TactileArraySpec& pad) {
  BodySpec stand;
  stand.id = "stand/base";
  stand.robot_id = "stand";
  stand.motion = BodyMotion::kArticulated;
  stand.inertial.mass = 1;
  stand.inertial.inertia = Mat3::Identity() * 1e-3;
  model->bodies.push_back(stand);
  model->tactile_arrays.push_back(pad);
  model->robots.push_back(RobotSpec{"stand", "test", "stand/base", {"stand/base"}, {}, {pad.id}});
}

}  // namespace graspsim::test_objects
