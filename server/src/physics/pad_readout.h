// Tactile pads on the engines whose contacts are not at the sensing elements (MuJoCo, Bullet: physics/engine.h).
//
// The pad's foam is a box of the sensing area × thickness on its link (FoamBox), which the engine collides like
// any geometry. After a step the pad reads the engine's contact force through the same ray sensor as graspsim's
// engine (tactile/ray_caster.h): for each body that pushes on the foam with normal force F (the engine's total on
// the foam box), the elements' segments find the body's surface at gaps g_e from the foam's surface (negative
// inside the foam), and the foam law's springs k (per element, tactile/pad_contacts.h) carry F when the body is
// pressed in by the δ that solves Σ_e k (δ − g_e)₊ = F. Each element reads k (δ − g_e)₊ normal to the pad and the
// same share of the body's tangential force. So the pad's total is the engine's contact force, and its pressure
// image is the foam law's over the geometry as the engine placed it. The foam's damping, bristles and the time
// the foam takes to compress are graspsim's engine's only. Segments are cast twice the foam's thickness, so an
// element sees a surface up to one thickness beyond the foam; a touch no segment sees (on the foam's side faces)
// is not read, as on the real pad.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "tactile/ray_caster.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim {

// Pad `pad`'s foam as a box on its link: (cols · pitch) × (rows · pitch) × thickness, over the pad frame's z ∈
// [0, thickness]; in the link frame. Flat pads only (CheckEngineSupports refuses curved ones on these engines).
Geometry FoamBox(const TactileArraySpec& pad);

// The indices (into SceneModel::tactile_arrays) of the pads mounted on body `body`.
std::vector<uint32_t> PadsOn(const SceneModel& model, size_t body);

// The engine's contact force on pad `pad`'s foam from body `body` (world frame, N; summed over the engine's
// contact points between the two).
struct PadLoad {
  uint32_t pad = 0;
  uint32_t body = 0;
  Vec3 force = Vec3::Zero();
};

// Adds `force` to the load of (pad, body) in *loads, or appends one.
void AddPadLoad(std::vector<PadLoad>* loads, uint32_t pad, uint32_t body, const Vec3& force);

class PadReadout {
 public:
  explicit PadReadout(const SceneModel& model);
  PadReadout(const PadReadout&) = delete;
  PadReadout& operator=(const PadReadout&) = delete;

  // Sizes state->pad_forces (per pad, per element) to the model.
  void Prepare(SceneState* state) const;
  // Fills state->pad_forces from `loads` at state->body_poses (elements no load reaches read zero).
  void Record(const std::vector<PadLoad>& loads, SceneState* state);

 private:
  SceneModel sensing_;  // the scene's model with every pad's segments twice as long (header comment)
  TactileRayCaster caster_;
  std::vector<double> element_stiffness_;  // per pad: k of one element
  std::vector<PadHit> hits_;               // Record's buffers: the step's hits, then one load's gaps and elements
  std::vector<double> gaps_;
  std::vector<uint32_t> elements_;
};

}  // namespace graspsim
