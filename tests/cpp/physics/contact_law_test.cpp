// The contact law against analytic answers: the penalty normal force, the LuGre steady state (the Stribeck
// curve), the exact bristle update (stable for any step, where explicit Euler diverges), stiction and
// presliding, the tangent plane, the linearisation and the material combination.
#include "physics/contact_law.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Dense>

namespace graspsim {
namespace {

ContactParams Params() {
  ContactParams p;
  p.stiffness = 1e4;
  p.damping = 10;
  p.static_friction = 0.6;
  p.dynamic_friction = 0.4;
  p.bristle_stiffness = 1e4;
  p.bristle_damping = 30;
  p.viscous_friction = 0.05;
  p.stribeck_velocity = 1e-2;
  return p;
}

const Vec3 kNormal = Vec3(1, 2, 3).normalized();
const Vec3 kTangent = kNormal.cross(Vec3::UnitX()).normalized();  // ⊥ kNormal
constexpr double kNormalForce = 10;                               // N, from depth F_n / k at rest

Vec3 Tangential(const Vec3& f) { return f - f.dot(kNormal) * kNormal; }

TEST(ContactLawTest, NormalForceIsSpringDamperAlongTheNormal) {
  ContactParams p = Params();
  p.static_friction = p.dynamic_friction = 0;  // the normal part alone
  const double d = 1e-3, rate = 0.02;          // penetrating at 2 cm/s: v_rel · n = −ḋ
  const ContactForce f = EvaluateContact(p, d, kNormal, -rate * kNormal, Vec3::Zero());
  const double expected = p.stiffness * d + p.damping * rate;
  EXPECT_NEAR(f.normal_force, expected, 1e-12 * expected);
  EXPECT_NEAR((f.force - expected * kNormal).norm(), 0, 1e-12 * expected);
  // A relative displacement δ of a w.r.t. b changes the depth by −n·δ: the finite difference of the force
  // matches the stiffness; likewise the damping w.r.t. the relative velocity (the law is linear: exact).
  const Vec3 delta = 1e-7 * Vec3(0.3, -0.5, 0.8);
  const ContactForce moved = EvaluateContact(p, d - kNormal.dot(delta), kNormal, -rate * kNormal, Vec3::Zero());
  EXPECT_NEAR((moved.force - f.force - f.Stiffness() * delta).norm(), 0, 1e-9);
  const ContactForce faster = EvaluateContact(p, d, kNormal, -rate * kNormal + delta, Vec3::Zero());
  EXPECT_NEAR((faster.force - f.force - f.Damping() * delta).norm(), 0, 1e-12);
  EXPECT_NEAR((f.Stiffness() + p.stiffness * kNormal * kNormal.transpose()).norm(), 0, 1e-9);
}

TEST(ContactLawTest, NeverPullsWhenSeparatingFast) {
  const ContactParams p = Params();
  const double d = 1e-3;
  const double limit = p.stiffness * d / p.damping;  // separation speed at which k d + c ḋ = 0
  const Vec3 z = 1e-5 * kTangent;
  for (double speed : {1.01 * limit, 2 * limit, 100 * limit}) {
    const ContactForce f = EvaluateContact(p, d, kNormal, speed * kNormal + 0.1 * kTangent, z);
    EXPECT_EQ(f.normal_force, 0);
    EXPECT_EQ(f.force, Vec3::Zero()) << "no normal force, no friction either";
    EXPECT_EQ(f.Stiffness(), Mat3::Zero());
    EXPECT_EQ(f.Damping(), Mat3::Zero());
  }
  const ContactForce slow = EvaluateContact(p, d, kNormal, 0.5 * limit * kNormal, Vec3::Zero());
  EXPECT_NEAR(slow.normal_force, 0.5 * p.stiffness * d, 1e-12);
}

TEST(ContactLawTest, NothingWithoutPenetration) {
  for (double d : {0.0, -1e-6, -1.0}) {
    const ContactForce f = EvaluateContact(Params(), d, kNormal, -kNormal + kTangent, 1e-4 * kTangent);
    EXPECT_EQ(f.force, Vec3::Zero());
    EXPECT_EQ(f.normal_force, 0);
    EXPECT_EQ(f.bristle_rate, Vec3::Zero());
  }
}

TEST(ContactLawTest, StribeckLimitFollowsItsFormula) {
  const ContactParams p = Params();
  for (double v : {0.0, 1e-3, 1e-2, 3e-2, 1.0}) {
    const double expected = kNormalForce * (0.4 + 0.2 * std::exp(-v * v / 1e-4));
    EXPECT_NEAR(StribeckLimit(p, kNormalForce, v), expected, 1e-14 * expected) << v;
  }
  EXPECT_DOUBLE_EQ(StribeckLimit(p, kNormalForce, 0), 0.6 * kNormalForce);  // μ_s F_n at rest
  EXPECT_DOUBLE_EQ(StribeckLimit(p, kNormalForce, 10), 0.4 * kNormalForce);  // μ_d F_n sliding fast
  EXPECT_EQ(StribeckLimit(p, 0, 0), 0);
}

// The bristle after sliding at constant slip long enough (40 time constants g/(σ0 v)) to reach steady state.
Vec3 SteadyBristle(const ContactParams& p, const Vec3& slip) {
  const double g = StribeckLimit(p, kNormalForce, slip.norm());
  const double tau = g / (p.bristle_stiffness * slip.norm());
  Vec3 z = Vec3::Zero();
  for (int i = 0; i < 40; ++i) z = AdvanceBristle(p, kNormalForce, kNormal, slip, z, tau);
  return z;
}

TEST(ContactLawTest, SteadySlidingFollowsTheStribeckCurve) {
  const ContactParams p = Params();
  const double depth = kNormalForce / p.stiffness;
  for (int i = 0; i <= 40; ++i) {
    const double v = std::pow(10.0, -4 + 0.1 * i);  // 1e-4 … 1 m/s, log sweep
    const Vec3 slip = v * kTangent;
    const Vec3 z = SteadyBristle(p, slip);
    const ContactForce f = EvaluateContact(p, depth, kNormal, slip, z);
    const double expected = StribeckLimit(p, kNormalForce, v) + p.viscous_friction * v;
    const Vec3 friction = Tangential(f.force);
    EXPECT_NEAR(friction.norm() / expected, 1, 1e-6) << "v = " << v;
    EXPECT_NEAR(friction.normalized().dot(kTangent), -1, 1e-12) << "opposes the slip";
    EXPECT_NEAR(f.normal_force, kNormalForce, 1e-9);
  }
}

TEST(ContactLawTest, ExactBristleUpdateIsBoundedForAnyStepWhereEulerDiverges) {
  for (double sigma0 : {1e2, 1e4, 1e6}) {
    ContactParams p = Params();
    p.bristle_stiffness = sigma0;
    for (double v : {1e-4, 1e-2, 1.0}) {
      const double g = StribeckLimit(p, kNormalForce, v);
      const double bound = g / sigma0;
      for (double dt : {1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0}) {
        // From rest and from the opposite steady state (a reversal, the hardest case).
        for (const Vec3& start : {Vec3(Vec3::Zero()), Vec3(-bound * kTangent)}) {
          Vec3 z = start;
          for (int i = 0; i < 50; ++i) {
            z = AdvanceBristle(p, kNormalForce, kNormal, v * kTangent, z, dt);
            ASSERT_TRUE(z.allFinite());
            ASSERT_LE(z.norm(), bound * (1 + 1e-12)) << "σ0 " << sigma0 << " v " << v << " dt " << dt;
          }
        }
      }
    }
  }
  // Explicit Euler on the same ODE, z += dt (v − σ0|v|/g z), multiplies the error by 1 + a dt, a = −σ0|v|/g:
  // it converges below dt = 2g/(σ0|v|) and diverges above — here 8e-5 s, far below a typical step.
  ContactParams p = Params();
  p.bristle_stiffness = 1e6;
  const double v = 0.1, g = StribeckLimit(p, kNormalForce, v), critical = 2 * g / (1e6 * v);
  auto euler = [&](double dt) {
    double z = 0;
    for (int i = 0; i < 50; ++i) z += dt * (v - 1e6 * v / g * z);
    return z;
  };
  EXPECT_NEAR(euler(0.9 * critical), g / 1e6, 1e-3 * g / 1e6);
  EXPECT_GT(std::abs(euler(1.1 * critical)), 10 * g / 1e6);
  EXPECT_FALSE(std::abs(euler(1e-3)) < 1e30) << "a 1 ms explicit step explodes";
}

TEST(ContactLawTest, ExactUpdateMatchesTheAnalyticSolutionAndComposes) {
  const ContactParams p = Params();
  const double v = 3e-3, g = StribeckLimit(p, kNormalForce, v), a = -p.bristle_stiffness * v / g;
  const Vec3 z0 = 2e-4 * kNormal.cross(kTangent);  // across the slip: decays while the steady state builds
  const double t = 7e-3;
  const Vec3 expected = std::exp(a * t) * z0 + (1 - std::exp(a * t)) * (g / p.bristle_stiffness) * kTangent;
  const Vec3 one = AdvanceBristle(p, kNormalForce, kNormal, v * kTangent, z0, t);
  EXPECT_NEAR((one - expected).norm(), 0, 1e-15);
  Vec3 many = z0;
  for (int i = 0; i < 7; ++i) many = AdvanceBristle(p, kNormalForce, kNormal, v * kTangent, many, t / 7);
  EXPECT_NEAR((many - expected).norm(), 0, 1e-15);
}

TEST(ContactLawTest, StictionHoldsBelowTheStaticLimitAtTinySlip) {
  // Creeping at 1 nm/s for 1e7 s (1 cm: many bristle lengths, possible only with the exact update): the
  // friction force rises to μ_s F_n and never exceeds it (c_t = 0: viscous friction adds c_t v at any slip).
  ContactParams p = Params();
  p.viscous_friction = 0;
  const double depth = kNormalForce / p.stiffness, v = 1e-9, limit = 0.6 * kNormalForce;
  Vec3 z = Vec3::Zero();
  double force = 0;
  for (int i = 0; i < 100; ++i) {
    force = Tangential(EvaluateContact(p, depth, kNormal, v * kTangent, z).force).norm();
    ASSERT_LE(force, limit * (1 + 1e-12));
    z = AdvanceBristle(p, kNormalForce, kNormal, v * kTangent, z, 1e5);
  }
  EXPECT_NEAR(force / limit, 1, 1e-6);
}

TEST(ContactLawTest, PreslidingIsTheBristleSpring) {
  // A tangential displacement x ≪ g/σ0 (here 5e-10 m against 6e-4 m) loads the bristles like a spring:
  // F_t = −σ0 x to first order in σ0 x / g, and the stiffness the implicit integrator sees is that spring.
  const ContactParams p = Params();
  const double depth = kNormalForce / p.stiffness, x = 5e-10;
  Vec3 z = Vec3::Zero();
  for (int i = 0; i < 10; ++i) z = AdvanceBristle(p, kNormalForce, kNormal, (x / 1e-3) * kTangent, z, 1e-4);
  const ContactForce f = EvaluateContact(p, depth, kNormal, Vec3::Zero(), z);
  const double sigma0 = p.bristle_stiffness;
  EXPECT_NEAR(Tangential(f.force).dot(kTangent) / (-sigma0 * x), 1, 1e-6);
  EXPECT_NEAR(Tangential(f.force).cross(kTangent).norm(), 0, 1e-15);
  const ContactForce rest = EvaluateContact(p, depth, kNormal, Vec3::Zero(), Vec3::Zero());
  EXPECT_NEAR((rest.Stiffness() * kTangent).dot(kTangent), -sigma0, 1e-9);
}

TEST(ContactLawTest, BristleStaysInTheTangentPlane) {
  const ContactParams p = Params();
  const Vec3 slip = 0.01 * kTangent + 0.5 * kNormal;        // a normal component the law must ignore
  const Vec3 tilted = 3e-4 * kTangent + 2e-4 * kNormal;     // as if the normal had turned since last step
  for (double dt : {0.0, 1e-4, 1.0}) {
    const Vec3 z = AdvanceBristle(p, kNormalForce, kNormal, slip, tilted, dt);
    EXPECT_NEAR(z.dot(kNormal), 0, 1e-17) << dt;
  }
  const ContactForce f = EvaluateContact(p, 1e-3, kNormal, slip, tilted);
  EXPECT_NEAR(f.bristle_rate.dot(kNormal), 0, 1e-15);
  EXPECT_NEAR((f.force - f.normal_force * kNormal).dot(kNormal), 0, 1e-12);
  // No slip: the bristle keeps its (projected) deflection.
  const Vec3 held = AdvanceBristle(p, kNormalForce, kNormal, Vec3::Zero(), tilted, 1.0);
  EXPECT_NEAR((held - 3e-4 * kTangent).norm(), 0, 1e-17);
}

TEST(ContactLawTest, NoFrictionWithoutNormalForceOrCoefficients) {
  ContactParams p = Params();
  EXPECT_EQ(AdvanceBristle(p, 0, kNormal, kTangent, 1e-4 * kTangent, 1e-3), Vec3::Zero()) << "let go";
  p.static_friction = p.dynamic_friction = 0;
  const ContactForce f = EvaluateContact(p, 1e-3, kNormal, kTangent, 1e-4 * kTangent);
  EXPECT_NEAR((f.force - 10 * kNormal).norm(), 0, 1e-12) << "k d only, no tangential part";
  EXPECT_EQ(AdvanceBristle(p, kNormalForce, kNormal, kTangent, 1e-4 * kTangent, 1e-3), Vec3::Zero());
}

TEST(ContactLawTest, StickingForceDropsWithTheNormalLoad) {
  // Bristles loaded at 10 N, then the load falls to 1 N while nothing slides: the friction force follows the
  // static limit μ_s F_n down instead of holding 6 N (a released object must not stay glued to the finger).
  const ContactParams p = Params();
  const Vec3 z = 0.6 * kNormalForce / p.bristle_stiffness * kTangent;
  const ContactForce f = EvaluateContact(p, 1.0 / p.stiffness, kNormal, Vec3::Zero(), z);
  EXPECT_NEAR(Tangential(f.force).norm(), 0.6 * 1.0, 1e-12);
}

// A 1 kg block pressed on the contact by 10 N and pushed along the surface, integrated as the simulation does
// (linearly implicit Euler with the law's stiffness and damping; bristles advanced with the step's new slip
// velocity, the one the implicit solve assumed). The push rises linearly over `ramp_steps`, then holds.
struct Block {
  Vec3 x = Vec3::Zero(), v = Vec3::Zero(), z = Vec3::Zero();
};

void Push(const ContactParams& p, const Vec3& external, double h, int steps, Block* b, int ramp_steps = 0) {
  const double m = 1, depth = kNormalForce / p.stiffness;
  const Mat3 P = Mat3::Identity() - kNormal * kNormal.transpose();
  for (int i = 0; i < steps; ++i) {
    const double ramp = ramp_steps > 0 ? std::min(1.0, (i + 1.0) / ramp_steps) : 1.0;
    const ContactForce f = EvaluateContact(p, depth, kNormal, b->v, b->z);
    const Mat3 A = m * Mat3::Identity() - h * f.Damping() - h * h * f.Stiffness();
    const Vec3 dv =
        A.ldlt().solve(h * (f.force - kNormalForce * kNormal + ramp * external) + h * h * f.Stiffness() * b->v);
    b->v = P * (b->v + dv);  // the normal load is held fixed
    b->z = AdvanceBristle(p, f.normal_force, kNormal, b->v, b->z, h);
    b->x += h * b->v;
  }
}

TEST(ContactLawTest, PushedBlockSticksBelowTheStaticLimitAndSlidesAbove) {
  // The push rises over 5 s, then holds. (A sudden load rings the underdamped bristle spring, and in LuGre the
  // ringing's slip speed alone, above v_s, lowers g toward μ_d F_n and breaks the contact loose; a fast ramp
  // does the same through the creep speed: LuGre's rate-dependent break-away.)
  const ContactParams p = Params();
  const double limit = 0.6 * kNormalForce, ratio = 0.9;  // push / μ_s F_n
  Block held;
  Push(p, ratio * limit * kTangent, 1e-3, 12000, &held, 5000);
  EXPECT_LT(held.v.norm(), 1e-9) << "at rest again";
  EXPECT_NEAR(held.z.dot(kTangent) * p.bristle_stiffness / (ratio * limit), 1, 1e-9) << "bristles carry the push";
  // Presliding drift: while loading, ż = v (1 − r) with r = σ0 z / g, so the block moves
  // ∫ dz / (1 − r) = z_max (−ln(1 − r)) for z_max = μ_s F_n / σ0 — quasi-statically and without the Stribeck
  // drop; inertia and the drop add a few percent.
  const double drift = limit / p.bristle_stiffness * -std::log(1 - ratio);
  EXPECT_GT(held.x.dot(kTangent), drift);
  EXPECT_LT(held.x.dot(kTangent), 1.1 * drift);
  Block sliding;
  Push(p, 1.1 * limit * kTangent, 1e-3, 7000, &sliding, 5000);
  EXPECT_GT(sliding.v.dot(kTangent), 1.0);
}

TEST(ContactLawTest, LinearisationDoesNotBiasASteadySlide) {
  // Pushed with exactly g(v) + c_t v at v and with the bristles at their steady state, the block keeps v: the
  // bristle stiffness vanishes along a saturated slip (a plain −σ0 P would add a drag σ0 h v = 1 N).
  const ContactParams p = Params();
  const double v = 0.1;
  Block b;
  b.v = v * kTangent;
  b.z = SteadyBristle(p, b.v);
  const Vec3 push = (StribeckLimit(p, kNormalForce, v) + p.viscous_friction * v) * kTangent;
  Push(p, push, 1e-3, 1000, &b);
  EXPECT_NEAR(b.v.dot(kTangent) / v, 1, 1e-9);
}

TEST(ContactLawTest, ImplicitStepFrictionFollowsTheNormalForceToTheBristlesAtItsEnd) {
  // A contact slipping at 1 m/s (2.5 bristle lengths per 1 ms step) whose normal force falls by 2 % over the step
  // (it separates at 1 cm/s). The friction the linearly implicit step applies, F + K dt v⁺ + D (v⁺ − v), must be
  // the bristle force at the step's end, −σ0 z⁺ with z⁺ advanced with the step's end normal force — the one the
  // next step starts from — whether the bristles were new (z = 0: a contact that just began) or saturated.
  // Holding a new contact's friction at the start's normal force was 0.06 N (1.4 %) off here.
  ContactParams p = Params();
  p.viscous_friction = 0;  // the bristles alone (σ1 has fallen to e^{−10⁴} σ1 at this slip)
  const double dt = 1e-3, depth = kNormalForce / p.stiffness;
  const Vec3 v = 1.0 * kTangent, v_end = v + 0.01 * kNormal;
  for (const Vec3& z : {Vec3(Vec3::Zero()), SteadyBristle(p, v)}) {
    const ContactForce f = EvaluateContact(p, depth, kNormal, v, z, dt);
    const Mat3 K = f.Stiffness() + f.k_slip_normal * f.slip_direction * kNormal.transpose();
    const Mat3 D = f.Damping() + f.d_slip_normal * f.slip_direction * kNormal.transpose();
    const Vec3 applied = Tangential(f.force + K * (dt * v_end) + D * (v_end - v));
    const double end_normal = StepEndNormalForce(p, f.normal_force, depth, kNormal, v_end, dt);
    EXPECT_NEAR(end_normal, kNormalForce - (p.damping + p.stiffness * dt) * 0.01, 1e-12);
    const Vec3 end_bristle = AdvanceBristle(p, end_normal, kNormal, v_end, z, dt);
    EXPECT_LT((applied + p.bristle_stiffness * end_bristle).norm(), 1e-3) << "z = " << z.transpose();
  }
}

TEST(ContactLawTest, CombinedParamsPutSurfacesInSeriesAndAverageFriction) {
  ContactParams a = Params(), b = Params();
  b.stiffness = 3e4;
  b.damping = 30;
  b.static_friction = 0.8;
  b.dynamic_friction = 0.6;
  b.bristle_stiffness = 3e4;
  b.bristle_damping = 10;
  b.viscous_friction = 0.15;
  b.stribeck_velocity = 3e-2;
  const ContactParams c = CombineContactParams(a, b);
  EXPECT_DOUBLE_EQ(c.stiffness, 1e4 * 3e4 / 4e4);
  EXPECT_DOUBLE_EQ(c.damping, 10.0 * 30 / 40);
  EXPECT_DOUBLE_EQ(c.static_friction, 0.7);
  EXPECT_DOUBLE_EQ(c.dynamic_friction, 0.5);
  EXPECT_DOUBLE_EQ(c.bristle_stiffness, 2e4);
  EXPECT_DOUBLE_EQ(c.bristle_damping, 20);
  EXPECT_DOUBLE_EQ(c.viscous_friction, 0.1);
  EXPECT_DOUBLE_EQ(c.stribeck_velocity, 2e-2);
  const ContactParams swapped = CombineContactParams(b, a);
  EXPECT_EQ(swapped.stiffness, c.stiffness);
  EXPECT_EQ(swapped.static_friction, c.static_friction);
  const ContactParams same = CombineContactParams(a, a);
  EXPECT_DOUBLE_EQ(same.stiffness, a.stiffness / 2) << "two equal layers in series";
  EXPECT_DOUBLE_EQ(same.static_friction, a.static_friction);
  b.stiffness = 0;  // an infinitely soft layer carries nothing
  EXPECT_EQ(CombineContactParams(a, b).stiffness, 0);
}

}  // namespace
}  // namespace graspsim
