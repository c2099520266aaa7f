// Private to grasp/: the Ferrari-Canny ε without the whole hull. qhull builds every facet of the 6-D wrench hull
// (thousands for 9 contacts x 8 edges, ~25 ms); ε needs only the one nearest the origin. This is the expanding
// polytope algorithm (van den Bergen's EPA) in 6-D: start from a full-dimensional simplex of the wrenches, then
// repeatedly take the current polytope's facet nearest the origin (smallest signed plane offset) and ask for the
// wrench farthest along its normal; if none lies beyond it, that facet is a facet of the hull and its offset is ε
// (negative or zero: the origin is not inside, no force closure); otherwise add that wrench (beneath-beyond:
// drop the facets it sees, cone the horizon ridges to it) and repeat. The polytope only grows inside the hull,
// so the nearest facet's offset never overshoots ε, and only the hull near the origin is ever built.
#pragma once

#include <vector>

#include "grasp/quality.h"

namespace graspsim::grasp {

struct NearestFacetResult {
  bool degenerate = false; // the wrenches do not span R^6 (or are fewer than 7): no force closure
  bool converged = false;  // false (and not degenerate): the iteration cap; the caller falls back to qhull
  double distance = 0;     // > 0: the origin is inside, this far from the nearest facet's plane (ε); <= 0: not
                           // strictly inside (then only the sign is meaningful)
};

NearestFacetResult NearestFacet(const std::vector<Wrench>& wrenches);

}  // namespace graspsim::grasp
