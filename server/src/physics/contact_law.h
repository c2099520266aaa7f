// The soft-contact law of PAPERS.md part B at one contact point: a penalty normal force and LuGre friction with
// the Stribeck effect.
//
//   depth d > 0 along the normal n (out of body b, into a); rate of penetration ḋ = -(v_rel · n), where v_rel is
//   the velocity of a's point relative to b's; slip velocity v_t = v_rel - (v_rel · n) n.
//   Normal force on a:   F_n = max(0, k d + c ḋ) n                          (never pulls)
//   Bristles:            ż = v_t - σ0 |v_t| / g(v_t) z,   g = α0 + α1 exp(-|v_t|² / v_s²),
//                        α0 = |F_n| μ_d,  α1 = |F_n| (μ_s - μ_d)
//   Friction force on a: F_t = -(σ0 z + σ1(v_t) ż + c_t v_t),  σ1(v) = σ1 exp(-|v|² / v_s²)
// The velocity-dependent micro-damping σ1(v) is Canudas de Wit's dissipative variant of LuGre (Olsson et al.
// 1998): it damps presliding as σ1 does, but a contact that starts sliding fast (ż ≈ v_t) is not hit with a
// force σ1 |v_t| unrelated to, and possibly thousands of times, μ |F_n|.
// Body b receives -(F_n + F_t). At constant slip v the bristles settle at z_ss = g(v)/σ0 · v/|v|, so
// |F_t| = g(v) + c_t |v|: the Stribeck curve. z lives in the tangent plane (world frame).
#pragma once

#include "core/math.h"
#include "world/simulation_params.h"

namespace graspsim {

struct ContactForce {
  Vec3 force = Vec3::Zero();  // on body a, world, N (body b gets the opposite)
  double normal_force = 0;    // |F_n|, N
  Vec3 bristle_rate = Vec3::Zero();  // ż at this instant, m/s
  // Linearisation for implicit integration, dF/d(relative displacement of a w.r.t. b) (N/m) and dF/d(v_rel)
  // (N s/m), kept as the scalars of
  //   K = k_iso I + k_normal n nᵀ + k_slip ŝ ŝᵀ,   D = d_iso I + d_normal n nᵀ
  // (n the contact normal, ŝ the slip direction): the simulation maps them to generalised coordinates with
  // rank-one updates, several times cheaper than 3 × 3 products per contact.
  double k_iso = 0, k_normal = 0, k_slip = 0, d_iso = 0, d_normal = 0;
  Vec3 normal = Vec3::Zero(), slip_direction = Vec3::Zero();
  // A sliding contact's friction follows its normal force, |F_t| = μ F_n: the non-symmetric coupling
  // ∂F_t/∂δ = k_slip_normal ŝ nᵀ and ∂F_t/∂v_rel = d_slip_normal ŝ nᵀ. Without it the step's friction would rest
  // on the normal force at its start while the step applies that force plus its implicit change: a sliding box
  // whose contacts come and go (its rocking, samples passing under its edges) then dragged 0.3 % more than
  // μ m g at 1 ms, 0.15 % at 0.5 ms (issue 21). The factor is ∂(σ0 z⁺·ŝ)/∂g of the exact bristle update over the
  // step (z⁺ as AdvanceBristle), times μ: ~μ for any contact slipping many bristle lengths per step, a new one
  // (z = 0) included, ~0 for one that sticks.
  double k_slip_normal = 0, d_slip_normal = 0;

  Mat3 Stiffness() const {
    return k_iso * Mat3::Identity() + k_normal * normal * normal.transpose() +
           k_slip * slip_direction * slip_direction.transpose();
  }
  Mat3 Damping() const { return d_iso * Mat3::Identity() + d_normal * normal * normal.transpose(); }
};

// Stribeck function g(v) for slip speed v (m/s) and normal force (N); N.
double StribeckLimit(const ContactParams& params, double normal_force, double slip_speed);

// The force at one contact point given its bristle deflection z. With a step dt > 0, the tangential stiffness is
// that of the exact bristle update over dt (AdvanceBristle), which the implicit solve needs: a fast new contact
// saturates its bristles within the step, so it must not be linearised as a stuck spring.
ContactForce EvaluateContact(const ContactParams& params, double depth, const Vec3& normal, const Vec3& relative_velocity,
                             const Vec3& bristle, double dt = 0);

// The bristle deflection after dt with the slip velocity and the normal force held constant over the step (the
// linearly implicit step passes the ones at its end: the new velocity and StepEndNormalForce), integrated exactly:
// z⁺ = e^{aΔt} z + (e^{aΔt} - 1)/a · v_t with a = -σ0|v_t|/g (and z⁺ = z + Δt v_t when a = 0). Stable for any
// dt. The result is projected onto the tangent plane of `normal`.
Vec3 AdvanceBristle(const ContactParams& params, double normal_force, const Vec3& normal, const Vec3& slip_velocity,
                    const Vec3& bristle, double dt);

// The normal force a linearly implicit step applies at a contact over the step, F_n + ∂F_n/∂δ dt v⁺ +
// ∂F_n/∂v_rel (v⁺ − v_rel) = max(0, k (d − dt n·v⁺) − c n·v⁺), with v⁺ the relative velocity at the step's end;
// 0 where the contact did not push at the start (normal_force, |F_n| there, is 0). The bristles of such a step
// advance with it (AdvanceBristle), not with the start's F_n: the step's friction followed the normal force to
// its end (ContactForce::k_slip_normal), and the bristles carry that friction into the next step. With the
// start's F_n a sliding contact's friction lagged its normal force by a step, which over the contact's life adds
// up to an impulse μ h (F_n at its first step − F_n at its last): floor samples passing under a sliding box from
// its loaded front edge to its unloaded rear slowed it by 0.6 % at 1 ms where μ_s > μ_d (issue 21; with
// μ_s = μ_d the static cap on z hid most of it).
double StepEndNormalForce(const ContactParams& params, double normal_force, double depth, const Vec3& normal,
                          const Vec3& end_velocity, double dt);

// Combines two bodies' materials into the parameters of their contact (documented in the implementation).
ContactParams CombineContactParams(const ContactParams& a, const ContactParams& b);

}  // namespace graspsim
