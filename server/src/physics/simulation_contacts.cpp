// Simulation's contact stages (physics/simulation.h): finding contacts and pad hits, their forces with the
// linearisation the implicit solve needs, the bristle update, and the pads' element forces.
#include <algorithm>

#include "physics/simulation.h"
#include "tactile/pad_contacts.h"

namespace graspsim {
namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;

// The bristle of `key` in the sorted vector (zero when the contact has none). Step after step the contacts come
// in the vector's order, so the search starts where the last one ended: O(1) per contact, a binary search only
// where contacts began or ended.
Vec3 BristleAt(const std::vector<std::pair<ContactKey, Vec3>>& bristles, const ContactKey& key, size_t* cursor) {
  if (*cursor < bristles.size() && bristles[*cursor].first == key) return bristles[(*cursor)++].second;
  const auto found = std::lower_bound(bristles.begin(), bristles.end(), key,
                                      [](const auto& entry, const ContactKey& k) { return entry.first < k; });
  *cursor = static_cast<size_t>(found - bristles.begin());
  if (found == bristles.end() || found->first != key) return Vec3::Zero();
  ++*cursor;
  return found->second;
}

// Σ c, Σ c p, Σ c p pᵀ over contact points: what a pair's 6 × 6 block needs of terms that share their 3 × 3
// shape (c I, or c n nᵀ with one normal n), at 9 multiply-adds a point instead of a 6 × 6 outer product.
struct PointMoments {
  double m0 = 0;
  Vec3 m1 = Vec3::Zero();
  Mat3 m2 = Mat3::Zero();
  void Add(double c, const Vec3& p) {
    m0 += c;
    m1 += c * p;
    m2.noalias() += (c * p) * p.transpose();
  }
  // Σ Eᵀ (c I) E = [[c (|p|² I − p pᵀ), c [p]×], [−c [p]×, c I]].
  void AddIsotropicTo(Mat6* A) const {
    A->topLeftCorner<3, 3>() += m2.trace() * Mat3::Identity() - m2;
    A->topRightCorner<3, 3>() += Skew(m1);
    A->bottomLeftCorner<3, 3>() -= Skew(m1);
    A->bottomRightCorner<3, 3>().diagonal().array() += m0;
  }
  // Σ Eᵀ (c n nᵀ) E = Σ c w wᵀ, w = [p × n; n]: [[N m2 Nᵀ, (m1 × n) nᵀ], [n (m1 × n)ᵀ, m0 n nᵀ]], N = [n]×.
  void AddAlongTo(const Vec3& n, Mat6* A) const {
    const Mat3 N = Skew(n);
    const Vec3 moment = m1.cross(n);
    A->topLeftCorner<3, 3>() += N * m2 * N.transpose();
    A->topRightCorner<3, 3>() += moment * n.transpose();
    A->bottomLeftCorner<3, 3>() += n * moment.transpose();
    A->bottomRightCorner<3, 3>() += m0 * n * n.transpose();
  }
};

// A += β w wᵀ with w = [p × u; u]: the 6 × 6 image Eᵀ (β u uᵀ) E of a rank-one 3 × 3 term at point p.
void AddRankOne(const Vec3& point, const Vec3& direction, double beta, Mat6* A) {
  if (beta == 0) return;
  const Vec6 w = Stack(point.cross(direction), direction);
  A->noalias() += (beta * w) * w.transpose();
}

// A += w_s (β_s w_s + β_n w_n)ᵀ: the images of the slip terms β_s ŝ ŝᵀ and (non-symmetric) β_n ŝ nᵀ at point p,
// as one rank-one update.
void AddSlipTerms(const Vec3& point, const Vec3& slip, const Vec3& normal, double beta_slip, double beta_normal,
                  Mat6* A) {
  if (beta_slip == 0 && beta_normal == 0) return;
  const Vec6 ws = Stack(point.cross(slip), slip), wn = Stack(point.cross(normal), normal);
  A->noalias() += ws * (beta_slip * ws + beta_normal * wn).transpose();
}

}  // namespace

void Simulation::FindContacts(SceneState* state) {
  // Every sample inside another body. Pairs of bodies that are both asleep or static exert nothing on each
  // other that would change their state, so their contacts are dropped; a touched sleeper wakes up.
  contacts_.clear();
  finder_.Find(state->body_poses, &contacts_);
  auto resting = [&](uint32_t body) {
    return model_->bodies[body].motion == BodyMotion::kStatic || state->sleeping[body];
  };
  std::erase_if(contacts_, [&](const ContactPoint& c) { return resting(c.body_a) && resting(c.body_b); });
  // Contacts come grouped by body pair: the pair's law is combined once per group.
  contact_params_.clear();
  for (size_t i = 0; i < contacts_.size(); ++i) {
    const ContactPoint& c = contacts_[i];
    const bool same_pair = i > 0 && contacts_[i - 1].body_a == c.body_a && contacts_[i - 1].body_b == c.body_b;
    const ContactParams params = same_pair ? contact_params_.back() : PairParams(c.body_a, c.body_b);
    contact_params_.push_back(params);
  }
  AddPadContacts(*state);
  for (const ContactPoint& c : contacts_) {
    if (state->sleeping[c.body_a] || state->sleeping[c.body_b]) {
      state->sleeping[c.body_a] = state->sleeping[c.body_b] = false;
      state->rest_time[c.body_a] = state->rest_time[c.body_b] = 0;
    }
  }
}

void Simulation::AddPadContacts(const SceneState& state) {
  // Each sensing element's segment into the foam: a hit is a soft contact with the pad's own law, acting on the
  // touching body (body_a) and the pad's link (body_b). Pads whose foam touches nothing cast nothing.
  if (model_->tactile_arrays.empty()) return;
  pad_hits_.clear();
  pads_.Cast(state.body_poses, &pad_hits_);
  for (const PadHit& hit : pad_hits_) {
    contacts_.push_back(
        {hit.body, pad_links_[hit.pad], PadFeature(hit.pad, hit.element), hit.point, hit.normal, hit.depth});
    contact_params_.push_back(pad_params_[hit.pad]);
  }
}

void Simulation::RecordPadForces(SceneState* state) const {
  // The reaction on the pad (body_b) of each element's contact force; elements without contact read zero.
  for (std::vector<Vec3>& pad : state->pad_forces) std::fill(pad.begin(), pad.end(), Vec3::Zero());
  for (size_t i = 0; i < contacts_.size(); ++i) {
    const std::optional<PadElementRef> element = PadElementOf(contacts_[i].feature);
    if (element) state->pad_forces[element->pad][element->element] = -forces_[i];
  }
}

void Simulation::ContactForces(const SceneState& state, const Eigen::VectorXd& v, double h, Forces* forces) {
  // Penalty normal force and LuGre friction at each point, mapped to generalised forces, with their stiffness
  // and damping for the linearly implicit solve.
  const int nv = multibody_.velocity_count();
  forces->tau.setZero(nv);
  forces->actuators.setZero(nv);
  forces->actuator_damping.setZero(nv);
  forces->actuator_stiffness.setZero(nv);
  const bool linearize = params_.integrator == Integrator::kLinearlyImplicitEuler;
  if (linearize) {
    forces->contact_matrix.setZero(nv, nv);
    forces->contact_rhs.setZero(nv);
  } else {
    forces->contact_matrix.resize(0, 0);
    forces->contact_rhs.resize(0);
  }
  const size_t n = contacts_.size();
  forces->normal_force.resize(n);
  forces->contact_pair.resize(n);
  forces->bristle.resize(n);
  forces->pair_jacobians.clear();
  forces_.resize(n);
  // Three passes. First the pairs' relative Jacobians and each contact's relative velocity and bristle; then the
  // law at every contact in one batch (physics/contact_law.h); then pair by pair each contact's force becomes a
  // wrench about the world origin, [p × f; f], and its linearisation (h D + h² K, in the scalar form of
  // ContactForce) the 6 × 6 block Eᵀ (h D + h² K) E with E(p) = [−[p]×, 1], summed as moments where terms share
  // their shape and as rank-one updates otherwise; only the pair's sums meet the nv-sized Jacobian (nv² work per
  // pair instead of per contact).
  samples_.resize(n);
  twists_.clear();
  size_t cursor = 0;  // into state.bristles, which is in the contacts' order
  for (size_t begin = 0; begin < n;) {
    const uint32_t a = contacts_[begin].body_a, b = contacts_[begin].body_b;
    const size_t pair = forces->pair_jacobians.size();
    const Vec6& twist = twists_.emplace_back(
        forces->pair_jacobians.emplace_back(multibody_.BodyJacobian(state, a) - multibody_.BodyJacobian(state, b)) * v);
    size_t end = begin;
    for (; end < n && contacts_[end].body_a == a && contacts_[end].body_b == b; ++end) {
      const ContactPoint& c = contacts_[end];
      const Vec3 z = forces->bristle[end] = BristleAt(state.bristles, ContactKey{a, b, c.feature}, &cursor);
      samples_[end] = {c.depth, c.normal, twist.tail<3>() + twist.head<3>().cross(c.point), z};
      forces->contact_pair[end] = pair;
    }
    begin = end;
  }
  EvaluateContacts(contact_params_, samples_, h, &laws_);
  for (size_t begin = 0; begin < n;) {
    const size_t pair = forces->contact_pair[begin];
    size_t end = begin;
    while (end < n && forces->contact_pair[end] == pair) ++end;
    const Multibody::SpatialJacobian& W = forces->pair_jacobians[pair];
    Vec3 force_sum = Vec3::Zero(), moment_sum = Vec3::Zero();
    Mat6 block = Mat6::Zero();
    Vec6 stiffness_twist = Vec6::Zero();  // Σ Eᵀ K (E twist), for h² K v
    // The isotropic terms, and the normal terms of the contacts that share the pair's first normal (all of a
    // flat pad's elements, a face lying on a face), as moments; the rest as rank-one updates.
    PointMoments isotropic, along_normal;
    const Vec3 shared_normal = contacts_[begin].normal;
    for (size_t i = begin; i < end; ++i) {
      const ContactPoint& c = contacts_[i];
      const ContactForce& f = laws_[i];
      forces->normal_force[i] = f.normal_force;
      forces_[i] = f.force;
      force_sum += f.force;
      moment_sum += c.point.cross(f.force);
      if (!linearize) continue;
      isotropic.Add(h * f.d_iso + h * h * f.k_iso, c.point);
      const double along = h * f.d_normal + h * h * f.k_normal;
      if (c.normal == shared_normal) {
        along_normal.Add(along, c.point);
      } else {
        AddRankOne(c.point, c.normal, along, &block);
      }
      AddSlipTerms(c.point, f.slip_direction, c.normal, h * h * f.k_slip,
                   h * f.d_slip_normal + h * h * f.k_slip_normal, &block);
      const Vec3& relative = samples_[i].relative_velocity;
      const Vec3 k_relative = f.k_iso * relative + f.k_normal * c.normal.dot(relative) * c.normal +
                              (f.k_slip * f.slip_direction.dot(relative) + f.k_slip_normal * c.normal.dot(relative)) *
                                  f.slip_direction;
      stiffness_twist.head<3>() += c.point.cross(k_relative);
      stiffness_twist.tail<3>() += k_relative;
    }
    forces->tau.noalias() += W.transpose() * Stack(moment_sum, force_sum);
    if (linearize) {
      isotropic.AddIsotropicTo(&block);
      along_normal.AddAlongTo(shared_normal, &block);
      forces->contact_matrix.noalias() += W.transpose() * (block * W);
      forces->contact_rhs.noalias() += (h * h) * (W.transpose() * stiffness_twist);
    }
    begin = end;
  }
}

void Simulation::AdvanceBristles(const Forces& forces, const Eigen::VectorXd& v, double h, SceneState* state) {
  // The exact LuGre update, with the slip velocity the friction force was evaluated with. Contacts that ended
  // drop their bristle state; frictionless contacts never get one. Built in the contacts' (sorted) order into
  // the previous step's buffer. (A batch form like the law's measured no faster here: one division per contact.)
  std::vector<std::pair<ContactKey, Vec3>>& bristles = spare_bristles_;
  bristles.clear();
  twists_.clear();
  for (const Multibody::SpatialJacobian& W : forces.pair_jacobians) twists_.push_back(W * v);
  for (size_t i = 0; i < contacts_.size(); ++i) {
    const ContactPoint& c = contacts_[i];
    const ContactParams& params = contact_params_[i];
    if (!params.HasFriction()) continue;
    const Vec6& twist = twists_[forces.contact_pair[i]];
    const Vec3 relative = twist.tail<3>() + twist.head<3>().cross(c.point);
    bristles.emplace_back(ContactKey{c.body_a, c.body_b, c.feature},
                          AdvanceBristle(params, forces.normal_force[i], c.normal, relative, forces.bristle[i], h));
  }
  auto by_key = [](const auto& x, const auto& y) { return x.first < y.first; };
  if (!std::is_sorted(bristles.begin(), bristles.end(), by_key)) std::sort(bristles.begin(), bristles.end(), by_key);
  std::swap(state->bristles, bristles);
}

}  // namespace graspsim
