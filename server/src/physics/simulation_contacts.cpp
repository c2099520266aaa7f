// Simulation's contact stages (physics/simulation.h): finding contacts and pad hits, their forces with the
// linearisation the implicit solve needs, the bristle update, and the pads' element forces.
#include <algorithm>

#include "physics/contact_kernel.h"
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

// Σ c, Σ c p, Σ c p pᵀ over contact points (summed by the contact kernel): what a pair's 6 × 6 block needs of
// terms that share their 3 × 3 shape (c I, or c n nᵀ with one normal n).
struct PointMoments {
  double m0 = 0;
  Vec3 m1 = Vec3::Zero();
  Mat3 m2 = Mat3::Zero();
  // From the kernel's Σ c, Σ c p, Σ c p pᵀ (upper triangle xx xy xz yy yz zz).
  explicit PointMoments(const double* sums) : m0(sums[0]), m1(sums[1], sums[2], sums[3]) {
    m2 << sums[4], sums[5], sums[6], sums[5], sums[7], sums[8], sums[6], sums[8], sums[9];
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

// A run's share of its pair's block Σ Eᵀ (h D + h² K) E, E(p) = [−[p]×, 1]; n: the run's first normal.
void AddRunBlock(const contact_kernel::RunSums& sums, const Vec3& n, Mat6* block) {
  using RowMajor6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;
  PointMoments(sums.isotropic).AddIsotropicTo(block);
  PointMoments(sums.along).AddAlongTo(n, block);
  *block += Eigen::Map<const RowMajor6>(sums.normal_block) + Eigen::Map<const RowMajor6>(sums.slip_block);
}

// Which law a contact obeys within its pair: a pad's elements the pad's (tactile/pad_contacts.h), surface samples
// the pair's combined law (FindContacts).
uint64_t LawOf(uint64_t feature) { return PadElementOf(feature) ? feature >> 32 : 0; }

// The end of the run of contacts that starts at `begin`: the same pair (up to pair_end) and the same law.
size_t RunEnd(const std::vector<ContactPoint>& contacts, size_t begin, size_t pair_end) {
  const uint64_t law = LawOf(contacts[begin].feature);
  size_t end = begin + 1;
  while (end < pair_end && LawOf(contacts[end].feature) == law) ++end;
  return end;
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
  AddPadContacts(*state);
  for (size_t i = 0; i < contacts_.size(); ++i) {
    const ContactPoint& c = contacts_[i];
    // Contacts come grouped by pair: a pair's bodies are woken (or found awake) by its first contact.
    if (i > 0 && contacts_[i - 1].body_a == c.body_a && contacts_[i - 1].body_b == c.body_b) continue;
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

void Simulation::ContactColumns::Resize(size_t n) {
  for (std::vector<double>* column :
       {&px, &py, &pz, &nx, &ny, &nz, &depth, &zx, &zy, &zz, &fx, &fy, &fz, &next_zx, &next_zy, &next_zz}) {
    column->resize(n);
  }
}

ContactParams Simulation::RunLaw(size_t begin) const {
  // A run shares one law (RunEnd): a pad's own, or the pair's combined one for surface samples.
  const ContactPoint& first = contacts_[begin];
  const std::optional<PadElementRef> element = PadElementOf(first.feature);
  return element ? pad_params_[element->pad] : PairParams(first.body_a, first.body_b);
}

contact_kernel::ContactRun Simulation::Run(const ContactRunRange& range, const Multibody::Vec6& twist,
                                           double h) const {
  contact_kernel::ContactRun run;
  const ContactColumns& c = columns_;
  const size_t begin = range.begin;
  run.count = range.end - begin;
  run.px = c.px.data() + begin, run.py = c.py.data() + begin, run.pz = c.pz.data() + begin;
  run.nx = c.nx.data() + begin, run.ny = c.ny.data() + begin, run.nz = c.nz.data() + begin;
  run.depth = c.depth.data() + begin;
  run.zx = c.zx.data() + begin, run.zy = c.zy.data() + begin, run.zz = c.zz.data() + begin;
  for (int k = 0; k < 6; ++k) run.twist[k] = twist[k];
  run.law = range.law;
  run.friction = run.law.HasFriction();
  run.h = h;
  return run;
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
  forces->pair_count = 0;
  forces_.resize(n);
  pair_wrenches_.clear();
  // Two passes. First the pairs' relative Jacobians and twists, and each contact's bristle, into columns; then
  // pair by pair the contact kernel (physics/contact_kernel.h) runs the law over each run of contacts under one
  // law and sums their wrenches [p × f; f] about the world origin and their linearisation's 6 × 6 block
  // Eᵀ (h D + h² K) E, E(p) = [−[p]×, 1]; only the pair's sums meet the nv-sized Jacobian (nv² work per pair
  // instead of per contact).
  ContactColumns& columns = columns_;
  columns.Resize(n);
  twists_.clear();
  runs_.clear();
  double *px = columns.px.data(), *py = columns.py.data(), *pz = columns.pz.data();
  double *nx = columns.nx.data(), *ny = columns.ny.data(), *nz = columns.nz.data(), *depth = columns.depth.data();
  double *zx = columns.zx.data(), *zy = columns.zy.data(), *zz = columns.zz.data();
  size_t cursor = 0;  // into state.bristles, which is in the contacts' order
  // Whether contact i's bristle is state.bristles[i] for every contact, and there are no others: a steady grasp,
  // step after step. AdvanceBristles then updates them in place.
  bristles_aligned_ = state.bristles.size() == n;
  for (size_t begin = 0; begin < n;) {
    const uint32_t a = contacts_[begin].body_a, b = contacts_[begin].body_b;
    const size_t pair = forces->pair_count++;
    if (pair == forces->pair_jacobians.size()) forces->pair_jacobians.emplace_back();
    Multibody::SpatialJacobian& W = forces->pair_jacobians[pair];  // W_a − W_b
    multibody_.BodyJacobian(state, a, &W);
    multibody_.BodyJacobian(state, b, &jacobian_b_);
    W -= jacobian_b_;
    twists_.push_back(W * v);
    size_t end = begin;
    for (; end < n && contacts_[end].body_a == a && contacts_[end].body_b == b; ++end) {
      const ContactPoint& c = contacts_[end];
      bristles_aligned_ = bristles_aligned_ && cursor == end;
      const Vec3 z = BristleAt(state.bristles, ContactKey{a, b, c.feature}, &cursor);
      px[end] = c.point.x(), py[end] = c.point.y(), pz[end] = c.point.z();
      nx[end] = c.normal.x(), ny[end] = c.normal.y(), nz[end] = c.normal.z();
      depth[end] = c.depth;
      zx[end] = z.x(), zy[end] = z.y(), zz[end] = z.z();
    }
    for (size_t run_begin = begin; run_begin < end;) {
      const size_t run_end = RunEnd(contacts_, run_begin, end);
      runs_.push_back({run_begin, run_end, pair, RunLaw(run_begin)});
      run_begin = run_end;
    }
    begin = end;
  }
  bristles_aligned_ = bristles_aligned_ && cursor == n;
  for (size_t r = 0; r < runs_.size();) {
    const size_t pair = runs_[r].pair, begin = runs_[r].begin;
    Vec6 wrench = Vec6::Zero(), stiffness_twist = Vec6::Zero();  // Σ Eᵀ K (E twist), for h² K v
    Mat6 block = Mat6::Zero();
    size_t end = begin;
    for (; r < runs_.size() && runs_[r].pair == pair; ++r) {
      const size_t run_begin = runs_[r].begin;
      end = runs_[r].end;
      contact_kernel::RunSums sums;
      contact_kernel::EvaluateRun(Run(runs_[r], twists_[pair], h), linearize, columns.fx.data() + run_begin,
                                  columns.fy.data() + run_begin, columns.fz.data() + run_begin,
                                  forces->normal_force.data() + run_begin, &sums);
      wrench += Stack(Vec3(sums.moment), Vec3(sums.force));
      if (linearize) {
        AddRunBlock(sums, contacts_[run_begin].normal, &block);
        stiffness_twist += Eigen::Map<const Vec6>(sums.stiffness_twist);
      }
    }
    for (size_t i = begin; i < end; ++i) forces_[i] = Vec3(columns.fx[i], columns.fy[i], columns.fz[i]);
    pair_wrenches_.push_back({contacts_[begin].body_a, contacts_[begin].body_b, wrench});
    const Multibody::SpatialJacobian& W = forces->pair_jacobians[pair];
    forces->tau.noalias() += W.transpose() * wrench;
    if (linearize) {
      // Coefficient-wise products: at these sizes (6 rows, a few dozen columns) a blocked product's setup and
      // temporaries cost more than the arithmetic.
      block_times_jacobian_.noalias() = block.lazyProduct(W);
      forces->contact_matrix.noalias() += W.transpose().lazyProduct(block_times_jacobian_);
      forces->contact_rhs.noalias() += (h * h) * (W.transpose() * stiffness_twist);
    }
  }
}

void Simulation::AdvanceBristles(const Forces& forces, const Eigen::VectorXd& v, double h, SceneState* state) {
  // The exact LuGre update (the contact kernel's AdvanceRun), with the slip velocity the friction force was
  // evaluated with — and, for the linearly implicit step, the normal force it applied at its end (contact_law.h's
  // StepEndNormalForce) — over the contacts of the last ContactForces (still in columns_). Contacts that ended drop
  // their bristle state; frictionless contacts never get one. Built in the contacts' (sorted) order into the
  // previous step's buffer.
  ContactColumns& columns = columns_;
  twists_.clear();
  for (size_t pair = 0; pair < forces.pair_count; ++pair) twists_.push_back(forces.pair_jacobians[pair] * v);
  // A steady grasp's contacts are the last step's, each at its bristle's index (ContactForces): the bristles are
  // updated in place. Otherwise they are built anew in the contacts' order.
  const bool in_place = bristles_aligned_;
  std::vector<std::pair<ContactKey, Vec3>>& bristles = in_place ? state->bristles : spare_bristles_;
  if (!in_place) bristles.clear();
  double *next_zx = columns.next_zx.data(), *next_zy = columns.next_zy.data(), *next_zz = columns.next_zz.data();
  for (const ContactRunRange& range : runs_) {
    contact_kernel::ContactRun run = Run(range, twists_[range.pair], h);
    run.step_end_normal = params_.integrator == Integrator::kLinearlyImplicitEuler;
    if (!run.friction) continue;  // a run shares its law: whether its contacts keep a bristle is decided once
    contact_kernel::AdvanceRun(run, forces.normal_force.data() + range.begin, next_zx + range.begin,
                               next_zy + range.begin, next_zz + range.begin);
    for (size_t i = range.begin; i < range.end; ++i) {
      const Vec3 z(next_zx[i], next_zy[i], next_zz[i]);
      if (in_place) {
        bristles[i].second = z;
      } else {
        const ContactPoint& c = contacts_[i];
        bristles.emplace_back(ContactKey{c.body_a, c.body_b, c.feature}, z);
      }
    }
  }
  if (in_place) return;  // every contact had a bristle, so every run has friction: all were written
  // The contacts come as a few runs sorted by key (a pair's samples in feature order, the pads' elements after
  // the finder's pairs): merging the runs in place costs O(n · runs), where a full sort of a grasp's hundreds of
  // bristles each step was a tenth of the step.
  auto by_key = [](const auto& x, const auto& y) { return x.first < y.first; };
  auto sorted_end = std::is_sorted_until(bristles.begin(), bristles.end(), by_key);
  while (sorted_end != bristles.end()) {
    const auto run_end = std::is_sorted_until(sorted_end, bristles.end(), by_key);
    std::inplace_merge(bristles.begin(), sorted_end, run_end, by_key);
    sorted_end = run_end;
  }
  std::swap(state->bristles, bristles);
}

}  // namespace graspsim
