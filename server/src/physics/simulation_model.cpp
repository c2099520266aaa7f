#include "physics/simulation_model.h"

#include <mutex>
#include <unordered_map>
#include <utility>

#include "tactile/pad_contacts.h"

namespace graspsim {
namespace {

// A material's value, or the scene default where the material leaves it at 0.
double Or(double value, double fallback) { return value > 0 ? value : fallback; }

ContactParams BodyContactParams(const Material& material, const ContactParams& defaults) {
  ContactParams params = defaults;
  params.static_friction = material.static_friction;
  params.dynamic_friction = material.dynamic_friction;
  params.stiffness = Or(material.contact_stiffness, defaults.stiffness);
  params.damping = Or(material.contact_damping, defaults.damping);
  params.bristle_stiffness = Or(material.bristle_stiffness, defaults.bristle_stiffness);
  params.bristle_damping = Or(material.bristle_damping, defaults.bristle_damping);
  params.viscous_friction = Or(material.viscous_friction, defaults.viscous_friction);
  params.stribeck_velocity = Or(material.stribeck_velocity, defaults.stribeck_velocity);
  return params;
}

}  // namespace

SimulationModel::SimulationModel(std::shared_ptr<const SceneModel> model)
    : scene_(std::move(model)),
      multibody_(*scene_),
      finder_(*scene_, ContactFinderOptions{scene_->simulation.sample_spacing, 0}),
      pads_(*scene_) {
  for (const BodySpec& body : scene_->bodies) {
    body_params_.push_back(BodyContactParams(body.material, scene_->simulation.contact));
  }
  for (const TactileArraySpec& pad : scene_->tactile_arrays) {
    pad_params_.push_back(ElementContactParams(pad));
    pad_links_.push_back(static_cast<uint32_t>(scene_->body_index.at(pad.body_id)));
  }
}

std::shared_ptr<const SimulationModel> SharedSimulationModel(const std::shared_ptr<const SceneModel>& model) {
  // Keyed by the SceneModel's address: a live entry's SimulationModel holds its SceneModel, so the address cannot
  // be reused while the entry can still be locked. Building happens outside the lock (it samples every surface).
  static std::mutex mutex;
  static std::unordered_map<const SceneModel*, std::weak_ptr<const SimulationModel>> built;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (auto found = built.find(model.get()); found != built.end()) {
      if (std::shared_ptr<const SimulationModel> live = found->second.lock()) return live;
    }
  }
  auto fresh = std::make_shared<const SimulationModel>(model);
  std::lock_guard<std::mutex> lock(mutex);
  std::weak_ptr<const SimulationModel>& entry = built[model.get()];
  if (std::shared_ptr<const SimulationModel> live = entry.lock()) return live;  // another thread was first
  entry = fresh;
  for (auto it = built.begin(); it != built.end();) it = it->second.expired() ? built.erase(it) : std::next(it);
  return fresh;
}

}  // namespace graspsim
