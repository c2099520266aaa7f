#include "motion/exact_checker.h"

#include <algorithm>

namespace graspsim::motion {

ExactChecker::ExactChecker(const SceneModel& model, const SceneState& state, const ArmModel& arm,
                           const ArmSphereModel& spheres, const std::vector<std::string>& ignore, double spacing)
    : arm_(arm), model_(std::make_unique<SceneModel>()) {
  for (const ArmLink& link : arm.links()) {
    BodySpec body = model.bodies[link.body];
    body.robot_id.clear();  // ContactFinder skips pairs within one robot; the self pairs are filtered below
    body.motion = BodyMotion::kFree;
    model_->bodies.push_back(std::move(body));
  }
  const auto ignored = [&](const std::string& id) {
    return !id.empty() && std::find(ignore.begin(), ignore.end(), id) != ignore.end();
  };
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    BodySpec body = model.bodies[b];
    if (body.robot_id == arm.robot_id() || ignored(body.id) || ignored(body.robot_id)) continue;
    body.robot_id.clear();
    body.motion = BodyMotion::kStatic;
    model_->bodies.push_back(std::move(body));
    poses_.push_back(state.body_poses[b]);
  }
  // Arm links first in poses_ too.
  poses_.insert(poses_.begin(), arm.links().size(), Pose());
  model_->Reindex();
  finder_ = std::make_unique<ContactFinder>(*model_, ContactFinderOptions{spacing, 0});
  self_pair_.assign(arm.links().size(), std::vector<bool>(arm.links().size(), false));
  for (const auto& [a, b] : spheres.self_pairs) self_pair_[a][b] = self_pair_[b][a] = true;
  for (int group : spheres.group) base_link_.push_back(group < 0);
}

ExactChecker::~ExactChecker() = default;

std::string ExactChecker::Explain(const Eigen::Ref<const VecX>& q) const {
  if (!arm_.WithinLimits(q)) return "outside the joint limits";
  arm_.LinkTransforms(q, &links_);
  for (size_t l = 0; l < links_.size(); ++l) poses_[l] = links_[l].ToPose();
  contacts_.clear();
  finder_->Find(poses_, &contacts_);
  const size_t arm_links = links_.size();
  for (const ContactPoint& c : contacts_) {
    if (c.depth <= 0) continue;
    const bool a_arm = c.body_a < arm_links, b_arm = c.body_b < arm_links;
    if (a_arm && b_arm && !self_pair_[c.body_a][c.body_b]) continue;
    if (!a_arm && !b_arm) continue;
    if ((a_arm && !b_arm && base_link_[c.body_a]) || (b_arm && !a_arm && base_link_[c.body_b])) continue;  // mounting
    return model_->bodies[c.body_a].id + " touches " + model_->bodies[c.body_b].id;
  }
  return "";
}

}  // namespace graspsim::motion
