// graspsim's engine, split as MuJoCo splits mjModel from mjData (DESIGN.md, "Model and state apart"): what the
// engine builds from a SceneModel once — the degrees of freedom, every body's surface samples and mesh BVHs, the
// tactile pads' sensing elements and BVHs, each body's and pad's contact law — is a SimulationModel, immutable and
// shared read-only by every Simulation of that SceneModel (a scene's own, a pick-and-place execution's, a
// simulated gripper's). A Simulation (physics/simulation.h) keeps only its step's working buffers; the state it
// advances is the caller's SceneState.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "collision/contact_finder.h"
#include "physics/contact_law.h"
#include "physics/multibody.h"
#include "tactile/ray_caster.h"
#include "world/model.h"

namespace graspsim {

class SimulationModel {
 public:
  explicit SimulationModel(std::shared_ptr<const SceneModel> model);
  SimulationModel(const SimulationModel&) = delete;
  SimulationModel& operator=(const SimulationModel&) = delete;

  const std::shared_ptr<const SceneModel>& scene() const { return scene_; }
  const Multibody& multibody() const { return multibody_; }
  const ContactFinder& finder() const { return finder_; }
  const TactileRayCaster& pads() const { return pads_; }
  const std::vector<ContactParams>& body_params() const { return body_params_; }  // per body: materials + defaults
  const std::vector<ContactParams>& pad_params() const { return pad_params_; }    // per pad: its law per element
  const std::vector<uint32_t>& pad_links() const { return pad_links_; }          // per pad: the body it is on

 private:
  std::shared_ptr<const SceneModel> scene_;
  Multibody multibody_;
  ContactFinder finder_;
  TactileRayCaster pads_;
  std::vector<ContactParams> body_params_;
  std::vector<ContactParams> pad_params_;
  std::vector<uint32_t> pad_links_;
};

// The SimulationModel of `model`: the one already built for this SceneModel object while any simulation still
// uses it, else a new one. Thread-safe; the process keeps no model alive (entries are weak).
std::shared_ptr<const SimulationModel> SharedSimulationModel(const std::shared_ptr<const SceneModel>& model);

}  // namespace graspsim
