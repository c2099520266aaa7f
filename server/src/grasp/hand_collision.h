// Private to grasp/: the hand's box tests beyond the closing sweep: its links' boxes against obstacle boxes,
// placed or swept along the approach, and against each other once the fingers have closed.
#pragma once

#include <utility>
#include <vector>

#include "core/math.h"
#include "grasp/grasp_object.h"
#include "grasp/hand_model.h"

namespace graspsim::grasp {

// Does box `a`, swept by the translation `motion` (its whole path), overlap box `b`? Boxes in one frame;
// touching within `margin` counts as overlapping (margin < 0: an overlap of at most -margin is allowed).
// Separating axes of the swept box (a convex polytope: a's faces, and faces spanned by a's edges and the
// motion) and of b, and the cross products of their edge directions.
bool SweptBoxOverlaps(const LinkBox& a, const Vec3& motion, const LinkBox& b, double margin);

// The link boxes at `poses` (object frame), each swept by `motion` (zero: placed), against the obstacles.
bool HandOverlapsObstacles(const HandModel& hand, const std::vector<Pose>& poses, const Vec3& motion,
                           const std::vector<ObstacleBox>& obstacles, double margin);

// Finger-finger and finger-palm overlap of a closed hand. Pairs joined by a joint, and pairs whose boxes
// already overlap in some pre-shape (boxes bound the real shapes loosely at knuckles), are never tested.
class SelfCollision {
 public:
  SelfCollision(const HandModel& hand, double margin);
  bool Collides(const std::vector<Pose>& poses) const;
  const std::vector<std::pair<int, int>>& pairs() const { return pairs_; }  // the link pairs tested

 private:
  const HandModel& hand_;
  double margin_;
  std::vector<std::pair<int, int>> pairs_;
};

}  // namespace graspsim::grasp
