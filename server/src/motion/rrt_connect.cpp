// RRT-Connect (Kuffner & LaValle 2000) as VAMP runs it: two trees in flat arrays, nearest neighbour by a linear
// scan (trees stay small on the problems it is for; a scan of a few hundred 7-vectors beats a tree structure's
// bookkeeping), the smaller tree grown while one is twice the other, dynamic domains, every new edge through
// the checker's batched, conservative motion test.
#include <cmath>
#include <random>

#include "motion/search.h"

namespace graspsim::motion {
namespace {

using Clock = std::chrono::steady_clock;

class Tree {
 public:
  explicit Tree(size_t dof) : dof_(dof) {}
  int Add(const VecX& q, int parent) {
    values_.insert(values_.end(), q.data(), q.data() + dof_);
    parents_.push_back(parent);
    domains_.push_back(INFINITY);
    return static_cast<int>(parents_.size()) - 1;
  }
  Eigen::Map<const VecX> At(int i) const { return {values_.data() + static_cast<size_t>(i) * dof_, static_cast<long>(dof_)}; }
  int Parent(int i) const { return parents_[i]; }
  size_t Size() const { return parents_.size(); }
  double& Domain(int i) { return domains_[i]; }  // its dynamic domain; infinite until an extension from it fails
  int Nearest(const VecX& q, double* distance = nullptr) const {
    int best = 0;
    double best_d = INFINITY;
    const double* v = values_.data();
    for (size_t i = 0; i < parents_.size(); ++i, v += dof_) {
      double d = 0;
      for (size_t k = 0; k < dof_; ++k) d += (v[k] - q[k]) * (v[k] - q[k]);
      if (d < best_d) best_d = d, best = static_cast<int>(i);
    }
    if (distance) *distance = std::sqrt(best_d);
    return best;
  }
  // Node i and its ancestors, root last.
  std::vector<VecX> PathToRoot(int i) const {
    std::vector<VecX> out;
    for (; i >= 0; i = parents_[i]) out.emplace_back(At(i));
    return out;
  }

 private:
  size_t dof_;
  std::vector<double> values_;
  std::vector<int> parents_;
  std::vector<double> domains_;
};

// Dynamic domain (Yershova et al. 2005), with VAMP's settings: a node whose extension failed only extends
// towards samples within its domain, kDomainRadius rad at the first failure, shrunk by kDomainAlpha at each
// further failure down to kDomainMinRadius, grown by it at each success. Samples beyond it cost no check.
constexpr double kDomainRadius = 4.0, kDomainAlpha = 1e-4, kDomainMinRadius = 1.0;

// *out: at most `range` from `from` towards `to`; returns whether that is `to` itself. Into a buffer the search
// keeps: a step is taken at every iteration.
bool Step(const Eigen::Ref<const VecX>& from, const VecX& to, double range, VecX* out) {
  const double distance = (to - from).norm();
  if (distance <= range) {
    *out = to;
    return true;
  }
  *out = from + (to - from) * (range / distance);
  return false;
}

}  // namespace

SearchResult SearchRrtConnect(const CollisionChecker& checker, const VecX& start, const std::vector<VecX>& goals,
                              const PlanOptions& options, Clock::time_point began) {
  const ArmModel& arm = checker.arm();
  const size_t n = arm.dof();
  const double range = options.range > 0 ? options.range : kDefaultRange;
  Tree start_tree(n), goal_tree(n);
  start_tree.Add(start, -1);
  for (const VecX& g : goals) goal_tree.Add(g, -1);
  Tree* a = &start_tree;
  Tree* b = &goal_tree;
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  VecX sample(n), added(n), next(n);
  SearchResult result;
  for (uint64_t iteration = 0;; ++iteration) {
    if ((iteration & 15) == 0) {
      if (options.cancelled && options.cancelled()) {
        result.cancelled = true;
        return result;
      }
      if (std::chrono::duration<double>(Clock::now() - began).count() > options.timeout) return result;
    }
    if (a->Size() >= 2 * b->Size()) std::swap(a, b);  // balance: grow the smaller tree while one is twice the other
    for (size_t i = 0; i < n; ++i) sample[i] = arm.lower()[i] + unit(rng) * (arm.upper()[i] - arm.lower()[i]);
    // Extend a towards the sample by one step.
    double near_distance;
    const int near = a->Nearest(sample, &near_distance);
    double& domain = a->Domain(near);
    if (near_distance > domain) {  // outside the nearest node's dynamic domain: not tried
      std::swap(a, b);
      continue;
    }
    Step(a->At(near), sample, range, &added);
    if (!checker.IsMotionValid(a->At(near), added)) {  // tests `added` itself first
      domain = std::isinf(domain) ? kDomainRadius : std::max(domain * (1 - kDomainAlpha), kDomainMinRadius);
    } else {
      if (!std::isinf(domain)) domain *= 1 + kDomainAlpha;
      const int a_node = a->Add(added, near);
      // Connect b to the new node, step by step, while the steps are free.
      int b_node = b->Nearest(added);
      while (true) {
        const bool reached = Step(b->At(b_node), added, range, &next);
        if (!checker.IsMotionValid(b->At(b_node), next)) break;
        if (reached) {
          std::vector<VecX> from_a = a->PathToRoot(a_node), from_b = b->PathToRoot(b_node);
          std::vector<VecX>& to_start = a == &start_tree ? from_a : from_b;
          std::vector<VecX>& to_goal = a == &start_tree ? from_b : from_a;
          result.path.assign(to_start.rbegin(), to_start.rend());
          result.path.insert(result.path.end(), to_goal.begin(), to_goal.end());
          return result;
        }
        b_node = b->Add(next, b_node);
      }
    }
    std::swap(a, b);
  }
}

}  // namespace graspsim::motion
