#include "grasp/hand_collision.h"

#include <algorithm>
#include <cmath>

namespace graspsim::grasp {
namespace {

LinkBox Place(const LinkBox& box, const Pose& pose) {
  return {pose * box.centre, pose.orientation.toRotationMatrix() * box.axes, box.half};
}

bool LinkOverlaps(const HandModel& hand, int l, const Pose& pose, int m, const Pose& other, double margin) {
  for (const LinkBox& a : hand.links()[l].boxes) {
    for (const LinkBox& b : hand.links()[m].boxes) {
      if (BoxesOverlap(Place(a, pose), Place(b, other), margin)) return true;
    }
  }
  return false;
}

}  // namespace

bool SweptBoxOverlaps(const LinkBox& a, const Vec3& motion, const LinkBox& b, double margin) {
  const Vec3 d = b.centre - a.centre;
  auto separated = [&](const Vec3& axis) {
    const double length = axis.norm();
    if (length < 1e-12) return false;
    const Vec3 u = axis / length;
    const double ra = (a.axes.transpose() * u).cwiseAbs().dot(a.half);
    const double rb = (b.axes.transpose() * u).cwiseAbs().dot(b.half);
    // a's interval relative to a's start centre: [min(0, m) - ra, max(0, m) + ra]; b's: d ± rb.
    const double m = motion.dot(u), c = d.dot(u);
    const double overlap = std::min(std::max(0.0, m) + ra, c + rb) - std::max(std::min(0.0, m) - ra, c - rb);
    return overlap < -margin;
  };
  for (int i = 0; i < 3; ++i) {
    if (separated(a.axes.col(i)) || separated(b.axes.col(i)) || separated(a.axes.col(i).cross(motion)) ||
        separated(b.axes.col(i).cross(motion))) {
      return false;
    }
    for (int j = 0; j < 3; ++j) {
      if (separated(a.axes.col(i).cross(b.axes.col(j)))) return false;
    }
  }
  return true;
}

bool HandOverlapsObstacles(const HandModel& hand, const std::vector<Pose>& poses, const Vec3& motion,
                           const std::vector<ObstacleBox>& obstacles, double margin) {
  if (obstacles.empty()) return false;
  for (size_t l = 0; l < poses.size(); ++l) {
    for (const LinkBox& box : hand.links()[l].boxes) {
      const LinkBox placed = Place(box, poses[l]);
      for (const ObstacleBox& obstacle : obstacles) {
        if (SweptBoxOverlaps(placed, motion, obstacle, margin)) return true;
      }
    }
  }
  return false;
}

SelfCollision::SelfCollision(const HandModel& hand, double margin) : hand_(hand), margin_(margin) {
  const size_t links = hand.links().size();
  std::vector<std::vector<bool>> skip(links, std::vector<bool>(links, false));
  for (const HandJoint& joint : hand.joints()) {
    skip[joint.parent_link][joint.child_link] = skip[joint.child_link][joint.parent_link] = true;
  }
  std::vector<Pose> poses(links);
  for (size_t p = 0; p < hand.preshape_names().size(); ++p) {
    hand.LinkPoses(Pose(), hand.PreshapeJoints(p), &poses);
    for (size_t l = 0; l < links; ++l) {
      for (size_t m = l + 1; m < links; ++m) {
        if (LinkOverlaps(hand, l, poses[l], m, poses[m], margin)) skip[l][m] = skip[m][l] = true;
      }
    }
  }
  for (size_t l = 0; l < links; ++l) {
    for (size_t m = l + 1; m < links; ++m) {
      if (!skip[l][m] && !hand.links()[l].boxes.empty() && !hand.links()[m].boxes.empty()) {
        pairs_.push_back({static_cast<int>(l), static_cast<int>(m)});
      }
    }
  }
}

bool SelfCollision::Collides(const std::vector<Pose>& poses) const {
  return std::any_of(pairs_.begin(), pairs_.end(), [&](const std::pair<int, int>& p) {
    return LinkOverlaps(hand_, p.first, poses[p.first], p.second, poses[p.second], margin_);
  });
}

}  // namespace graspsim::grasp
