// The dynamic simulation of one scene, as a readable list of stages per step (MuJoCo's mj_step):
//   FindContacts → ContactForces → ActuatorForces → SolveVelocityChange (⇄ LimitCurrents) → AdvanceBristles → Integrate
//   → RecordJointWrenches → ClampJointLimits → UpdateSleep, then CheckFinite.
// Contacts are soft (penalty normal force, LuGre friction; physics/contact_law.h) at the surface samples the
// collision library finds; the articulated dynamics are physics/multibody.h. The linearly implicit integrator
// solves (M − h D − h² K) Δv = h (τ − b + f + h K v) with K, D the contact stiffness and damping mapped to
// generalised coordinates (Baraff & Witkin 1998), so stiff contacts stay stable at millisecond steps; the
// semi-implicit (symplectic) Euler integrator (first order) is the cheaper reference, velocity Verlet
// (second order, symplectic, exact under constant forces, two contact evaluations per step) the energy-keeping one
// for smooth motion, and classic Runge–Kutta (fourth order, four evaluations) the most accurate one for it. Static bodies never move; free
// bodies at rest fall asleep and are skipped until something touches them.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/LU>

#include "collision/contact_finder.h"
#include "physics/actuators.h"
#include "physics/contact_law.h"
#include "physics/engine.h"
#include "physics/multibody.h"
#include "physics/simulation_model.h"
#include "tactile/ray_caster.h"
#include "world/model.h"
#include "world/state.h"

namespace graspsim {
namespace contact_kernel {
struct ContactRun;
}

// Checks a parameter set at the boundary; throws Error(kInvalidArgument) naming the field.
void ValidateSimulationParams(const SimulationParams& params);

class Simulation : public PhysicsEngine {
 public:
  // A simulation of `model` on its shared SimulationModel (physics/simulation_model.h: built once per SceneModel,
  // the degrees of freedom, surface samples, mesh BVHs); the parameters are the model's (SceneModel::simulation).
  // A Simulation keeps its step's working buffers only: one caller at a time, any number per SimulationModel.
  explicit Simulation(std::shared_ptr<const SceneModel> model);
  explicit Simulation(std::shared_ptr<const SimulationModel> compiled);

  const SceneModel& model() const override { return *model_; }
  void PrepareState(SceneState* state) const override;

  // Advances `steps` steps. On divergence throws Error(kFailedPrecondition) naming the body or joint, the step
  // and the quantity, and leaves *state as it was before the call.
  using PhysicsEngine::Step;
  StepStats Step(SceneState* state, int steps, Readings readings) override;

  // The contact points and their forces (on body_a, world, N) of the last sub-step. Tactile pad contacts are
  // among them: body_a the touching body, body_b the pad's link, feature = PadFeature(pad, element) (tactile/pad_contacts.h).
  const std::vector<ContactPoint>& contacts() const override { return contacts_; }
  const std::vector<Vec3>& contact_forces() const override { return forces_; }

 private:
  // Generalised forces at one configuration; the linearised contacts only for the linearly implicit integrator.
  struct Forces {
    Eigen::VectorXd tau, actuators;
    Eigen::VectorXd actuator_damping, actuator_stiffness;  // per generalised velocity (diagonal), ≤ 0
    Eigen::MatrixXd contact_matrix;  // h D + h² K: the contacts' damping and stiffness at the sub-step h
    Eigen::VectorXd contact_rhs;     // h² K v
    // Per touching body pair (contacts come sorted by pair): W = W_a − W_b, the relative spatial Jacobian, so
    // the relative velocity of a contact point p is (W v).tail + (W v).head × p.
    // The first pair_count are this evaluation's; the rest are kept for their buffers (no allocation per step).
    std::vector<Multibody::SpatialJacobian> pair_jacobians;
    size_t pair_count = 0;
    std::vector<double> normal_force;  // per contact, N
  };

  // The stages of one sub-step, in order.
  // record_readings: this sub-step records what the sensors read (joint wrenches, pad forces): Step's last one.
  void SubStep(SceneState* state, double h, bool record_readings);
  void RungeKutta4(const Eigen::VectorXd& v, double h, SceneState* state, bool record_readings);
  static void HoldDrives(const Forces& first, Forces* later);
  void FindContacts(SceneState* state);
  void AddPadContacts(const SceneState& state);
  void RecordPadForces(SceneState* state) const;
  void RecordJointWrenches(const Eigen::VectorXd& v, const Eigen::VectorXd& v_next, double h,
                           SceneState* state) const;
  void ContactForces(const SceneState& state, const Eigen::VectorXd& v, double h, Forces* forces);
  void ActuatorForces(SceneState* state, double h, Forces* forces);
  bool LimitCurrents(const Eigen::VectorXd& v, const Eigen::VectorXd& v_next, double h, SceneState* state,
                     Forces* forces);
  void RecordDriveOutputs(const Eigen::VectorXd& v, const Eigen::VectorXd& v_next, double h, SceneState* state) const;
  // Δv over h from v; the bias forces at bias_velocity when given (else at v).
  Eigen::VectorXd SolveVelocityChange(const SceneState& state, const Eigen::VectorXd& v, const Forces& forces,
                                      double h, const Eigen::VectorXd* bias_velocity = nullptr);
  void AdvanceBristles(const Forces& forces, const Eigen::VectorXd& v, double h, SceneState* state);

  void UpdateSleep(SceneState* state, double h) const;
  ContactParams PairParams(uint32_t a, uint32_t b) const;
  void ClampJointLimits(SceneState* state) const;
  void CheckFinite(const SceneState& state) const;

  // The shared, immutable model and views into it (SimulationModel's accessors say what each is).
  std::shared_ptr<const SimulationModel> compiled_;
  std::shared_ptr<const SceneModel> model_;
  const SimulationParams& params_;
  const Multibody& multibody_;
  const ContactFinder& finder_;
  const TactileRayCaster& pads_;
  const std::vector<ContactParams>& pad_params_;
  const std::vector<uint32_t>& pad_links_;
  const std::vector<ContactParams>& body_params_;
  // Per scene, from here on: what the last step found, and the step's buffers.
  std::vector<ContactPoint> contacts_;
  std::vector<PadHit> pad_hits_;
  std::vector<Vec3> forces_;
  // Buffers reused from step to step (a work cycle steps one step per call: allocations would dominate).
  SceneState backup_;                    // the state before Step, restored on divergence
  SceneState stage_start_;               // RungeKutta4: the sub-step's start, each stage's origin
  Forces forces_at_start_, forces_at_end_;  // of a sub-step (the end's only for velocity Verlet)
  std::vector<std::pair<ContactKey, Vec3>> spare_bristles_;  // swapped with the state's each sub-step
  std::vector<Multibody::Vec6> twists_;  // per pair
  Multibody::SpatialJacobian jacobian_b_;  // ContactForces: W_b of the pair at hand, its buffer reused
  Multibody::SpatialJacobian block_times_jacobian_;  // ContactForces: the pair's 6 × 6 block times its W
  Eigen::MatrixXd solve_matrix_;           // SolveVelocityChange's system, its factors and right-hand side
  Eigen::PartialPivLU<Eigen::MatrixXd> solve_lu_;
  Eigen::VectorXd solve_rhs_;
  // Per contact, one array per coordinate: the contact kernel's inputs and outputs (physics/contact_kernel.h),
  // filled by ContactForces; AdvanceBristles reads the same contacts (the last evaluation's) and writes next_z*.
  struct ContactColumns {
    std::vector<double> px, py, pz, nx, ny, nz, depth, zx, zy, zz, fx, fy, fz, next_zx, next_zy, next_zz;
    void Resize(size_t n);
  };
  ContactColumns columns_;
  // The runs of contacts [begin, end) of one pair and one law (the contact kernel's unit) of the last
  // ContactForces, in order, with their pair's index.
  struct ContactRunRange {
    size_t begin = 0, end = 0, pair = 0;
    ContactParams law;  // the run's law, combined once per evaluation (RunLaw)
  };
  std::vector<ContactRunRange> runs_;
  // The law the run starting at contact `begin` obeys; the contact kernel's view of a run in columns_, moving
  // with `twist`.
  ContactParams RunLaw(size_t begin) const;
  contact_kernel::ContactRun Run(const ContactRunRange& range, const Multibody::Vec6& twist, double h) const;
  bool bristles_aligned_ = false;  // the last ContactForces: contact i's bristle is state.bristles[i], for every i
  // Per contact pair of the last ContactForces: its bodies and the wrench [Σ p × f; Σ f] on body_a.
  struct PairWrench {
    uint32_t body_a = 0, body_b = 0;
    Multibody::Vec6 wrench;
  };
  std::vector<PairWrench> pair_wrenches_;
  // The sub-step's driven joints: the motor's state before the step and its output (ActuatorForces).
  struct Drive {
    size_t joint = 0;
    int offset = 0;
    DcMotorState state_before;
    ActuatorOutput output;
  };
  std::vector<Drive> drives_;
};

}  // namespace graspsim
