// Scenes for the motion suites: a built-in arm (with or without a hand) on the floor or a table.
#pragma once

#include <memory>
#include <string>

#include "core/limits.h"
#include "motion/arm.h"
#include "world/loaders.h"
#include "world/scene.h"

namespace graspsim::motion_test {

struct ArmScene {
  std::unique_ptr<Scene> scene;
  SceneView view;
};

// `model` a built-in robot placed as robot "arm" at `base`; `extra` runs on the scene before the view is taken.
template <typename Extra>
ArmScene MakeArmScene(const std::string& model, const Pose& base, Extra&& extra) {
  ArmScene out;
  out.scene = std::make_unique<Scene>("s", "s", Limits());
  out.scene->AddRobot("arm", "builtin:" + model, LoadUrdf(BuiltinModelUrdf(model), nullptr, Limits()), base);
  extra(out.scene.get());
  out.view = out.scene->View();
  return out;
}

inline ArmScene MakeArmScene(const std::string& model, const Pose& base = {}) {
  return MakeArmScene(model, base, [](Scene*) {});
}

}  // namespace graspsim::motion_test
