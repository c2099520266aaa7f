// The contact law of contact_law.h: penalty normal force and LuGre friction with the Stribeck effect.
//
// Choices beyond the header (each also stated where it is made):
// - No normal force (d ≤ 0, or a contact separating faster than k d / c) means g = 0: no friction at all, a
//   reported ż of 0, and AdvanceBristle resets z to 0 (the g → 0 limit of the exact update).
// - The bristle deflection the caller passes is projected onto the current tangent plane (the normal turns as
//   the bodies turn) and capped at the static limit max(α0, α0 + α1)/σ0 = μ_s|F_n|/σ0. LuGre is derived for a
//   constant normal load; when the load drops while the contact sticks (|v_t| = 0, so ż = 0) the bristles would
//   otherwise keep holding a force above μ_s|F_n| — a released object would stay glued to the finger. The cap is
//   the static bound, not g(v), so LuGre's frictional memory while sliding (z lagging g(v)) is untouched.
// - Linearisation: see EvaluateContact.
// - σ1 falls with the slip speed (contact_law.h), in the force and in its linearisation alike.
#include "physics/contact_law.h"

#include <algorithm>
#include <cmath>

namespace graspsim {
namespace {

// The largest friction force the bristles can hold at this normal force: g's maximum over the slip speed.
double StaticLimit(const ContactParams& params, double normal_force) {
  const double n = std::abs(normal_force);
  return n * std::max(params.dynamic_friction, params.static_friction);
}

// z in the tangent plane of `normal`, no longer than static_force / σ0 (a bristle cannot store more than the
// static friction). Compared squared and scaled by σ0 so the common case, a bristle within its limit, takes no
// division or square root.
Vec3 ProjectBristle(const Vec3& normal, const Vec3& bristle, double static_force, double sigma0) {
  Vec3 z = bristle - bristle.dot(normal) * normal;
  const double length2 = z.squaredNorm();
  if (length2 * sigma0 * sigma0 > static_force * static_force) {
    z *= static_force / (sigma0 * std::sqrt(length2));  // static_force ≥ 0; length > 0 here
  }
  return z;
}

// e^x − 1 and (e^x − 1)/x. A sticking contact's arguments are ~1e-8: there the series are exact to rounding (the
// next terms are below 1e-16 relative) and several times cheaper than the library call and the division, which
// every contact needs twice a step. x = −∞ (g underflowing) gives −1 and 0.
struct ExpMinusOne {
  double value, over_x;
  explicit ExpMinusOne(double x) {
    if (std::abs(x) < 1e-5) {
      over_x = 1 + x * (0.5 + x / 6);
      value = x * over_x;
    } else {
      value = std::expm1(x);
      over_x = value / x;
    }
  }
};

// ∂(σ0 z⁺·ŝ)/∂g: how much of a change of g (so of the normal force) the step's friction follows. Along the slip
// the exact update gives σ0 z⁺·ŝ = e^{−x} σ0 z·ŝ + (1 − e^{−x}) g with x = σ0|v| dt/g, so with
// stick = 1 − σ0 z·ŝ/g the derivative is (1 − e^{−x}) − x e^{−x} stick: ~1 for a contact slipping many bristle
// lengths per step, saturated (stick 0) or new (z = 0, stick 1) alike, and ~0 for one that sticks (x → 0).
// `grown` is e^{−x} − 1 (ExpMinusOne); x e^{−x} is taken as 0 where e^{−x} underflows (x may be +∞ there).
// Without a step (dt = 0) the bristles cannot move: only a saturated slip, 1 − stick, follows g.
double FollowsNormal(double x, double grown, double stick) {
  if (!(x > 0)) return 1 - stick;
  const double decayed = 1 + grown;  // e^{−x}
  return -grown - (decayed > 0 ? x * decayed : 0.0) * stick;
}

// exp(−v²/v_s²), the Stribeck hump, from the squared slip speed (so the division need not wait for a square
// root); v_s ≤ 0 would be a drop of zero width: 1 at rest only.
double Hump(const ContactParams& params, double slip_speed2) {
  const double vs = params.stribeck_velocity;
  return vs > 0 ? 1 + ExpMinusOne(-slip_speed2 / (vs * vs)).value : (slip_speed2 == 0 ? 1.0 : 0.0);
}

// g / |F_n|: the friction coefficient in effect at this point of the Stribeck curve.
double EffectiveFriction(const ContactParams& params, double hump) {
  return params.dynamic_friction + (params.static_friction - params.dynamic_friction) * hump;
}

// The law at one point (the simulation runs the same arithmetic in SIMD lanes: physics/contact_kernel.h).
ContactForce Law(const ContactParams& params, double depth, const Vec3& normal,
                                               const Vec3& relative_velocity, const Vec3& bristle, double dt) {
  ContactForce out;
  out.normal = normal;
  if (!(depth > 0)) return out;  // not touching (or a NaN depth): no force at all

  // Normal: ḋ = −(v_rel·n). A relative displacement δ of a w.r.t. b changes the depth by −n·δ, so
  // ∂F_n/∂δ = −k n nᵀ and ∂F_n/∂v_rel = −c n nᵀ — both only while the spring-damper pushes; once clamped the
  // force is identically 0 nearby and so are its derivatives.
  const double normal_speed = relative_velocity.dot(normal);
  const double push = params.stiffness * depth - params.damping * normal_speed;
  if (push > 0) {
    out.normal_force = push;
    out.force = push * normal;
    out.k_normal = -params.stiffness;
    out.d_normal = -params.damping;
  }
  if (!params.HasFriction()) return out;

  const Vec3 slip = relative_velocity - normal_speed * normal;
  const double speed2 = slip.squaredNorm(), speed = std::sqrt(speed2);
  const double hump = Hump(params, speed2);
  const double mu = EffectiveFriction(params, hump), g = out.normal_force * mu;
  // g = 0: nothing presses the surfaces together, so nothing can carry friction. ż is reported as 0 rather
  // than the −∞ · z of the formula; AdvanceBristle drops the deflection.
  if (!(g > 0)) return out;

  const double sigma0 = params.bristle_stiffness;
  const Vec3 z = ProjectBristle(normal, bristle, StaticLimit(params, out.normal_force), sigma0);
  const double relax_per_speed = sigma0 / g;      // −a/|v| of the bristle equation ż = v + a z
  const double relax = relax_per_speed * speed;
  const Vec3 z_rate = slip - relax * z;
  out.bristle_rate = z_rate;
  const double sigma1 = params.stribeck_velocity > 0 ? params.bristle_damping * hump : 0.0;
  out.force -= sigma0 * z + sigma1 * z_rate + params.viscous_friction * slip;

  // Tangential damping, ∂F_t/∂v_t at fixed z = −(σ1 ∂ż/∂v_t + c_t) P. Exactly, ∂ż/∂v_t = I − σ0 z ∂(|v|/g)/∂v,
  // which along the slip falls to ~0 at steady sliding and below 0 on the Stribeck drop (negative damping).
  // The conservative −(σ1 + c_t) P keeps the implicit solve stable; it only over-damps transients (a steady
  // slide has Δv = 0, so this term never biases it). P = I − n nᵀ.
  const double tangential_damping = sigma1 + params.viscous_friction;
  out.d_iso = -tangential_damping;
  out.d_normal += tangential_damping;

  // Tangential stiffness, −σ0 ∂z/∂δ: the bristle spring. A displacement δ deflects the bristles by
  // ∂ż/∂v_t · δ; along the slip direction ŝ that is (1 − σ0 z·ŝ / g) — LuGre's tangent stiffness, 1 while
  // sticking, 0 at steady sliding — and across it 1. So −σ0 (P − (1 − s) ŝŝᵀ) with s clamped to [0, 1] (the
  // non-symmetric part z ŝᵀ is dropped). Unlike the plain −σ0 P this matters: the implicit solve applies K to
  // the step's displacement h v, so −σ0 P would add a drag σ0 h per contact to every steady slide.
  // Over a step the exact update moves z by (1 − e^{a dt})/(−a) · v, a = −σ0|v|/g, not dt · v: the bristles of a
  // contact slipping many bristle lengths per step saturate, and their stiffness falls by that ratio.
  const ExpMinusOne relaxed(-relax * dt);  // e^{a dt} − 1, a dt = −relax dt
  const double follow = dt > 0 ? relaxed.over_x : 1.0;
  const double tangential_stiffness = sigma0 * follow;
  out.k_iso = -tangential_stiffness;
  out.k_normal += tangential_stiffness;
  if (speed > 0) {
    out.slip_direction = slip * (1 / speed);
    const double stick = std::clamp(1 - relax_per_speed * z.dot(out.slip_direction), 0.0, 1.0);
    out.k_slip = tangential_stiffness * (1 - stick);
    // F_t = −g(F_n) ŝ where it slides, g/F_n = μ the effective coefficient: ∂F_t/∂δ = −μ ŝ ∂F_n/∂δ = μ k ŝ nᵀ
    // (F_n > 0 here, since g > 0), scaled by how far the step's bristles follow g (FollowsNormal). Not by
    // 1 − stick alone: a contact that starts under a sliding body (a floor sample passing under a box's edge)
    // has z = 0, stick 1, yet saturates within the step; its friction kept the start normal force while the solve
    // applied the end one, and a box sliding down 45° at μ 0.6 came out 0.11 % slow at 1 ms (issue 21).
    const double coupling = FollowsNormal(relax * dt, relaxed.value, stick) * mu;
    out.k_slip_normal = coupling * params.stiffness;
    out.d_slip_normal = coupling * params.damping;
  }
  return out;
}

}  // namespace

double StribeckLimit(const ContactParams& params, double normal_force, double slip_speed) {
  return std::abs(normal_force) * EffectiveFriction(params, Hump(params, slip_speed * slip_speed));
}

ContactForce EvaluateContact(const ContactParams& params, double depth, const Vec3& normal, const Vec3& relative_velocity,
                             const Vec3& bristle, double dt) {
  return Law(params, depth, normal, relative_velocity, bristle, dt);
}

double StepEndNormalForce(const ContactParams& params, double normal_force, double depth, const Vec3& normal,
                          const Vec3& end_velocity, double dt) {
  // The linearised spring-damper at δ = dt v⁺: k (d − dt n·v⁺) − c n·v⁺. A contact that did not push at the
  // step's start had no normal linearisation (contact_law.h), so none at its end either.
  if (!(std::abs(normal_force) > 0)) return 0;
  return std::max(0.0, params.stiffness * depth - (params.damping + params.stiffness * dt) * end_velocity.dot(normal));
}

Vec3 AdvanceBristle(const ContactParams& params, double normal_force, const Vec3& normal, const Vec3& slip_velocity,
                    const Vec3& bristle, double dt) {
  if (!params.HasFriction()) return Vec3::Zero();
  const Vec3 slip = slip_velocity - slip_velocity.dot(normal) * normal;
  const double speed2 = slip.squaredNorm();
  const double g = std::abs(normal_force) * EffectiveFriction(params, Hump(params, speed2));
  if (!(g > 0)) return Vec3::Zero();  // no normal force: the bristles let go (a → −∞ in the update below)
  const double sigma0 = params.bristle_stiffness;
  const Vec3 z = ProjectBristle(normal, bristle, StaticLimit(params, normal_force), sigma0);
  if (speed2 == 0 || !(dt > 0)) return z;

  // ż = v + a z with v and a = −σ0|v|/g constant over the step: z⁺ = e^{a dt} z + (e^{a dt} − 1)/a · v
  //    = e^{a dt} z + (1 − e^{a dt}) z_ss,  z_ss = g/σ0 · v/|v|,
  // a convex combination of z and the steady state, so no dt can overshoot (explicit Euler's factor 1 + a dt
  // leaves [−1, 1] once dt > 2g/(σ0|v|)). expm1 keeps (e^{a dt} − 1)/a accurate when a dt → 0; a dt = −∞
  // (g underflowing) gives z⁺ = 0, the relaxed bristle.
  const double x = -sigma0 * std::sqrt(speed2) / g * dt;  // a dt
  const ExpMinusOne grown(x);                              // e^{a dt} − 1, and over a dt
  // No projection afterwards: a convex combination of a capped z and z_ss (|z_ss| = g/σ0 ≤ the cap), both in the
  // tangent plane, stays capped and tangent up to rounding, and the next evaluation projects anyway.
  return (1 + grown.value) * z + (dt * grown.over_x) * slip;
}

ContactParams CombineContactParams(const ContactParams& a, const ContactParams& b) {
  // The two surfaces deform in series: the same force compresses both, so their compliances add,
  // k = k_a k_b / (k_a + k_b) (two equal materials give k/2), and the same for the dampers (the
  // usual harmonic-mean approximation of two Kelvin–Voigt layers). A zero stands for an infinitely soft
  // layer, so the pair carries no force; the simulation fills a material's unset (0) values with the scene
  // defaults before combining, so this only happens on purpose.
  auto series = [](double x, double y) { return x > 0 && y > 0 ? x * y / (x + y) : 0.0; };
  auto mean = [](double x, double y) { return (x + y) / 2; };
  // Friction is a property of the pair that no material formula predicts; the arithmetic mean is the common
  // engine default (PhysX "average") and keeps a pair of equal materials at their own values. The bristle and
  // Stribeck parameters describe the same interface, so they are averaged alike.
  ContactParams out;
  out.stiffness = series(a.stiffness, b.stiffness);
  out.damping = series(a.damping, b.damping);
  out.static_friction = mean(a.static_friction, b.static_friction);
  out.dynamic_friction = mean(a.dynamic_friction, b.dynamic_friction);
  out.bristle_stiffness = mean(a.bristle_stiffness, b.bristle_stiffness);
  out.bristle_damping = mean(a.bristle_damping, b.bristle_damping);
  out.viscous_friction = mean(a.viscous_friction, b.viscous_friction);
  out.stribeck_velocity = mean(a.stribeck_velocity, b.stribeck_velocity);
  return out;
}

}  // namespace graspsim
