// The Bullet backend (physics/engine.h): the scene model built as a btMultiBodyDynamicsWorld (Debian's libbullet
// 3.24, its double-precision build: BT_USE_DOUBLE_PRECISION, the -float64 libraries), its state copied in before a
// Step call and out after it.
//
// How the scene maps onto Bullet:
//   - the world: btMultiBodyDynamicsWorld with btMultiBodyConstraintSolver, btDefaultCollisionConfiguration,
//     btCollisionDispatcher and btDbvtBroadphase; one stepSimulation(h, 0) per sub-step (h = time_step / substeps;
//     maxSubSteps 0 = exactly one step of h). Bullet has one integrator, semi-implicit Euler with its
//     sequential-impulse solver, so SimulationParams.integrator is ignored. Solver: 50 iterations, pybullet's
//     default (Bullet's own 10 leave a sliding box's friction unconverged: 0.07–1.1 % off its closed-form
//     acceleration at 1 ms, worse at finer steps; 50 make it exact); otherwise Bullet's defaults: ERP 0.2,
//     split impulse for rigid bodies deeper than 4 cm, warm starting 0.85, no linear slop, two friction
//     directions per contact point (btMultiBodyDynamicsWorld's setting), the first along the sliding velocity.
//   - a free object: a btRigidBody whose frame sits at the centre of mass along the principal axes of its inertia
//     (Bullet takes principal moments; the tensor is diagonalised when it has products of inertia), so Bullet's
//     linear velocity is the centre-of-mass velocity SceneState keeps and both velocities are world-frame as
//     there; its geometry in a btCompoundShape posed relative to that frame. No damping, no sleeping; Bullet's
//     default gyroscopic term (implicit, body frame);
//   - a static object: a kinematic btRigidBody (mass 0, CF_KINEMATIC_OBJECT) placed at the state's pose before each
//     Step call, with no velocity (a SetBodyPoses between calls needs no rebuilding and is a teleport, not a push);
//   - a robot: one btMultiBody with a fixed base welded at the state pose of its base body (moved before each Step
//     call), one link per joint in topological order: revolute and continuous → setupRevolute, prismatic →
//     setupPrismatic, fixed → setupFixed; each link's frame at its centre of mass along its principal axes (as
//     Bullet's URDF importer does); limits of revolute and prismatic joints as btMultiBodyJointLimitConstraint,
//     mimic joints as btMultiBodyGearConstraint (a velocity constraint with position feedback: the follower
//     tracks the leader to within the solver's tolerance, not exactly as graspsim's reduced coordinates do);
//     no damping, gyroscopic term on, no sleeping; a robot's links never collide with each other. Links joined to
//     the base through fixed joints only are static colliders (Bullet's URDF importer does the same);
//   - geometry: boxes (btBoxShape), spheres, cylinders along z (btCylinderShapeZ), meshes by their convex hull
//     (btConvexHullShape: Bullet collides moving bodies as convex shapes), except on static objects, which keep
//     the triangles (btBvhTriangleMeshShape). Collision margins: boxes and cylinders keep their size with a
//     0.1 mm margin inside the shape (Bullet's default of up to 4 cm rounds edges and corners), convex hulls grow
//     by a 0.1 mm margin (Bullet adds a hull's margin outside), a sphere is all margin;
//   - friction: the material's dynamic μ; Bullet MULTIPLIES the two bodies' coefficients (combined = f_a · f_b),
//     so each body gets √μ and two equal materials combine to μ (two different ones to their geometric mean);
//     no rolling or spinning friction, restitution 0. Contact stiffness and damping, LuGre bristles and the
//     static μ are graspsim's contact law and do not apply: Bullet's contacts are rigid (complementarity solved by
//     sequential impulses, penetration corrected by ERP);
//   - drives: graspsim's DC-motor model (physics/actuators.h) each sub-step. Its output, f + D (q̇⁺ − q̇) with
//     D = ∂force/∂q̇ ≤ 0, is c (v_t − q̇⁺) with c = −D and v_t = q̇ + f / c: a damper toward v_t, which enters
//     Bullet's solver as a soft joint-velocity row (DriveDamper: a btMultiBodyJointMotor with a compliance of
//     1 / (c h), velocity per impulse, which makes its impulse c h (v_t − q̇⁺)), so the drive is implicit in
//     the step as in the other engines; a drive without damping applies f as a joint force;
//   - contacts: the dispatcher's manifold points that penetrate or carry a normal impulse; body_a = Bullet's body 0
//     (its userIndex is our body index), the normal Bullet's normal on body 1 (from b into a), depth −distance, the
//     point midway between the two witness points, the force on body_a the normal and friction impulses over h.
//   - tactile pads: the foam as one more box in its link's compound (physics/pad_readout.h), read through the ray
//     sensor from the impulses on that child shape (PadReadout); Bullet keeps one friction per collider, so a
//     link carrying a pad takes the foam's dynamic μ (the finger's own material gives way to it); curved pads
//     are refused.
// Not simulated (refused or left at zero, docs/physics.md): joint wrenches (the force/torque sensor), sleeping.
#include "physics/bullet_engine.h"

#include <btBulletDynamicsCommon.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyGearConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <memory>

#include "core/error.h"
#include "core/format.h"
#include "physics/actuators.h"
#include "physics/pad_readout.h"

#ifndef BT_USE_DOUBLE_PRECISION
#error "bullet_engine.cpp needs Bullet's double-precision headers (BT_USE_DOUBLE_PRECISION, the -float64 libraries)"
#endif

namespace graspsim {
namespace {

constexpr double kMargin = 1e-4;  // m: collision margin of boxes, cylinders and convex hulls (header comment)

btVector3 Bt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
btQuaternion Bt(const Quat& q) { return btQuaternion(q.x(), q.y(), q.z(), q.w()); }
btTransform Bt(const Pose& p) { return btTransform(Bt(p.orientation), Bt(p.position)); }
Vec3 ToVec(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }
// `near`: the quaternion's sign is chosen on its side, so a pose read back keeps the sign it was written with.
Pose ToPose(const btTransform& t, const Quat& near) {
  const btQuaternion q = t.getRotation();
  Quat out(q.w(), q.x(), q.y(), q.z());
  out.normalize();
  if (out.dot(near) < 0) out.coeffs() *= -1;
  return {ToVec(t.getOrigin()), out};
}

// A body's Bullet frame: at its centre of mass along the principal axes of its inertia, and its principal moments.
struct PrincipalFrame {
  Pose frame;          // in the body frame
  double mass = 0;
  Vec3 moments = Vec3::Zero();
};

PrincipalFrame Principal(const Inertial& inertial) {
  PrincipalFrame p;
  p.frame.position = inertial.center_of_mass;
  // Bullet refuses nothing, but a massless link (URDF frames) would make the articulated inertia singular: it gets
  // a negligible mass, as in the MuJoCo backend.
  p.mass = std::max(inertial.mass, 1e-9);
  const double scale = inertial.mass > 0 ? 1.0 : 0.0;
  const Mat3& I = inertial.inertia;
  if (I(0, 1) == 0 && I(0, 2) == 0 && I(1, 2) == 0) {
    p.moments = I.diagonal();
  } else {
    Eigen::SelfAdjointEigenSolver<Mat3> eigen(I);
    Mat3 axes = eigen.eigenvectors();
    if (axes.determinant() < 0) axes.col(2) *= -1;
    p.frame.orientation = Quat(axes).normalized();
    p.moments = eigen.eigenvalues();
  }
  for (int a = 0; a < 3; ++a) p.moments[a] = std::max(scale * p.moments[a], 1e-12);
  return p;
}

// Bullet's world and everything in it. The world is declared last: it is destroyed first, while the collision
// objects it unregisters still exist.
struct BulletWorld {
  std::unique_ptr<btDefaultCollisionConfiguration> configuration;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btMultiBodyConstraintSolver> solver;
  std::vector<std::unique_ptr<btStridingMeshInterface>> meshes;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btRigidBody>> rigid_bodies;
  std::vector<std::unique_ptr<btMultiBody>> multibodies;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders;
  std::vector<std::unique_ptr<btMultiBodyConstraint>> constraints;
  std::unique_ptr<btMultiBodyDynamicsWorld> world;

  // Everything, the world first.
  void Clear() {
    world.reset();
    constraints.clear();
    colliders.clear();
    multibodies.clear();
    rigid_bodies.clear();
    shapes.clear();
    meshes.clear();
    solver.reset();
    broadphase.reset();
    dispatcher.reset();
    configuration.reset();
  }
};

// A drive's damper (header comment): Bullet's velocity motor row, made soft. The motor's row asks for
// λ = (v_t − q̇) / a with a = J M⁻¹ Jᵀ (1 / m_jacDiagABInv); a compliance ε = 1 / (c h) makes it
// λ = (v_t − q̇) / (a + ε) = c h (v_t − q̇⁺). The multibody solver's row update is
// Δλ = rhs − cfm λ − (J Δv) m_jacDiagABInv, so ε enters as Bullet's own soft rows do: m_jacDiagABInv = 1 / (a + ε),
// rhs scaled alike, cfm = ε m_jacDiagABInv.
class DriveDamper : public btMultiBodyJointMotor {
 public:
  DriveDamper(btMultiBody* body, int link) : btMultiBodyJointMotor(body, link, 0, 0) { setPositionTarget(0, 0); }
  void Set(double damping, double target, double h) {
    damping_ = damping, h_ = h;
    setVelocityTarget(target, 1);
    setMaxAppliedImpulse(1e12);
  }
  void Off() { damping_ = 0, setMaxAppliedImpulse(0); }
  void createConstraintRows(btMultiBodyConstraintArray& rows, btMultiBodyJacobianData& data,
                            const btContactSolverInfo& info) override {
    const int first = rows.size();
    btMultiBodyJointMotor::createConstraintRows(rows, data, info);
    if (!(damping_ > 0)) return;
    const double compliance = 1 / (damping_ * h_);
    for (int r = first; r < rows.size(); ++r) {
      btMultiBodySolverConstraint& row = rows[r];
      if (!(row.m_jacDiagABInv > 0)) continue;
      const double soft = 1 / (1 / row.m_jacDiagABInv + compliance);
      row.m_rhs *= soft / row.m_jacDiagABInv;
      row.m_cfm = compliance * soft;
      row.m_jacDiagABInv = soft;
    }
  }

 private:
  double damping_ = 0, h_ = 1;
};

class BulletEngine : public PhysicsEngine {
 public:
  explicit BulletEngine(std::shared_ptr<const SceneModel> model) : model_(std::move(model)) { Build(); }

  const SceneModel& model() const override { return *model_; }

  void PrepareState(SceneState* state) const override {
    PrepareStateWithoutExtras(*model_, state);
    if (pads_) pads_->Prepare(state);
  }

  using PhysicsEngine::Step;
  StepStats Step(SceneState* state, int steps, Readings /*recorded always: they come with the step*/) override {
    const SceneState backup = *state;
    PrepareState(state);
    try {
      CopyIn(*state);
      const int substeps = model_->simulation.substeps;
      const double h = model_->simulation.time_step / substeps;
      for (int s = 0; s < steps; ++s) {
        for (int sub = 0; sub < substeps; ++sub) {
          Drive(state, h);
          bullet_.world->stepSimulation(h, 0);
          RecordDrives(state);
          CheckVelocities(*state);
        }
        ++state->step;
        state->time += model_->simulation.time_step;
      }
      CopyOut(state);
      ReadContacts(state, h);
      if (pads_) pads_->Record(pad_loads_, state);
      CheckFinite(*state);
    } catch (...) {
      *state = backup;
      // Bullet's caches (warm-started impulses, contact manifolds) may hold what diverged: start over.
      bullet_.Clear();
      Build();
      throw;
    }
    StepStats stats;
    stats.contacts = contacts_.size();
    for (const BodySpec& body : model_->bodies) stats.awake_bodies += body.motion == BodyMotion::kFree;
    return stats;
  }

  const std::vector<ContactPoint>& contacts() const override { return contacts_; }
  const std::vector<Vec3>& contact_forces() const override { return forces_; }

 private:
  // Per robot: its multibody, and per link (joint in topological order) the joint and child body.
  struct Robot {
    btMultiBody* multibody = nullptr;
    size_t base = 0;
    std::vector<size_t> joints, children;
  };

  void Build();
  // A body's collision geometry, then the foam of each pad on it (child shapes in this order).
  std::vector<Geometry> Geometries(size_t body) const;
  // Friction of a body's collider: √μ (Bullet multiplies the two), μ the foam's when a pad is on it.
  double Friction(size_t body) const;
  btCompoundShape* Shapes(const std::vector<Geometry>& geometries, const Pose& frame, bool concave_meshes);
  void BuildRobot(size_t r);
  void CopyIn(const SceneState& state);
  void CopyOut(SceneState* state);
  void Drive(SceneState* state, double h);
  void RecordDrives(SceneState* state) const;
  void ReadContacts(SceneState* state, double h);
  // The pad whose foam is child shape `child` of body `body`'s compound, or -1.
  int PadOfChild(int body, int child) const {
    const int first_foam = static_cast<int>(model_->bodies[body].collision.size());
    if (child < first_foam) return -1;
    const std::vector<uint32_t>& pads = pads_on_[body];
    return child - first_foam < static_cast<int>(pads.size()) ? static_cast<int>(pads[child - first_foam]) : -1;
  }
  void CheckVelocities(const SceneState& state) const;
  void CheckFinite(const SceneState& state) const;
  [[noreturn]] void Diverged(const SceneState& state, const std::string& what) const {
    throw Error(ErrorCode::kFailedPrecondition, "simulation (engine bullet) diverged at step " +
                                                    std::to_string(state.step + 1) + ": " + what +
                                                    "; reduce time_step or raise substeps");
  }

  std::shared_ptr<const SceneModel> model_;
  BulletWorld bullet_;
  std::vector<PrincipalFrame> frames_;     // per body: its Bullet frame (identity for static bodies and bases)
  std::vector<btRigidBody*> rigid_of_;     // per body: its rigid body (free and static objects), or null
  std::vector<Robot> robots_;              // per robot
  std::vector<DriveDamper*> damper_of_joint_;  // per joint: its drive's damper (moving joints of robots), or null
  // The sub-step's drives: the joint, its multibody and link, its velocity before the step, the motor's output.
  struct DriveStep {
    size_t joint = 0;
    btMultiBody* multibody = nullptr;
    int link = 0;
    double velocity_before = 0;
    ActuatorOutput output;
  };
  std::vector<DriveStep> drives_;
  std::vector<int> link_of_;               // per body: its multibody link, -1 (a base) or -2 (not a robot's)
  std::vector<int> robot_of_;              // per body: its robot, or -1
  std::vector<int> link_of_joint_;         // per joint: its multibody link
  btAlignedObjectArray<btQuaternion> scratch_q_;
  btAlignedObjectArray<btVector3> scratch_v_;
  std::vector<ContactPoint> contacts_;
  std::vector<Vec3> forces_;
  std::unique_ptr<PadReadout> pads_;  // when the scene has tactile pads
  std::vector<std::vector<uint32_t>> pads_on_;  // per body: the pads mounted on it
  std::vector<PadLoad> pad_loads_;    // ReadContacts: the contact forces on each pad's foam
};

std::vector<Geometry> BulletEngine::Geometries(size_t body) const {
  std::vector<Geometry> geometries = model_->bodies[body].collision;
  for (uint32_t p : pads_on_[body]) geometries.push_back(FoamBox(model_->tactile_arrays[p]));
  return geometries;
}

double BulletEngine::Friction(size_t body) const {
  const std::vector<uint32_t>& pads = pads_on_[body];
  const double mu = pads.empty() ? model_->bodies[body].material.dynamic_friction
                                 : model_->tactile_arrays[pads[0]].contact.dynamic_friction;
  return std::sqrt(std::max(mu, 0.0));
}

btCompoundShape* BulletEngine::Shapes(const std::vector<Geometry>& geometries, const Pose& frame,
                                      bool concave_meshes) {
  auto compound = std::make_unique<btCompoundShape>();
  const Pose to_frame = frame.Inverse();
  for (const Geometry& g : geometries) {
    std::unique_ptr<btCollisionShape> shape;
    switch (g.kind) {
      case Geometry::Kind::kBox:
        shape = std::make_unique<btBoxShape>(Bt(Vec3(g.box_size / 2)));
        shape->setMargin(kMargin);
        break;
      case Geometry::Kind::kSphere:
        shape = std::make_unique<btSphereShape>(g.radius);
        break;
      case Geometry::Kind::kCylinder:
        shape = std::make_unique<btCylinderShapeZ>(btVector3(g.radius, g.radius, g.length / 2));
        shape->setMargin(kMargin);
        break;
      case Geometry::Kind::kMesh:
        if (concave_meshes) {
          // The triangles as they are (float vertices, uint32 indices), read in place: the model outlives the engine.
          btIndexedMesh mesh;
          mesh.m_numTriangles = static_cast<int>(g.mesh->triangles.size());
          mesh.m_triangleIndexBase = reinterpret_cast<const unsigned char*>(g.mesh->triangles.data());
          mesh.m_triangleIndexStride = sizeof(g.mesh->triangles[0]);
          mesh.m_numVertices = static_cast<int>(g.mesh->vertices.size());
          mesh.m_vertexBase = reinterpret_cast<const unsigned char*>(g.mesh->vertices.data());
          mesh.m_vertexStride = sizeof(g.mesh->vertices[0]);
          mesh.m_indexType = PHY_INTEGER;
          mesh.m_vertexType = PHY_FLOAT;
          auto array = std::make_unique<btTriangleIndexVertexArray>();
          array->addIndexedMesh(mesh, PHY_INTEGER);
          shape = std::make_unique<btBvhTriangleMeshShape>(array.get(), true);
          bullet_.meshes.push_back(std::move(array));
        } else {
          auto hull = std::make_unique<btConvexHullShape>();
          for (const Eigen::Vector3f& v : g.mesh->vertices) hull->addPoint(btVector3(v.x(), v.y(), v.z()), false);
          hull->recalcLocalAabb();
          hull->optimizeConvexHull();
          hull->setMargin(kMargin);
          shape = std::move(hull);
        }
        break;
    }
    compound->addChildShape(Bt(to_frame * g.origin), shape.get());
    bullet_.shapes.push_back(std::move(shape));
  }
  btCompoundShape* out = compound.get();
  bullet_.shapes.push_back(std::move(compound));
  return out;
}

void BulletEngine::Build() {
  const SceneModel& m = *model_;
  BulletWorld& b = bullet_;
  b.configuration = std::make_unique<btDefaultCollisionConfiguration>();
  b.dispatcher = std::make_unique<btCollisionDispatcher>(b.configuration.get());
  b.broadphase = std::make_unique<btDbvtBroadphase>();
  b.solver = std::make_unique<btMultiBodyConstraintSolver>();
  b.world = std::make_unique<btMultiBodyDynamicsWorld>(b.dispatcher.get(), b.broadphase.get(), b.solver.get(),
                                                       b.configuration.get());
  b.world->getSolverInfo().m_numIterations = 50;  // pybullet's default (header comment)
  b.world->setGravity(Bt(m.simulation.gravity));  // before the bodies: a rigid body takes the world's at addition

  frames_.assign(m.bodies.size(), PrincipalFrame{});
  pads_on_.clear();
  for (size_t i = 0; i < m.bodies.size(); ++i) pads_on_.push_back(PadsOn(m, i));
  rigid_of_.assign(m.bodies.size(), nullptr);
  link_of_.assign(m.bodies.size(), -2);
  robot_of_.assign(m.bodies.size(), -1);
  link_of_joint_.assign(m.joints.size(), -1);
  damper_of_joint_.assign(m.joints.size(), nullptr);
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    const BodySpec& body = m.bodies[i];
    if (body.motion == BodyMotion::kArticulated || !body.robot_id.empty()) continue;  // robots: BuildRobot
    const bool free = body.motion == BodyMotion::kFree;
    if (free) frames_[i] = Principal(body.inertial);
    const std::vector<Geometry> geometries = Geometries(i);
    btCompoundShape* shape = Shapes(geometries, frames_[i].frame, !free);
    btRigidBody::btRigidBodyConstructionInfo info(free ? frames_[i].mass : 0.0, nullptr, shape,
                                                  free ? Bt(frames_[i].moments) : btVector3(0, 0, 0));
    // Bullet multiplies the two bodies' coefficients: √μ each, so equal materials combine to μ.
    info.m_friction = Friction(i);
    info.m_rollingFriction = 0;
    info.m_spinningFriction = 0;
    info.m_restitution = 0;
    info.m_linearDamping = 0;
    info.m_angularDamping = 0;
    auto rigid = std::make_unique<btRigidBody>(info);
    if (!free) rigid->setCollisionFlags(rigid->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    rigid->setActivationState(DISABLE_DEACTIVATION);
    rigid->setUserIndex(static_cast<int>(i));
    if (geometries.empty()) {
      b.world->addRigidBody(rigid.get(), btBroadphaseProxy::DefaultFilter, 0);  // collides with nothing
    } else {
      b.world->addRigidBody(rigid.get());
    }
    rigid_of_[i] = rigid.get();
    b.rigid_bodies.push_back(std::move(rigid));
  }
  robots_.assign(m.robots.size(), Robot{});
  for (size_t r = 0; r < m.robots.size(); ++r) BuildRobot(r);
  if (!m.tactile_arrays.empty()) pads_ = std::make_unique<PadReadout>(m);
}

void BulletEngine::BuildRobot(size_t r) {
  const SceneModel& m = *model_;
  BulletWorld& b = bullet_;
  Robot& robot = robots_[r];
  robot.base = m.body_index.at(m.robots[r].base_body);
  robot.joints = m.robot_joints[r];
  const size_t n = robot.joints.size();
  link_of_[robot.base] = -1;
  robot_of_[robot.base] = static_cast<int>(r);
  // The base's Bullet frame is its body frame (a fixed base: its mass and inertia take no part).
  const BodySpec& base = m.bodies[robot.base];
  const Vec3 base_moments = base.inertial.inertia.diagonal().cwiseMax(1e-12);
  auto multibody = std::make_unique<btMultiBody>(static_cast<int>(n), std::max(base.inertial.mass, 1e-9),
                                                 Bt(base_moments), /*fixedBase=*/true, /*canSleep=*/false);
  btMultiBody* mb = multibody.get();
  robot.multibody = mb;
  for (size_t k = 0; k < n; ++k) {
    const size_t j = robot.joints[k];
    const JointSpec& joint = m.joints[j];
    const auto [parent, child] = m.joint_bodies[j];
    robot.children.push_back(child);
    link_of_[child] = static_cast<int>(k);
    robot_of_[child] = static_cast<int>(r);
    link_of_joint_[j] = static_cast<int>(k);
    frames_[child] = Principal(m.bodies[child].inertial);
    const PrincipalFrame& link = frames_[child];
    // As Bullet's URDF importer: the joint frame in the parent's Bullet frame (A), the child's link frame (= the
    // joint frame at q = 0) in the child's Bullet frame (B).
    const Pose in_a = frames_[parent].frame.Inverse() * joint.origin;
    const Pose in_b = link.frame.Inverse();
    const btQuaternion parent_to_this = Bt(Quat(in_b.orientation * in_a.orientation.conjugate()).normalized());
    const btVector3 axis = Bt(Vec3(in_b.orientation * joint.axis));
    const int parent_link = link_of_[parent];
    switch (joint.type) {
      case JointType::kRevolute:
      case JointType::kContinuous:
        mb->setupRevolute(static_cast<int>(k), link.mass, Bt(link.moments), parent_link, parent_to_this, axis,
                          Bt(in_a.position), Bt(Vec3(-in_b.position)), true);
        break;
      case JointType::kPrismatic:
        mb->setupPrismatic(static_cast<int>(k), link.mass, Bt(link.moments), parent_link, parent_to_this, axis,
                           Bt(in_a.position), Bt(Vec3(-in_b.position)), true);
        break;
      case JointType::kFixed:
        mb->setupFixed(static_cast<int>(k), link.mass, Bt(link.moments), parent_link, parent_to_this,
                       Bt(in_a.position), Bt(Vec3(-in_b.position)));
        break;
    }
  }
  mb->finalizeMultiDof();
  mb->setHasSelfCollision(false);
  mb->setLinearDamping(0);
  mb->setAngularDamping(0);
  mb->setUseGyroTerm(true);
  mb->setCanSleep(false);
  b.world->addMultiBody(mb);

  // Colliders: the base and links joined to it through fixed joints only are static (they never move within a
  // step); every other link is dynamic.
  // Every link has a collider, an empty one colliding with nothing when it has no geometry: Bullet solves a link's
  // constraints (limits, mimic joints) in its collider's simulation island, and with none, not at all.
  auto add_collider = [&](size_t body, int link, bool is_static) {
    const std::vector<Geometry> geometries = Geometries(body);
    if (geometries.empty() && link < 0) return;  // a base needs none
    auto collider = std::make_unique<btMultiBodyLinkCollider>(mb, link);
    collider->setCollisionShape(Shapes(geometries, frames_[body].frame, false));
    collider->setFriction(Friction(body));
    collider->setRollingFriction(0);
    collider->setSpinningFriction(0);
    collider->setRestitution(0);
    collider->setUserIndex(static_cast<int>(body));
    collider->setActivationState(DISABLE_DEACTIVATION);
    if (geometries.empty()) {
      b.world->addCollisionObject(collider.get(), btBroadphaseProxy::DefaultFilter, 0);
    } else if (is_static) {
      collider->setCollisionFlags(collider->getCollisionFlags() | btCollisionObject::CF_STATIC_OBJECT);
      b.world->addCollisionObject(collider.get(), btBroadphaseProxy::StaticFilter,
                                  btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
    } else {
      b.world->addCollisionObject(collider.get(), btBroadphaseProxy::DefaultFilter, btBroadphaseProxy::AllFilter);
    }
    if (link < 0) {
      mb->setBaseCollider(collider.get());
    } else {
      mb->getLink(link).m_collider = collider.get();
    }
    b.colliders.push_back(std::move(collider));
  };
  add_collider(robot.base, -1, true);
  std::vector<bool> welded(n, false);  // joined to the base through fixed joints only
  for (size_t k = 0; k < n; ++k) {
    const int parent = link_of_[m.joint_bodies[robot.joints[k]][0]];
    welded[k] = m.joints[robot.joints[k]].type == JointType::kFixed && (parent < 0 || welded[parent]);
    add_collider(robot.children[k], static_cast<int>(k), welded[k]);
  }

  // Limits, and mimic joints: the follower's velocity tied to the leader's (q̇_f − multiplier q̇_l = 0), its
  // position error fed back at the solver's ERP (gear erp 1 × ERP 0.2 per step) toward the offset.
  for (size_t k = 0; k < n; ++k) {
    const JointSpec& joint = m.joints[robot.joints[k]];
    if ((joint.type == JointType::kRevolute || joint.type == JointType::kPrismatic) && joint.lower <= joint.upper) {
      auto limit = std::make_unique<btMultiBodyJointLimitConstraint>(mb, static_cast<int>(k), joint.lower, joint.upper);
      b.world->addMultiBodyConstraint(limit.get());
      b.constraints.push_back(std::move(limit));
    }
    if (joint.mimic && joint.type != JointType::kFixed) {
      const size_t leader = m.joint_index.at(joint.mimic->joint_id);
      if (m.joints[leader].type == JointType::kFixed || link_of_joint_[leader] < 0 ||
          robot_of_[m.joint_bodies[leader][1]] != static_cast<int>(r)) {
        continue;
      }
      auto gear = std::make_unique<btMultiBodyGearConstraint>(mb, static_cast<int>(k), mb, link_of_joint_[leader],
                                                              btVector3(0, 0, 0), btVector3(0, 0, 0),
                                                              btMatrix3x3::getIdentity(), btMatrix3x3::getIdentity());
      gear->setGearRatio(-joint.mimic->multiplier);
      gear->setRelativePositionTarget(joint.mimic->offset);
      gear->setErp(1);
      gear->setMaxAppliedImpulse(1e10);
      b.world->addMultiBodyConstraint(gear.get());
      b.constraints.push_back(std::move(gear));
    }
  }
  // Every moving joint gets a damper, off until a drive sets it (Drive).
  for (size_t k = 0; k < n; ++k) {
    const JointType type = m.joints[robot.joints[k]].type;
    if (type == JointType::kFixed) continue;
    auto damper = std::make_unique<DriveDamper>(mb, static_cast<int>(k));
    damper->Off();
    b.world->addMultiBodyConstraint(damper.get());
    damper_of_joint_[robot.joints[k]] = damper.get();
    b.constraints.push_back(std::move(damper));
  }
  b.multibodies.push_back(std::move(multibody));
}

void BulletEngine::CopyIn(const SceneState& state) {
  const SceneModel& m = *model_;
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    btRigidBody* rigid = rigid_of_[i];
    if (!rigid) continue;
    const btTransform pose = Bt(state.body_poses[i] * frames_[i].frame);
    if (m.bodies[i].motion == BodyMotion::kFree) {
      rigid->setCenterOfMassTransform(pose);  // also the world inertia tensor
      rigid->setLinearVelocity(Bt(state.body_velocities[i].linear));
      rigid->setAngularVelocity(Bt(state.body_velocities[i].angular));
      rigid->setInterpolationLinearVelocity(rigid->getLinearVelocity());
      rigid->setInterpolationAngularVelocity(rigid->getAngularVelocity());
    } else {
      // Kinematic: Bullet derives its velocity from the interpolation transform to the world transform, so both
      // are set: no velocity.
      rigid->setWorldTransform(pose);
      rigid->setInterpolationWorldTransform(pose);
      rigid->setLinearVelocity(btVector3(0, 0, 0));
      rigid->setAngularVelocity(btVector3(0, 0, 0));
      rigid->setInterpolationLinearVelocity(btVector3(0, 0, 0));
      rigid->setInterpolationAngularVelocity(btVector3(0, 0, 0));
    }
  }
  for (Robot& robot : robots_) {
    btMultiBody* mb = robot.multibody;
    mb->setBaseWorldTransform(Bt(state.body_poses[robot.base]));
    mb->setBaseVel(btVector3(0, 0, 0));
    mb->setBaseOmega(btVector3(0, 0, 0));
    for (size_t k = 0; k < robot.joints.size(); ++k) {
      if (model_->joints[robot.joints[k]].type == JointType::kFixed) continue;
      mb->setJointPos(static_cast<int>(k), state.joint_positions[robot.joints[k]]);
      mb->setJointVel(static_cast<int>(k), state.joint_velocities[robot.joints[k]]);
    }
    // The colliders where the state puts them: collision detection comes first in a step.
    mb->forwardKinematics(scratch_q_, scratch_v_);
    mb->updateCollisionObjectWorldTransforms(scratch_q_, scratch_v_);
  }
}

void BulletEngine::Drive(SceneState* state, double h) {
  for (DriveDamper* damper : damper_of_joint_) {
    if (damper) damper->Off();  // a drive switched off leaves no damping behind
  }
  drives_.clear();
  for (auto& [j, actuator] : state->actuators) {
    if (j >= link_of_joint_.size() || link_of_joint_[j] < 0 || model_->joints[j].type == JointType::kFixed) continue;
    const size_t body = model_->joint_bodies[j][1];
    btMultiBody* mb = robots_[robot_of_[body]].multibody;
    const int link = link_of_joint_[j];
    const double q = mb->getJointPos(link), q_dot = mb->getJointVel(link);
    const ActuatorOutput out = StepDcMotor(actuator.motor, actuator.command, q, q_dot, h, &actuator.state);
    actuator.voltage = out.voltage;
    DriveDamper* damper = damper_of_joint_[j];
    if (damper && out.damping < 0) {
      damper->Set(-out.damping, q_dot - out.joint_force / out.damping, h);
    } else {
      mb->addJointTorque(link, out.joint_force);
    }
    drives_.push_back({j, mb, link, q_dot, out});
  }
}

void BulletEngine::RecordDrives(SceneState* state) const {
  // What a drive reports is the force the step applied, f + D (q̇⁺ − q̇), as the other engines report it.
  for (const DriveStep& drive : drives_) {
    state->actuators.at(drive.joint).joint_force =
        drive.output.joint_force +
        drive.output.damping * (drive.multibody->getJointVel(drive.link) - drive.velocity_before);
  }
}

void BulletEngine::CopyOut(SceneState* state) {
  const SceneModel& m = *model_;
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    if (m.bodies[i].motion != BodyMotion::kFree || !rigid_of_[i]) continue;
    const btRigidBody* rigid = rigid_of_[i];
    Pose& pose = state->body_poses[i];
    const Quat near = (pose * frames_[i].frame).orientation;
    pose = ToPose(rigid->getWorldTransform(), near) * frames_[i].frame.Inverse();
    state->body_velocities[i].linear = ToVec(rigid->getLinearVelocity());
    state->body_velocities[i].angular = ToVec(rigid->getAngularVelocity());
  }
  for (Robot& robot : robots_) {
    btMultiBody* mb = robot.multibody;
    mb->forwardKinematics(scratch_q_, scratch_v_);  // the links' world transforms after the last step
    for (size_t k = 0; k < robot.joints.size(); ++k) {
      const size_t j = robot.joints[k], child = robot.children[k];
      Pose& pose = state->body_poses[child];
      const Quat near = (pose * frames_[child].frame).orientation;
      pose = ToPose(mb->getLink(static_cast<int>(k)).m_cachedWorldTransform, near) * frames_[child].frame.Inverse();
      if (m.joints[j].type == JointType::kFixed) continue;
      state->joint_positions[j] = mb->getJointPos(static_cast<int>(k));
      state->joint_velocities[j] = mb->getJointVel(static_cast<int>(k));
    }
  }
}

void BulletEngine::ReadContacts(SceneState* state, double h) {
  contacts_.clear();
  forces_.clear();
  pad_loads_.clear();
  const bool two_directions = bullet_.world->getSolverInfo().m_solverMode & SOLVER_USE_2_FRICTION_DIRECTIONS;
  btDispatcher* dispatcher = bullet_.world->getDispatcher();
  for (int i = 0; i < dispatcher->getNumManifolds(); ++i) {
    const btPersistentManifold* manifold = dispatcher->getManifoldByIndexInternal(i);
    const int a = manifold->getBody0()->getUserIndex(), b = manifold->getBody1()->getUserIndex();
    if (a < 0 || b < 0) continue;
    for (int p = 0; p < manifold->getNumContacts(); ++p) {
      const btManifoldPoint& c = manifold->getContactPoint(p);
      if (!(c.getDistance() < 0) && !(c.m_appliedImpulse > 0)) continue;  // a speculative point, not touching
      ContactPoint& point = contacts_.emplace_back();
      point.body_a = static_cast<uint32_t>(a);
      point.body_b = static_cast<uint32_t>(b);
      point.feature = (static_cast<uint64_t>(i) << 32) | static_cast<uint64_t>(p);
      point.point = ToVec((c.getPositionWorldOnA() + c.getPositionWorldOnB()) * 0.5);
      point.normal = ToVec(c.m_normalWorldOnB);
      point.depth = -c.getDistance();
      btVector3 impulse = c.m_appliedImpulse * c.m_normalWorldOnB + c.m_appliedImpulseLateral1 * c.m_lateralFrictionDir1;
      if (two_directions) impulse += c.m_appliedImpulseLateral2 * c.m_lateralFrictionDir2;
      forces_.push_back(ToVec(impulse / h));
      // On a pad's foam (a child shape after the body's own geometry): the force on the pad.
      if (pads_) {
        if (const int pad = PadOfChild(a, c.m_index0); pad >= 0) AddPadLoad(&pad_loads_, pad, b, forces_.back());
        if (const int pad = PadOfChild(b, c.m_index1); pad >= 0) AddPadLoad(&pad_loads_, pad, a, -forces_.back());
      }
    }
  }
  state->contacts.resize(contacts_.size());
  for (size_t i = 0; i < contacts_.size(); ++i) {
    state->contacts[i] = {contacts_[i].body_a, contacts_[i].body_b, contacts_[i].point, forces_[i]};
  }
}

// After each sub-step, on Bullet's own values: stop before a NaN reaches the broadphase.
void BulletEngine::CheckVelocities(const SceneState& state) const {
  const double limit = model_->simulation.divergence_speed;
  for (size_t i = 0; i < model_->bodies.size(); ++i) {
    if (model_->bodies[i].motion != BodyMotion::kFree || !rigid_of_[i]) continue;
    const btRigidBody* rigid = rigid_of_[i];
    const double v = rigid->getLinearVelocity().length(), w = rigid->getAngularVelocity().length();
    if (!(v < limit) || !(w < limit) || !std::isfinite(rigid->getWorldTransform().getOrigin().length())) {
      Diverged(state, "body '" + model_->bodies[i].id + "' moves faster than " + FormatNumber(limit));
    }
  }
  for (const Robot& robot : robots_) {
    for (size_t k = 0; k < robot.joints.size(); ++k) {
      if (model_->joints[robot.joints[k]].type == JointType::kFixed) continue;
      const double q = robot.multibody->getJointPos(static_cast<int>(k));
      const double q_dot = robot.multibody->getJointVel(static_cast<int>(k));
      if (!std::isfinite(q) || !(std::abs(q_dot) < limit)) {
        Diverged(state, "joint '" + model_->joints[robot.joints[k]].id + "' velocity " + FormatNumber(q_dot));
      }
    }
  }
}

void BulletEngine::CheckFinite(const SceneState& state) const {
  const double limit = model_->simulation.divergence_speed;
  for (size_t i = 0; i < model_->bodies.size(); ++i) {
    const BodyVelocity& v = state.body_velocities[i];
    if (!state.body_poses[i].position.allFinite() || !state.body_poses[i].orientation.coeffs().allFinite() ||
        !(v.linear.norm() < limit) || !(v.angular.norm() < limit)) {
      Diverged(state, "body '" + model_->bodies[i].id + "' moves faster than " + FormatNumber(limit));
    }
  }
  for (size_t j = 0; j < model_->joints.size(); ++j) {
    if (!std::isfinite(state.joint_positions[j]) || !(std::abs(state.joint_velocities[j]) < limit)) {
      Diverged(state, "joint '" + model_->joints[j].id + "' velocity " + FormatNumber(state.joint_velocities[j]));
    }
  }
}

}  // namespace

std::shared_ptr<PhysicsEngine> MakeBulletEngine(std::shared_ptr<const SceneModel> model) {
  return std::make_shared<BulletEngine>(std::move(model));
}

}  // namespace graspsim
