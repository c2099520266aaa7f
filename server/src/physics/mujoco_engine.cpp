// The MuJoCo backend (physics/engine.h): the scene model written as MJCF and compiled by MuJoCo's own loader
// (Debian's libmujoco 2.2.2), its state copied in before a Step call and out after it.
//
// How the scene maps onto MuJoCo:
//   - a free object: a body with a free joint whose frame sits at the object's centre of mass (same orientation),
//     so the free joint's linear velocity is the centre-of-mass velocity SceneState keeps; geometry shifted back;
//   - a static object and a robot's base: mocap bodies, moved to the state's poses before each Step call (a
//     SetBodyPoses between calls needs no recompilation);
//   - robot links: bodies nested along the joints (hinge, slide; a fixed joint welds the child), limits as MuJoCo
//     joint ranges, mimic joints as joint equality constraints; a robot's links never collide with each other;
//   - geometry: boxes, spheres, cylinders as such, meshes by their convex hull (MuJoCo collides hulls only);
//   - friction: one coefficient per geom, the material's dynamic μ (MuJoCo takes the larger of two geoms');
//     contact softness MuJoCo's defaults; elliptic friction cones (the pyramid's default limits diagonal slip to
//     μ/√2);
//   - integrators: linearly implicit Euler → MuJoCo's "implicit", semi-implicit Euler → "Euler", Runge–Kutta 4
//     and velocity Verlet (the smooth-motion integrators) → "RK4";
//   - drives: graspsim's DC-motor model (physics/actuators.h) each sub-step; its force enters as an applied
//     joint force and its damping (∂force/∂q̇) as the joint's armature, h·(−∂force/∂q̇), which makes the step
//     implicit in the drive under every integrator, as graspsim's solve is (Drive).
//   - tactile pads: the foam as a box geom on the pad's link (physics/pad_readout.h) with priority 1, so its own
//     friction (the foam's dynamic μ) sets its contacts', and MuJoCo's default contact softness; read through the
//     ray sensor from MuJoCo's contact forces on it (PadReadout); curved pads are refused.
// Not simulated (refused or left at zero, docs/physics.md): joint wrenches (the force/torque sensor), sleeping.
#include "physics/mujoco_engine.h"

#include <mujoco/mujoco.h>

#include <cmath>
#include <cstring>
#include <iomanip>
#include <map>
#include <mutex>
#include <memory>
#include <sstream>

#include "core/error.h"
#include "core/format.h"
#include "core/log.h"
#include "physics/actuators.h"
#include "physics/pad_readout.h"

namespace graspsim {
namespace {

std::string Numbers(std::initializer_list<double> values) {
  std::ostringstream out;
  out << std::setprecision(17);
  bool first = true;
  for (double v : values) {
    out << (first ? "" : " ") << v;
    first = false;
  }
  return out.str();
}

std::string PosQuat(const Pose& pose) {
  const Quat& q = pose.orientation;
  return "pos=\"" + Numbers({pose.position.x(), pose.position.y(), pose.position.z()}) + "\" quat=\"" +
         Numbers({q.w(), q.x(), q.y(), q.z()}) + "\"";
}

std::string Inertia(const Inertial& inertial, const Vec3& at) {
  const Mat3& I = inertial.inertia;
  // MuJoCo refuses a moving body without mass; a massless link (URDF frames) gets a negligible one.
  const double mass = std::max(inertial.mass, 1e-9);
  const double scale = inertial.mass > 0 ? 1.0 : 0.0;
  return "<inertial pos=\"" + Numbers({at.x(), at.y(), at.z()}) + "\" mass=\"" + Numbers({mass}) +
         "\" fullinertia=\"" +
         Numbers({std::max(scale * I(0, 0), 1e-12), std::max(scale * I(1, 1), 1e-12), std::max(scale * I(2, 2), 1e-12),
                  scale * I(0, 1), scale * I(0, 2), scale * I(1, 2)}) +
         "\"/>";
}

// MuJoCo's warnings go to the server's log: its default handler appends them to MUJOCO_LOG.TXT in the working
// directory. The step reads the warnings it acts on from mjData's counters (Step).
void LogMujocoWarning(const char* message) { Log(LogLevel::kWarn, "mujoco", {{"warning", message}}); }

class MujocoEngine : public PhysicsEngine {
 public:
  explicit MujocoEngine(std::shared_ptr<const SceneModel> model) : model_(std::move(model)) {
    static std::once_flag route_warnings;
    std::call_once(route_warnings, [] { mju_user_warning = LogMujocoWarning; });
    Compile();
  }
  ~MujocoEngine() override {
    if (data_) mj_deleteData(data_);
    if (mj_) mj_deleteModel(mj_);
  }

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
      const int bad_before = data_->warning[mjWARN_BADQACC].number, full_before = ListsFull();
      for (int s = 0; s < steps; ++s) {
        for (int sub = 0; sub < substeps; ++sub) {
          Drive(state);
          mj_step(mj_, data_);
          RecordDrives(state);
          if (data_->warning[mjWARN_BADQACC].number != bad_before) {
            Diverged(state->step + 1, "MuJoCo found a bad acceleration (qacc) at time " + FormatNumber(data_->time));
          }
          if (ListsFull() != full_before) ThrowListsFull(state->step + 1);
          CheckSpeeds(state->step + 1);
        }
        ++state->step;
        state->time += model_->simulation.time_step;
      }
      CopyOut(state);
      ReadContacts(state);
      if (pads_) pads_->Record(pad_loads_, state);
      CheckFinite(*state);
    } catch (...) {
      *state = backup;
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
  void Compile();
  void WriteGeometries(std::ostringstream& out, size_t body, const Vec3& shift);
  void WriteLink(std::ostringstream& out, size_t body, const std::map<size_t, std::vector<size_t>>& children);
  void CopyIn(const SceneState& state);
  void CopyOut(SceneState* state);
  void Drive(SceneState* state);
  void RecordDrives(SceneState* state) const;
  void ReadContacts(SceneState* state);
  void CheckSpeeds(uint64_t step) const;
  // How often the contact or constraint list overflowed (MuJoCo counts its warnings).
  int ListsFull() const { return data_->warning[mjWARN_CONTACTFULL].number + data_->warning[mjWARN_CNSTRFULL].number; }
  [[noreturn]] void ThrowListsFull(uint64_t step) const {
    throw Error(ErrorCode::kFailedPrecondition,
                "simulation (engine mujoco) at step " + std::to_string(step) + ": more contacts than the backend's " +
                    std::to_string(mj_->nconmax) + " (or constraint rows than its " + std::to_string(mj_->njmax) +
                    "), sized from the scene's geometries; contacts would be dropped. Use the graspsim engine");
  }
  void CheckFinite(const SceneState& state) const;
  [[noreturn]] void Diverged(uint64_t step, const std::string& what) const {
    throw Error(ErrorCode::kFailedPrecondition, "simulation (engine mujoco) diverged at step " + std::to_string(step) +
                                                    ": " + what + "; reduce time_step or raise substeps");
  }

  // The sub-step's drives: the joint, its velocity before the step and the motor's output (Drive).
  struct DriveStep {
    size_t joint = 0;
    int dof = 0;
    double velocity_before = 0;
    ActuatorOutput output;
  };
  std::vector<DriveStep> drives_;

  std::shared_ptr<const SceneModel> model_;
  mjModel* mj_ = nullptr;
  mjData* data_ = nullptr;
  std::vector<int> body_of_;   // per MuJoCo body: our body index, or -1 (the world)
  std::vector<int> mj_body_;   // per body: its MuJoCo body
  std::vector<int> joint_of_;  // per joint: its MuJoCo joint, or -1 (fixed)
  std::vector<ContactPoint> contacts_;
  std::vector<Vec3> forces_;
  std::vector<std::string> meshes_;  // MJCF <mesh> assets, by geometry in the order written
  std::unique_ptr<PadReadout> pads_;  // when the scene has tactile pads
  std::vector<int> pad_of_geom_;      // per MuJoCo geom: the pad whose foam it is, or -1
  std::vector<PadLoad> pad_loads_;    // ReadContacts: the contact forces on each pad's foam
};

void MujocoEngine::WriteGeometries(std::ostringstream& out, size_t body_index, const Vec3& shift) {
  const BodySpec& body = model_->bodies[body_index];
  const double mu = body.material.dynamic_friction;
  for (const Geometry& g : body.collision) {
    Pose origin = g.origin;
    origin.position -= shift;
    out << "<geom " << PosQuat(origin) << " friction=\"" << Numbers({mu, 0, 0}) << "\" ";
    switch (g.kind) {
      case Geometry::Kind::kBox:
        out << "type=\"box\" size=\"" << Numbers({g.box_size.x() / 2, g.box_size.y() / 2, g.box_size.z() / 2}) << "\"";
        break;
      case Geometry::Kind::kSphere:
        out << "type=\"sphere\" size=\"" << Numbers({g.radius}) << "\"";
        break;
      case Geometry::Kind::kCylinder:
        out << "type=\"cylinder\" size=\"" << Numbers({g.radius, g.length / 2}) << "\"";
        break;
      case Geometry::Kind::kMesh: {
        const std::string name = "mesh" + std::to_string(meshes_.size());
        std::ostringstream asset;
        asset << std::setprecision(17) << "<mesh name=\"" << name << "\" vertex=\"";
        for (const Eigen::Vector3f& v : g.mesh->vertices) asset << v.x() << ' ' << v.y() << ' ' << v.z() << ' ';
        asset << "\" face=\"";
        for (const auto& t : g.mesh->triangles) asset << t[0] << ' ' << t[1] << ' ' << t[2] << ' ';
        asset << "\"/>";
        meshes_.push_back(asset.str());
        out << "type=\"mesh\" mesh=\"" << name << "\"";
        break;
      }
    }
    out << "/>";
  }
  for (uint32_t p : PadsOn(*model_, body_index)) {
    const TactileArraySpec& pad = model_->tactile_arrays[p];
    const Geometry foam = FoamBox(pad);
    Pose origin = foam.origin;
    origin.position -= shift;
    out << "<geom name=\"pad" << p << "\" " << PosQuat(origin) << " type=\"box\" size=\""
        << Numbers({foam.box_size.x() / 2, foam.box_size.y() / 2, foam.box_size.z() / 2}) << "\" priority=\"1\" friction=\""
        << Numbers({pad.contact.dynamic_friction, 0, 0}) << "\"/>";
  }
}

void MujocoEngine::WriteLink(std::ostringstream& out, size_t body, const std::map<size_t, std::vector<size_t>>& children) {
  auto it = children.find(body);
  if (it == children.end()) return;
  for (size_t j : it->second) {
    const JointSpec& joint = model_->joints[j];
    const size_t child = model_->joint_bodies[j][1];
    const BodySpec& link = model_->bodies[child];
    out << "<body name=\"b" << child << "\" " << PosQuat(joint.origin) << ">";
    out << Inertia(link.inertial, link.inertial.center_of_mass);
    if (joint.type != JointType::kFixed) {
      const bool limited = joint.type == JointType::kRevolute || joint.type == JointType::kPrismatic;
      out << "<joint name=\"j" << j << "\" type=\"" << (joint.type == JointType::kPrismatic ? "slide" : "hinge")
          << "\" axis=\"" << Numbers({joint.axis.x(), joint.axis.y(), joint.axis.z()}) << "\" limited=\""
          << (limited ? "true" : "false") << "\"";
      if (limited) out << " range=\"" << Numbers({joint.lower, joint.upper}) << "\"";
      out << "/>";
    }
    WriteGeometries(out, child, Vec3::Zero());
    WriteLink(out, child, children);
    out << "</body>";
  }
}

void MujocoEngine::Compile() {
  const SceneModel& m = *model_;
  const SimulationParams& p = m.simulation;
  std::ostringstream world;
  world << std::setprecision(17);
  // Free and mocap bodies are written at the origin, links at their joints' zero: CopyIn places them all.
  std::map<size_t, std::vector<size_t>> children;  // robot links: parent body → joints to children
  for (size_t j = 0; j < m.joints.size(); ++j) children[m.joint_bodies[j][0]].push_back(j);
  std::ostringstream excludes;
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    const BodySpec& body = m.bodies[i];
    if (body.motion == BodyMotion::kFree) {
      const Vec3& com = body.inertial.center_of_mass;
      world << "<body name=\"b" << i << "\"><freejoint/>" << Inertia(body.inertial, Vec3::Zero());
      WriteGeometries(world, i, com);
      world << "</body>";
    } else if (body.motion == BodyMotion::kStatic ||
               (!body.robot_id.empty() && m.robots[m.robot_index.at(body.robot_id)].base_body == body.id)) {
      world << "<body name=\"b" << i << "\" mocap=\"true\">";
      WriteGeometries(world, i, Vec3::Zero());
      WriteLink(world, i, children);
      world << "</body>";
    }
  }
  for (const RobotSpec& robot : m.robots) {
    for (size_t a = 0; a < robot.body_ids.size(); ++a) {
      for (size_t b = a + 1; b < robot.body_ids.size(); ++b) {
        excludes << "<exclude body1=\"b" << m.body_index.at(robot.body_ids[a]) << "\" body2=\"b"
                 << m.body_index.at(robot.body_ids[b]) << "\"/>";
      }
    }
  }
  std::ostringstream equality;
  for (size_t j = 0; j < m.joints.size(); ++j) {
    const JointSpec& joint = m.joints[j];
    if (!joint.mimic || joint.type == JointType::kFixed) continue;
    equality << "<joint joint1=\"j" << j << "\" joint2=\"j" << m.joint_index.at(joint.mimic->joint_id)
             << "\" polycoef=\"" << Numbers({joint.mimic->offset, joint.mimic->multiplier, 0, 0, 0}) << "\"/>";
  }
  // MuJoCo 2.2's lists have fixed sizes, and its automatic stack grows with njmax² (5 njmax² numbers: a fixed
  // njmax of 5000 made every compile allocate and clear 1 GB, more than the whole work cycle's stepping). Sized
  // from the scene: up to 8 contacts per geometry (a box on a box makes 4-8), 3 rows each (elliptic cones), a
  // row per limit and equality; a step that fills them stops (ThrowListsFull) rather than drop contacts.
  size_t geometries = m.tactile_arrays.size();
  for (const BodySpec& body : m.bodies) geometries += body.collision.size();
  const size_t max_contacts = 100 + 8 * geometries, max_rows = 3 * max_contacts + 2 * m.joints.size() + 10;
  const bool smooth = p.integrator == Integrator::kVelocityVerlet || p.integrator == Integrator::kRungeKutta4;
  const char* integrator = p.integrator == Integrator::kSemiImplicitEuler ? "Euler" : smooth ? "RK4" : "implicit";
  std::ostringstream xml;
  xml << std::setprecision(17) << "<mujoco model=\"graspsim\"><compiler angle=\"radian\" inertiafromgeom=\"false\"/>"
      << "<option timestep=\"" << p.time_step / p.substeps << "\" gravity=\""
      << Numbers({p.gravity.x(), p.gravity.y(), p.gravity.z()}) << "\" integrator=\"" << integrator
      << "\" cone=\"elliptic\"/><size njmax=\"" << max_rows << "\" nconmax=\"" << max_contacts << "\"/><asset>";
  for (const std::string& mesh : meshes_) xml << mesh;
  xml << "</asset><worldbody>" << world.str() << "</worldbody><contact>" << excludes.str() << "</contact><equality>"
      << equality.str() << "</equality></mujoco>";

  // MuJoCo 2.2 loads from files only: the text goes through its in-memory file system.
  const std::string text = xml.str();
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), "scene.xml", static_cast<int>(text.size())) != 0) {
    throw Error(ErrorCode::kInternal, "engine mujoco: could not hold the model in memory");
  }
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), "scene.xml")], text.data(), text.size());
  char error[1000] = "";
  mj_ = mj_loadXML("scene.xml", vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (!mj_) throw Error(ErrorCode::kFailedPrecondition, std::string("engine mujoco: the scene does not compile: ") + error);
  data_ = mj_makeData(mj_);

  body_of_.assign(mj_->nbody, -1);
  mj_body_.assign(m.bodies.size(), -1);
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    const int id = mj_name2id(mj_, mjOBJ_BODY, ("b" + std::to_string(i)).c_str());
    mj_body_[i] = id;
    if (id >= 0) body_of_[id] = static_cast<int>(i);
  }
  joint_of_.assign(m.joints.size(), -1);
  for (size_t j = 0; j < m.joints.size(); ++j) joint_of_[j] = mj_name2id(mj_, mjOBJ_JOINT, ("j" + std::to_string(j)).c_str());
  pad_of_geom_.assign(mj_->ngeom, -1);
  for (size_t p = 0; p < m.tactile_arrays.size(); ++p) {
    const int geom = mj_name2id(mj_, mjOBJ_GEOM, ("pad" + std::to_string(p)).c_str());
    if (geom >= 0) pad_of_geom_[geom] = static_cast<int>(p);  // a pad on a body MuJoCo does not have reads nothing
  }
  if (!m.tactile_arrays.empty()) pads_ = std::make_unique<PadReadout>(m);
}

void MujocoEngine::CopyIn(const SceneState& state) {
  const SceneModel& m = *model_;
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    const int id = mj_body_[i];
    if (id < 0) continue;
    const Pose& pose = state.body_poses[i];
    const Quat& q = pose.orientation;
    if (mj_->body_mocapid[id] >= 0) {
      const int k = mj_->body_mocapid[id];
      for (int a = 0; a < 3; ++a) data_->mocap_pos[3 * k + a] = pose.position[a];
      data_->mocap_quat[4 * k] = q.w(), data_->mocap_quat[4 * k + 1] = q.x();
      data_->mocap_quat[4 * k + 2] = q.y(), data_->mocap_quat[4 * k + 3] = q.z();
    } else if (m.bodies[i].motion == BodyMotion::kFree) {
      const int joint = mj_->body_jntadr[id];
      mjtNum* qpos = data_->qpos + mj_->jnt_qposadr[joint];
      mjtNum* qvel = data_->qvel + mj_->jnt_dofadr[joint];
      const Vec3 com = pose * m.bodies[i].inertial.center_of_mass;
      const Vec3 angular_local = q.conjugate() * state.body_velocities[i].angular;
      for (int a = 0; a < 3; ++a) {
        qpos[a] = com[a];
        qvel[a] = state.body_velocities[i].linear[a];
        qvel[3 + a] = angular_local[a];
      }
      qpos[3] = q.w(), qpos[4] = q.x(), qpos[5] = q.y(), qpos[6] = q.z();
    }
  }
  for (size_t j = 0; j < m.joints.size(); ++j) {
    if (joint_of_[j] < 0) continue;
    data_->qpos[mj_->jnt_qposadr[joint_of_[j]]] = state.joint_positions[j];
    data_->qvel[mj_->jnt_dofadr[joint_of_[j]]] = state.joint_velocities[j];
  }
}

void MujocoEngine::Drive(SceneState* state) {
  // force(q̇⁺) = f + D (q̇⁺ − q̇), D = ∂force/∂q̇ ≤ 0: M a = f + D h a, i.e. (M − h D) a = f. So f is applied and
  // −h D is the joint's armature: part of the mass matrix under every integrator and in the constraint solver
  // (as a joint damping, RK4 and the constraint solver would see it explicitly: a stiff drive diverged under
  // RK4, and a mimic follower of a stiffly driven light leader drifted by radians). Every joint is reset first:
  // a drive switched off leaves the scene's actuators and must leave no force behind.
  const double h = mj_->opt.timestep;
  mju_zero(data_->qfrc_applied, mj_->nv);
  mju_zero(mj_->dof_armature, mj_->nv);
  drives_.clear();
  for (auto& [j, actuator] : state->actuators) {
    if (joint_of_[j] < 0) continue;
    const int dof = mj_->jnt_dofadr[joint_of_[j]];
    const double q = data_->qpos[mj_->jnt_qposadr[joint_of_[j]]], q_dot = data_->qvel[dof];
    const ActuatorOutput out = StepDcMotor(actuator.motor, actuator.command, q, q_dot, h, &actuator.state);
    actuator.voltage = out.voltage;
    mj_->dof_armature[dof] = -h * out.damping;
    data_->qfrc_applied[dof] = out.joint_force;
    drives_.push_back({j, dof, q_dot, out});
  }
}

void MujocoEngine::RecordDrives(SceneState* state) const {
  // What a drive reports is the force the step applied, f + D (q̇⁺ − q̇), as graspsim's engine reports it.
  for (const DriveStep& drive : drives_) {
    state->actuators.at(drive.joint).joint_force =
        drive.output.joint_force + drive.output.damping * (data_->qvel[drive.dof] - drive.velocity_before);
  }
}

void MujocoEngine::CheckSpeeds(uint64_t step) const {
  const double limit = model_->simulation.divergence_speed;
  for (int dof = 0; dof < mj_->nv; ++dof) {
    if (std::abs(data_->qvel[dof]) < limit) continue;
    const int body = body_of_[mj_->jnt_bodyid[mj_->dof_jntid[dof]]];
    Diverged(step, "body '" + (body >= 0 ? model_->bodies[body].id : std::string("?")) + "' moves at " +
                       FormatNumber(data_->qvel[dof]) + " (m/s or rad/s), faster than " + FormatNumber(limit));
  }
}

void MujocoEngine::CopyOut(SceneState* state) {
  const SceneModel& m = *model_;
  mj_kinematics(mj_, data_);  // mj_step leaves the positions of the step's start in xpos
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    const int id = mj_body_[i];
    if (id < 0 || mj_->body_mocapid[id] >= 0) continue;
    const mjtNum* x = data_->xpos + 3 * id;
    const mjtNum* xq = data_->xquat + 4 * id;
    Pose& pose = state->body_poses[i];
    pose.orientation = Quat(xq[0], xq[1], xq[2], xq[3]).normalized();
    if (m.bodies[i].motion == BodyMotion::kFree) {
      pose.position = Vec3(x[0], x[1], x[2]) - pose.orientation * m.bodies[i].inertial.center_of_mass;
      const mjtNum* qvel = data_->qvel + mj_->jnt_dofadr[mj_->body_jntadr[id]];
      state->body_velocities[i].linear = Vec3(qvel[0], qvel[1], qvel[2]);
      state->body_velocities[i].angular = pose.orientation * Vec3(qvel[3], qvel[4], qvel[5]);
    } else {
      pose.position = Vec3(x[0], x[1], x[2]);
    }
  }
  for (size_t j = 0; j < m.joints.size(); ++j) {
    if (joint_of_[j] < 0) continue;
    state->joint_positions[j] = data_->qpos[mj_->jnt_qposadr[joint_of_[j]]];
    state->joint_velocities[j] = data_->qvel[mj_->jnt_dofadr[joint_of_[j]]];
  }
}

void MujocoEngine::ReadContacts(SceneState* state) {
  // MuJoCo's frame: normal from geom1 to geom2, so geom2's body is body_a (the normal points out of b into a)
  // and the contact force on it is along the frame.
  contacts_.clear();
  forces_.clear();
  pad_loads_.clear();
  for (int i = 0; i < data_->ncon; ++i) {
    const mjContact& c = data_->contact[i];
    const int a = body_of_[mj_->geom_bodyid[c.geom2]], b = body_of_[mj_->geom_bodyid[c.geom1]];
    if (a < 0 || b < 0) continue;
    mjtNum local[6];
    mj_contactForce(mj_, data_, i, local);
    ContactPoint& point = contacts_.emplace_back();
    point.body_a = static_cast<uint32_t>(a);
    point.body_b = static_cast<uint32_t>(b);
    point.feature = static_cast<uint64_t>(i);
    point.point = Vec3(c.pos[0], c.pos[1], c.pos[2]);
    point.normal = Vec3(c.frame[0], c.frame[1], c.frame[2]);
    point.depth = -c.dist;
    Vec3 force = Vec3::Zero();
    for (int r = 0; r < 3; ++r) force += local[r] * Vec3(c.frame[3 * r], c.frame[3 * r + 1], c.frame[3 * r + 2]);
    forces_.push_back(force);
    // On a pad's foam: the force on the pad (geom2's body is body_a, the force is on it).
    if (const int pad = pad_of_geom_[c.geom2]; pad >= 0) AddPadLoad(&pad_loads_, pad, point.body_b, force);
    if (const int pad = pad_of_geom_[c.geom1]; pad >= 0) AddPadLoad(&pad_loads_, pad, point.body_a, -force);
  }
  state->contacts.resize(contacts_.size());
  for (size_t i = 0; i < contacts_.size(); ++i) {
    state->contacts[i] = {contacts_[i].body_a, contacts_[i].body_b, contacts_[i].point, forces_[i]};
  }
}

void MujocoEngine::CheckFinite(const SceneState& state) const {
  const double limit = model_->simulation.divergence_speed;
  for (size_t i = 0; i < model_->bodies.size(); ++i) {
    const BodyVelocity& v = state.body_velocities[i];
    if (!state.body_poses[i].position.allFinite() || !(v.linear.norm() < limit) || !(v.angular.norm() < limit)) {
      Diverged(state.step, "body '" + model_->bodies[i].id + "' moves faster than " + FormatNumber(limit));
    }
  }
  for (size_t j = 0; j < model_->joints.size(); ++j) {
    if (!std::isfinite(state.joint_positions[j]) || !(std::abs(state.joint_velocities[j]) < limit)) {
      Diverged(state.step,
               "joint '" + model_->joints[j].id + "' velocity " + FormatNumber(state.joint_velocities[j]));
    }
  }
}

}  // namespace

std::shared_ptr<PhysicsEngine> MakeMujocoEngine(std::shared_ptr<const SceneModel> model) {
  return std::make_shared<MujocoEngine>(std::move(model));
}

}  // namespace graspsim
