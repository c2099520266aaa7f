// The stress runs of sweep.h.
//
// Every run starts with the bodies at rest with their lowest samples on the surface (the slider moving), no
// spring compressed, no bristle deflected. Contacts are found at the start of a step in every integrator, so
// the first step falls g h² into the contact with no force yet: (h ω)² × the static depth, a one-step accuracy
// error of any penalty method that a stable integrator then damps out; impacts (a tumbling slider's edge) go
// deeper than any static answer too. Those are reported (onset_depth_ratio, onset_energy_gain), not judged.
// Judged is whether the integration settles instead of growing or chattering:
// - Energy, over the second half of the run: the total energy — kinetic + gravitational (Multibody::Energy) +
//   ½ k_pair d² per contact + ½ σ0 |z|² per bristle — can only fall (c, σ1, c_t ≥ 0 and the bristle cap
//   dissipate). It may not climb above the lowest value it reached before by more than Σ ½ W d_s (the energy of
//   the bodies' whole settling oscillation, the scale of a stable integrator's energy error at rest) plus 1 % of
//   the slider's launch energy ½ m v0² (the scale of its error on the slide and any tumbling). More means the
//   integrator pumps energy in (chatter, a launched body).
// - Depth, over the last tenth of the run: no contact deeper than kDepthFactor = 4 × its static answer d_s. At
//   rest a body's contacts sit at d_s; undamped oscillation reaches 2 d_s; friction's tipping moment on a sliding
//   5 cm cube (μ = 0.6, 6 × 6 samples) loads its leading row up to ~2× the mean. d_s is the depth at which the
//   body's own samples, on springs k/2 (two equal materials in series), carry its weight: an upper bound of the
//   engine's answer (the other body's samples can only add springs).
#include "stress/sweep.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <map>
#include <sstream>

#include "collision/contact_finder.h"
#include "core/error.h"
#include "physics/contact_law.h"
#include "physics/multibody.h"
#include "physics/simulation.h"

namespace graspsim::stress {
namespace {

constexpr double kG = 9.81;
constexpr double kDepthFactor = 4;
constexpr double kTipRadius = 0.01, kObjectEdge = 0.1, kObjectMass = 3.0, kSliderEdge = 0.05, kSlideSpeed = 0.2;
// 1 cm samples: the slider's bottom has 6 × 6 points, the object's 11 × 11 — enough for a spread load, cheap
// enough for ~2000 runs.
constexpr double kSampleSpacing = 0.01;

BodySpec Free(const std::string& id, double mass, const Mat3& inertia, Geometry geometry) {
  BodySpec body;
  body.id = id;
  body.motion = BodyMotion::kFree;
  body.collision.push_back(std::move(geometry));
  body.inertial.mass = mass;
  body.inertial.inertia = inertia;
  return body;
}

// Static depth: Σ k (d − h_i)⁺ = W over the sample heights h_i above the lowest sample.
double StaticDepth(std::vector<double> heights, double k, double weight) {
  std::sort(heights.begin(), heights.end());
  double sum = 0;
  for (size_t n = 1; n <= heights.size(); ++n) {
    sum += heights[n - 1];
    const double d = (weight / k + sum) / n;
    if (n == heights.size() || d <= heights[n]) return d;
  }
  return weight / k;
}

struct Scene {
  std::shared_ptr<SceneModel> model = std::make_shared<SceneModel>();
  SceneState state;
  std::map<std::pair<uint32_t, uint32_t>, double> depth_bound;  // per body pair (low index first): d_s
  double energy_allowance = 0;                                   // J: Σ ½ W d_s (+ 1 % of the launch energy)

  uint32_t Add(BodySpec body, const Vec3& position) {
    model->bodies.push_back(std::move(body));
    state.body_poses.push_back({position, Quat::Identity()});
    return static_cast<uint32_t>(model->bodies.size() - 1);
  }
};

// The static depth of `body` resting on `support` under `weight`; also the bound of its contacts with `other`
// (the tip falling off the object lands on the table).
void Bound(const ContactFinder& finder, double k_pair, uint32_t body, uint32_t support, uint32_t other, double weight,
           Scene* scene) {
  const std::vector<Vec3>& samples = finder.Samples(body);
  double lowest = 1e9;
  for (const Vec3& p : samples) lowest = std::min(lowest, p.z());
  std::vector<double> heights;
  for (const Vec3& p : samples) heights.push_back(p.z() - lowest);
  const double d = StaticDepth(heights, k_pair, weight);
  for (uint32_t b : {support, other}) scene->depth_bound[{std::min(body, b), std::max(body, b)}] = d;
  scene->energy_allowance += 0.5 * weight * d;
}

bool Finite(const SceneState& s) {
  for (const Pose& p : s.body_poses) {
    if (!p.position.allFinite() || !p.orientation.coeffs().allFinite()) return false;
  }
  for (const BodyVelocity& v : s.body_velocities) {
    if (!v.linear.allFinite() || !v.angular.allFinite()) return false;
  }
  for (double x : s.joint_positions) if (!std::isfinite(x)) return false;
  for (double x : s.joint_velocities) if (!std::isfinite(x)) return false;
  for (const auto& [key, z] : s.bristles) if (!z.allFinite()) return false;
  return true;
}

bool Same(const SceneState& a, const SceneState& b) {
  if (a.step != b.step || a.body_poses.size() != b.body_poses.size() || a.bristles != b.bristles) return false;
  for (size_t i = 0; i < a.body_poses.size(); ++i) {
    if (a.body_poses[i].position != b.body_poses[i].position) return false;
    if (a.body_poses[i].orientation.coeffs() != b.body_poses[i].orientation.coeffs()) return false;
    if (a.body_velocities[i].linear != b.body_velocities[i].linear) return false;
    if (a.body_velocities[i].angular != b.body_velocities[i].angular) return false;
  }
  return true;
}

// What is wrong with a divergence report, or "" if it is as Simulation::Step promises.
std::string CheckReport(const Error& error, const SceneModel& model, const SceneState& before, const SceneState& after) {
  const std::string message = error.what();
  if (error.code() != ErrorCode::kFailedPrecondition) return "divergence reported with another code: " + message;
  if (message.find("step " + std::to_string(before.step + 1)) == std::string::npos) return "no step: " + message;
  bool named = false;
  for (const BodySpec& body : model.bodies) named = named || message.find("'" + body.id + "'") != std::string::npos;
  if (!named) return "no body named: " + message;
  bool quantity = false;
  for (const char* word : {"velocity", "position", "bristle"}) quantity = quantity || message.find(word) != std::string::npos;
  if (!quantity) return "no quantity: " + message;
  if (!Finite(after)) return "state not finite after the report";
  if (!Same(before, after)) return "state changed by the failed step";
  return "";
}

}  // namespace

BodySpec SphereBody(const std::string& id, double radius, double mass) {
  Geometry sphere;
  sphere.kind = Geometry::Kind::kSphere;
  sphere.radius = radius;
  return Free(id, mass, Mat3::Identity() * (0.4 * mass * radius * radius), sphere);
}

BodySpec CubeBody(const std::string& id, double edge, double mass) {
  Geometry box;
  box.box_size = Vec3::Constant(edge);
  return Free(id, mass, Mat3::Identity() * (mass * edge * edge / 6), box);
}

BodySpec TableBody() {
  auto mesh = std::make_shared<TriangleMesh>();
  for (float z : {-1.0f, 0.0f}) {
    for (float y : {-5.0f, 5.0f}) {
      for (float x : {-5.0f, 5.0f}) mesh->vertices.emplace_back(x, y, z);
    }
  }
  mesh->triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                     {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  BodySpec table;
  table.id = "table";
  table.motion = BodyMotion::kStatic;
  Geometry geometry;
  geometry.kind = Geometry::Kind::kMesh;
  geometry.mesh = mesh;
  table.collision.push_back(geometry);
  table.inertial.mass = 1000;
  table.inertial.inertia = Mat3::Identity() * 1000;
  return table;
}

const char* Name(Scenario scenario) {
  switch (scenario) {
    case Scenario::kTipOnTable: return "tip_on_table";
    case Scenario::kTipOnObject: return "tip_on_object";
    case Scenario::kSlide: return "slide";
  }
  return "?";
}

const char* Name(Integrator integrator) {
  switch (integrator) {
    case Integrator::kSemiImplicitEuler: return "semi_implicit_euler";
    case Integrator::kLinearlyImplicitEuler: return "linearly_implicit_euler";
    case Integrator::kVelocityVerlet: return "velocity_verlet";
    case Integrator::kRungeKutta4: return "runge_kutta_4";
  }
  return "?";
}

RunResult RunOne(const RunSpec& spec) {
  const auto started = std::chrono::steady_clock::now();
  Scene scene;
  SimulationParams& params = scene.model->simulation;
  params.time_step = spec.time_step;
  params.integrator = spec.integrator;
  params.contact = spec.contact;
  params.sample_spacing = kSampleSpacing;
  params.sleep_time = 0;  // never skip a body: the integrator is what is under test
  const uint32_t table = scene.Add(TableBody(), Vec3::Zero());
  uint32_t body = 0, object = 0;
  switch (spec.scenario) {
    case Scenario::kTipOnTable:
      body = scene.Add(SphereBody("tip", kTipRadius, spec.mass), Vec3(0, 0, kTipRadius));
      break;
    case Scenario::kTipOnObject:
      object = scene.Add(CubeBody("object", kObjectEdge, kObjectMass), Vec3(0, 0, kObjectEdge / 2));
      body = scene.Add(SphereBody("tip", kTipRadius, spec.mass), Vec3(0, 0, kObjectEdge + kTipRadius));
      break;
    case Scenario::kSlide:
      body = scene.Add(CubeBody("slider", kSliderEdge, spec.mass), Vec3(0, 0, kSliderEdge / 2));
      break;
  }
  scene.model->Reindex();
  Simulation simulation(scene.model);
  simulation.PrepareState(&scene.state);
  if (spec.scenario == Scenario::kSlide) {
    scene.state.body_velocities[body].linear = Vec3(kSlideSpeed, 0, 0);
    scene.energy_allowance += 0.01 * 0.5 * spec.mass * kSlideSpeed * kSlideSpeed;
  }

  // The engine's own contact geometry, evaluated at the end of each step for depths and spring energies.
  const ContactFinder finder(*scene.model, ContactFinderOptions{kSampleSpacing, 0});
  const ContactParams pair = CombineContactParams(spec.contact, spec.contact);
  if (spec.scenario == Scenario::kTipOnObject) {
    Bound(finder, pair.stiffness, body, object, table, spec.mass * kG, &scene);
    Bound(finder, pair.stiffness, object, table, table, (spec.mass + kObjectMass) * kG, &scene);
  } else {
    Bound(finder, pair.stiffness, body, table, table, spec.mass * kG, &scene);
  }
  const Multibody multibody(*scene.model);
  std::vector<ContactPoint> contacts;
  double depth_ratio = 0;  // of the last state evaluated
  auto energy = [&](const SceneState& s) {
    contacts.clear();
    finder.Find(s.body_poses, &contacts);
    double e = multibody.Energy(s, params.gravity);
    depth_ratio = 0;
    for (const ContactPoint& c : contacts) {
      e += 0.5 * pair.stiffness * c.depth * c.depth;
      depth_ratio = std::max(depth_ratio, c.depth / scene.depth_bound.at({std::min(c.body_a, c.body_b),
                                                                          std::max(c.body_a, c.body_b)}));
    }
    for (const auto& [key, z] : s.bristles) e += 0.5 * pair.bristle_stiffness * z.squaredNorm();
    return e;
  };

  RunResult result;
  const double e0 = energy(scene.state);
  double lowest = e0;
  const double x0 = scene.state.body_poses[body].position.x();
  result.steps_planned = static_cast<int>(std::min(
      std::lround(spec.duration / spec.time_step),
      std::max<long>(spec.max_steps, std::lround(spec.min_duration / spec.time_step))));
  for (int i = 0; i < result.steps_planned; ++i) {
    const SceneState before = scene.state;
    try {
      simulation.Step(&scene.state, 1);
    } catch (const Error& error) {
      result.reason = "diverged";
      result.error = error.what();
      result.contract = CheckReport(error, *scene.model, before, scene.state);
      break;
    } catch (const std::exception& error) {
      result.reason = "diverged";
      result.contract = std::string("not a graspsim::Error: ") + error.what();
      break;
    }
    ++result.steps_run;
    if (!Finite(scene.state)) {
      result.reason = "diverged";
      result.contract = "non-finite state returned at step " + std::to_string(scene.state.step);
      break;
    }
    const double e = energy(scene.state);
    result.onset_energy_gain = std::max(result.onset_energy_gain, (e - e0) / scene.energy_allowance);
    result.onset_depth_ratio = std::max(result.onset_depth_ratio, depth_ratio);
    if (2 * (i + 1) > result.steps_planned) {  // the second half
      result.energy_growth = std::max(result.energy_growth, (e - lowest) / scene.energy_allowance);
    }
    if (10 * (i + 1) > 9 * result.steps_planned) {  // the last tenth
      result.end_depth_ratio = std::max(result.end_depth_ratio, depth_ratio);
    }
    lowest = std::min(lowest, e);
    for (size_t c = 0; c < simulation.contacts().size(); ++c) {
      const Vec3& f = simulation.contact_forces()[c];
      const Vec3& n = simulation.contacts()[c].normal;
      const double normal = f.dot(n);
      if (normal > 0) {
        result.friction_ratio = std::max(result.friction_ratio, (f - normal * n).norm() / (pair.static_friction * normal));
      }
    }
    if (spec.trace) {
      std::fprintf(stderr, "step %d E-E0 %.4g depth_ratio %.4g contacts %zu", i + 1, (e - e0) / scene.energy_allowance,
                   depth_ratio, simulation.contacts().size());
      for (size_t b = 1; b < scene.model->bodies.size(); ++b) {
        const Vec3& p = scene.state.body_poses[b].position;
        std::fprintf(stderr, " | %s z %.6g x %.4g v %.4g w %.4g", scene.model->bodies[b].id.c_str(), p.z(), p.x(),
                     scene.state.body_velocities[b].linear.norm(), scene.state.body_velocities[b].angular.norm());
      }
      std::fprintf(stderr, "\n");
    }
  }
  result.slide = scene.state.body_poses[body].position.x() - x0;
  result.slide_ratio = spec.scenario == Scenario::kSlide
                           ? result.slide / (kSlideSpeed * kSlideSpeed / (2 * pair.dynamic_friction * kG))
                           : 0;
  if (result.reason.empty() && result.end_depth_ratio > kDepthFactor) result.reason = "penetration";
  if (result.reason.empty() && result.energy_growth > 1) result.reason = "energy";
  result.stable = result.reason.empty();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

std::string ToJson(const RunSpec& spec, const RunResult& r) {
  auto quote = [](const std::string& s) {
    std::string out = "\"";
    for (char ch : s) {
      if (ch == '"' || ch == '\\') out += '\\';
      out += (ch == '\n' ? ' ' : ch);
    }
    return out + "\"";
  };
  std::ostringstream o;
  o.precision(6);
  o << "{\"grid\":" << quote(spec.grid) << ",\"scenario\":\"" << Name(spec.scenario) << "\",\"integrator\":\""
    << Name(spec.integrator) << "\",\"dt\":" << spec.time_step << ",\"mass\":" << spec.mass
    << ",\"k\":" << spec.contact.stiffness << ",\"c\":" << spec.contact.damping
    << ",\"sigma0\":" << spec.contact.bristle_stiffness << ",\"sigma1\":" << spec.contact.bristle_damping
    << ",\"steps_planned\":" << r.steps_planned << ",\"steps_run\":" << r.steps_run
    << ",\"stable\":" << (r.stable ? "true" : "false") << ",\"reason\":" << quote(r.reason)
    << ",\"contract\":" << quote(r.contract) << ",\"end_depth_ratio\":" << r.end_depth_ratio
    << ",\"energy_growth\":" << r.energy_growth << ",\"onset_depth_ratio\":" << r.onset_depth_ratio
    << ",\"onset_energy_gain\":" << r.onset_energy_gain << ",\"friction_ratio\":" << r.friction_ratio
    << ",\"slide_m\":" << r.slide << ",\"slide_ratio\":" << r.slide_ratio << ",\"seconds\":" << r.seconds
    << ",\"error\":" << quote(r.error) << "}";
  return o.str();
}

namespace {

// Log-spaced grids (half decades for dt, the quantity the tables resolve).
const std::vector<double> kTimeSteps = {1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2};
const std::vector<double> kStiffnesses = {1e2, 1e3, 1e4, 1e5, 1e6};
const std::vector<double> kMasses = {0.05, 0.3, 3.0};
const std::vector<Integrator> kIntegrators = {Integrator::kSemiImplicitEuler, Integrator::kLinearlyImplicitEuler,
                                              Integrator::kVelocityVerlet};

void Grid(const std::string& name, const std::vector<Scenario>& scenarios, const std::vector<double>& masses,
          const std::vector<double>& steps, const std::vector<double>& values, double ContactParams::*field,
          std::vector<RunSpec>* out) {
  for (Scenario scenario : scenarios) {
    for (Integrator integrator : kIntegrators) {
      for (double mass : masses) {
        for (double value : values) {
          for (double dt : steps) {
            RunSpec spec;
            spec.grid = name;
            spec.scenario = scenario;
            spec.integrator = integrator;
            spec.mass = mass;
            spec.time_step = dt;
            spec.contact.*field = value;
            if (scenario == Scenario::kSlide) spec.min_duration = kSlideMinDuration;
            out->push_back(spec);
          }
        }
      }
    }
  }
}

}  // namespace

std::vector<RunSpec> FullSweep() {
  // main: k × dt × integrator × mass on all three scenarios, the other contact parameters at their defaults;
  // then one parameter at a time around k = 1e4: normal damping c on the resting cases, σ0 and σ1 on the slide.
  const std::vector<Scenario> all = {Scenario::kTipOnTable, Scenario::kTipOnObject, Scenario::kSlide};
  std::vector<RunSpec> out;
  Grid("main", all, kMasses, kTimeSteps, kStiffnesses, &ContactParams::stiffness, &out);
  Grid("damping", {Scenario::kTipOnTable, Scenario::kTipOnObject}, {0.05, 3.0}, kTimeSteps, {0, 1, 10, 100, 1000},
       &ContactParams::damping, &out);
  Grid("sigma0", {Scenario::kSlide}, kMasses, kTimeSteps, {1e2, 1e3, 1e4, 1e5, 1e6},
       &ContactParams::bristle_stiffness, &out);
  Grid("sigma1", {Scenario::kSlide}, kMasses, kTimeSteps, {0, 1, 10, 100, 1000}, &ContactParams::bristle_damping,
       &out);
  return out;
}

std::vector<RunSpec> ReducedSweep() {
  std::vector<RunSpec> out;
  Grid("main", {Scenario::kTipOnTable, Scenario::kTipOnObject, Scenario::kSlide}, {0.05, 3.0},
       {1e-4, 1e-3, 3e-3, 1e-2}, kStiffnesses, &ContactParams::stiffness, &out);
  return out;
}

}  // namespace graspsim::stress
