#include "physics/pad_readout.h"

#include <algorithm>

#include "tactile/pad_contacts.h"

namespace graspsim {
namespace {

SceneModel WithLongSegments(const SceneModel& model) {
  SceneModel sensing = model;
  for (TactileArraySpec& pad : sensing.tactile_arrays) pad.thickness *= 2;
  return sensing;
}

// The δ with Σ (δ − g)₊ = target over `gaps`, target > 0. f(δ) = Σ (δ − g)₊ − target is convex, piecewise
// linear and rising: Newton's steps from a δ above the root stay above it and end on it in a few passes (no sort:
// a PG70 pad has thousands of elements, and this runs every step).
double PressDepth(const std::vector<double>& gaps, double target) {
  double depth = *std::min_element(gaps.begin(), gaps.end()) + target;  // f ≥ 0 here
  size_t last_pressed = 0;
  for (int pass = 0; pass < 100; ++pass) {
    double excess = -target;
    size_t pressed = 0;
    for (double gap : gaps) {
      if (gap < depth) excess += depth - gap, ++pressed;
    }
    // The same elements as the last step's line: that step landed on the root (up to rounding).
    if (pressed == last_pressed || !(excess > 0)) break;
    last_pressed = pressed;
    depth -= excess / static_cast<double>(pressed);
  }
  return depth;
}

}  // namespace

Geometry FoamBox(const TactileArraySpec& pad) {
  Geometry box;
  box.kind = Geometry::Kind::kBox;
  box.box_size = Vec3(pad.cols * pad.pitch, pad.rows * pad.pitch, pad.thickness);
  box.origin = pad.origin * Pose{Vec3(0, 0, pad.thickness / 2), Quat::Identity()};
  return box;
}

std::vector<uint32_t> PadsOn(const SceneModel& model, size_t body) {
  std::vector<uint32_t> pads;
  for (uint32_t p = 0; p < model.tactile_arrays.size(); ++p) {
    if (model.tactile_arrays[p].body_id == model.bodies[body].id) pads.push_back(p);
  }
  return pads;
}

void AddPadLoad(std::vector<PadLoad>* loads, uint32_t pad, uint32_t body, const Vec3& force) {
  for (PadLoad& load : *loads) {
    if (load.pad == pad && load.body == body) {
      load.force += force;
      return;
    }
  }
  loads->push_back({pad, body, force});
}

PadReadout::PadReadout(const SceneModel& model) : sensing_(WithLongSegments(model)), caster_(sensing_) {
  // A foam without stiffness (a pad spec may leave it at 0) presses every element it sees alike: any k > 0 gives
  // the same shares when the load sinks the body through all of them, and the total is the engine's either way.
  for (const TactileArraySpec& pad : model.tactile_arrays) {
    const double k = ElementContactParams(pad).stiffness;
    element_stiffness_.push_back(k > 0 ? k : 1.0);
  }
}

void PadReadout::Prepare(SceneState* state) const {
  state->pad_forces.resize(sensing_.tactile_arrays.size());
  for (uint32_t pad = 0; pad < sensing_.tactile_arrays.size(); ++pad) {
    state->pad_forces[pad].assign(caster_.Elements(pad).size(), Vec3::Zero());
  }
}

void PadReadout::Record(const std::vector<PadLoad>& loads, SceneState* state) {
  Prepare(state);
  if (loads.empty()) return;
  hits_.clear();  // Cast appends
  caster_.Cast(state->body_poses, &hits_);
  for (const PadLoad& load : loads) {
    const TactileArraySpec& pad = sensing_.tactile_arrays[load.pad];
    const Pose& link = state->body_poses[sensing_.body_index.at(pad.body_id)];
    const Vec3 out_of_foam = (link.orientation * pad.origin.orientation) * Vec3::UnitZ();
    const double normal = -load.force.dot(out_of_foam);  // a push on the foam is along −z
    if (!(normal > 0)) continue;                           // pulled: the foam reads nothing
    const double thickness = pad.thickness / 2;            // the real foam's
    gaps_.clear();
    elements_.clear();
    for (const PadHit& hit : hits_) {
      if (hit.pad != load.pad || hit.body != load.body) continue;
      gaps_.push_back(thickness - hit.depth);
      elements_.push_back(hit.element);
    }
    if (gaps_.empty()) continue;
    const double k = element_stiffness_[load.pad];
    const double depth = PressDepth(gaps_, normal / k);
    std::vector<Vec3>& forces = state->pad_forces[load.pad];
    for (size_t i = 0; i < gaps_.size(); ++i) {
      const double pressed = depth - gaps_[i];
      if (pressed > 0) forces[elements_[i]] += load.force * (k * pressed / normal);
    }
  }
}

}  // namespace graspsim
