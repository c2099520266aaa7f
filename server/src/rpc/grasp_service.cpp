#include "rpc/grasp_service.h"

#include <algorithm>

#include "core/error.h"
#include "grasp/hand.h"
#include "grasp/plan_request.h"
#include "grasp/scene_object.h"
#include "rpc/call.h"
#include "rpc/failed_call.h"
#include "rpc/convert.h"
#include "rpc/plan_arm_path.h"

namespace graspsim::rpc {
namespace {

struct ResolvedObject {
  std::shared_ptr<const TriangleMesh> mesh;
  std::vector<grasp::ObstacleBox> obstacles;
};

ResolvedObject ObjectFromProto(const v1::GraspTarget& target, const SceneRegistry& registry) {
  ResolvedObject out;
  if (!target.scene_id().empty()) {
    if (target.body_id().empty()) ThrowInvalidArgument("object.body_id: empty; name the body to grasp");
    const SceneView view = registry.Get(target.scene_id())->View();
    grasp::SceneObject object = grasp::ObjectFromScene(*view.model, view.state, "object.body_id", target.body_id());
    out.mesh = std::move(object.mesh);
    out.obstacles = std::move(object.obstacles);
    return out;
  }
  if (!target.body_id().empty()) ThrowInvalidArgument("object.scene_id: empty; a body needs its scene");
  if (target.mesh().vertices().empty() && target.mesh().triangles().empty()) {
    ThrowInvalidArgument("object: empty; give scene_id and body_id, or a mesh");
  }
  out.mesh = std::make_shared<TriangleMesh>(MeshFromProto("object.mesh", target.mesh(), registry.limits()));
  return out;
}

// PlanGraspsRequest and EvaluateGraspRequest share these fields (checked by grasp::ValidateClosingParams).
template <class Request>
grasp::ClosingParams SimulationFromProto(const Request& r) {
  grasp::ClosingParams params;
  if (r.has_friction()) params.friction = r.friction();
  params.object_material = r.object_material();
  for (const auto& [link, material] : r.link_materials()) params.link_materials[link] = material;
  for (const v1::FrictionPair& pair : r.friction_pairs()) {
    params.friction_pairs.push_back({pair.material_a(), pair.material_b(), pair.friction()});
  }
  grasp::ValidateClosingParams(params);
  return params;
}

grasp::Candidate CandidateFromProto(const v1::GraspCandidate& c, const grasp::HandSpec& hand) {
  return grasp::CandidateFrom(hand, {FromProto(c.approach()), FromProto(c.reference()), FromProto(c.target()), c.roll(),
                                     c.standoff(), c.preshape()});
}

void CandidateToProto(const grasp::Candidate& c, const std::vector<std::string>& preshapes, v1::GraspCandidate* out) {
  ToProto(c.approach, out->mutable_approach());
  ToProto(c.target, out->mutable_target());
  ToProto(c.reference, out->mutable_reference());
  out->set_roll(c.roll);
  out->set_standoff(c.standoff);
  out->set_preshape(preshapes.at(c.preshape));
}

void GraspToProto(const grasp::PlannedGrasp& g, const std::vector<std::string>& preshapes,
             const std::vector<std::string>& links, const char* outcome, v1::Grasp* out) {
  CandidateToProto(g.candidate, preshapes, out->mutable_candidate());
  out->set_candidate_index(g.candidate_index);
  out->set_outcome(outcome);
  ToProto(g.hand_pose, out->mutable_hand_pose());
  for (double q : g.joints) out->add_joint_positions(q);
  for (const grasp::GraspContact& c : g.contacts) {
    v1::Contact* contact = out->add_contacts();
    ToProto(c.point, contact->mutable_point());
    ToProto(c.normal, contact->mutable_normal());
    contact->set_link(links.at(c.link));
  }
  out->set_epsilon(g.quality.epsilon);
  out->set_volume(g.quality.volume);
  out->set_force_closure(g.quality.force_closure);
}

const char* OutcomeName(grasp::Outcome outcome) {
  switch (outcome) {
    case grasp::Outcome::kGrasp: return "grasp";
    case grasp::Outcome::kMissed: return "missed";
    case grasp::Outcome::kCollision: return "collision";
  }
  return "";
}

}  // namespace

GraspPlanJob PlanJobFromProto(const v1::PlanGraspsRequest& r, const SceneRegistry& registry) {
  GraspPlanJob job;
  const grasp::HandSpec hand = grasp::LoadHand("hand", r.hand());
  job.hand = r.hand();
  job.simulation = SimulationFromProto(r);
  grasp::CandidateParams& c = job.candidates;
  c.method = grasp::CandidateMethodNamed("method", r.method());
  c.preshapes = grasp::PreshapeIndices(hand, {r.preshapes().begin(), r.preshapes().end()});
  if (r.standoffs_size() > 0) c.standoffs.assign(r.standoffs().begin(), r.standoffs().end());
  if (r.has_rolls()) c.rolls = static_cast<int>(std::min<uint32_t>(r.rolls(), 1u << 20));
  if (r.has_spacing()) c.spacing = r.spacing();
  if (r.has_circle_samples()) c.circle_samples = static_cast<int>(std::min<uint32_t>(r.circle_samples(), 1u << 20));
  if (r.has_grasp_point_a() != r.has_grasp_point_b()) {
    ThrowInvalidArgument(std::string(r.has_grasp_point_a() ? "grasp_point_b" : "grasp_point_a") +
                         ": absent; give both grasp points or neither");
  }
  if (r.has_grasp_point_a()) c.grasp_points = std::make_pair(FromProto(r.grasp_point_a()), FromProto(r.grasp_point_b()));
  if (r.has_seed()) c.seed = r.seed();
  c.max_candidates = r.max_candidates();
  job.max_grasps = grasp::MaxGrasps("max_grasps", r.max_grasps());
  job.recompute = r.recompute();
  grasp::ValidateCandidateParams(c);
  ResolvedObject object = ObjectFromProto(r.object(), registry);
  job.mesh = std::move(object.mesh);
  job.obstacles = std::move(object.obstacles);
  return job;
}

void ToProto(const grasp::GraspSet& set, const grasp::StoredGraspSet& meta, bool from_store, v1::GraspSet* out) {
  out->set_set_id(meta.key);
  out->set_hand(set.hand);
  out->set_mesh_sha256(meta.mesh_hash);
  out->set_from_store(from_store);
  out->set_candidates(set.candidates);
  out->set_missed(set.missed);
  out->set_collisions(set.collisions);
  out->set_simulated(set.simulated);
  out->set_force_closure(set.force_closure);
  out->set_seconds(set.seconds);
  out->set_cpu_seconds(from_store ? 0.0 : set.cpu_seconds);
  for (const std::string& id : set.joint_names) out->add_joint_ids(id);
  for (const std::string& name : set.preshape_names) out->add_preshapes(name);
  for (const grasp::PlannedGrasp& g : set.grasps) GraspToProto(g, set.preshape_names, set.link_names, "grasp", out->add_grasps());
  out->set_params(meta.params_text);
}

grpc::ServerWriteReactor<v1::PlanGraspsProgress>* GraspServiceImpl::PlanGrasps(Context* context,
                                                                               const v1::PlanGraspsRequest* request) {
  return StartStream<v1::PlanGraspsProgress>(
      context, [&] { return StartPlanGraspsStream(*request, registry_, store_, pool_, context); });
}

grpc::ServerUnaryReactor* GraspServiceImpl::GetGraspSet(Context* context, const v1::GetGraspSetRequest* request,
                                                        v1::GraspSet* response) {
  return RunUnary(context, "GraspService/GetGraspSet", pool_, [=, this] {
    const grasp::StoredGraspSet stored = grasp::FindStoredSet(store_.get(), "set_id", request->set_id());
    ToProto(stored.set, stored, true, response);
  });
}

grpc::ServerUnaryReactor* GraspServiceImpl::EvaluateGrasp(Context* context, const v1::EvaluateGraspRequest* request,
                                                          v1::Grasp* response) {
  return RunUnary(context, "GraspService/EvaluateGrasp", pool_, [=, this] {
    const grasp::HandSpec hand = grasp::LoadHand("hand", request->hand());
    const grasp::ClosingParams params = SimulationFromProto(*request);
    if (!request->has_candidate()) ThrowInvalidArgument("candidate: absent; give the candidate to simulate");
    const grasp::Candidate candidate = CandidateFromProto(request->candidate(), hand);
    ResolvedObject object = ObjectFromProto(request->object(), *registry_);
    const grasp::GraspPlanner planner(request->hand(), object.mesh, std::move(object.obstacles), params);
    grasp::PlannedGrasp grasp;
    const grasp::Outcome outcome = planner.Evaluate(candidate, &grasp);
    std::vector<std::string> links;
    for (const grasp::HandLink& link : planner.hand().links()) links.push_back(link.name);
    GraspToProto(grasp, planner.hand().preshape_names(), links, OutcomeName(outcome), response);
  });
}

grpc::ServerUnaryReactor* GraspServiceImpl::PlanArmPath(Context* context, const v1::PlanArmPathRequest* request,
                                                        v1::PlanArmPathResponse* response) {
  return RunUnary(context, "GraspService/PlanArmPath", pool_, [=, this] {
    rpc::PlanArmPath(*request, *registry_, [context] { return context->IsCancelled(); }, response, overlays_);
  });
}

grpc::ServerUnaryReactor* GraspServiceImpl::PlanArmPaths(Context* context, const v1::PlanArmPathsRequest* request,
                                                         v1::PlanArmPathsResponse* response) {
  return RunUnary(context, "GraspService/PlanArmPaths", pool_, [=, this] {
    rpc::PlanArmPaths(*request, *registry_, [context] { return context->IsCancelled(); }, response);
  });
}

grpc::ServerWriteReactor<v1::PickAndPlaceProgress>* GraspServiceImpl::PickAndPlace(Context* context,
                                                                                   const v1::PickAndPlaceRequest* request) {
  return StartStream<v1::PickAndPlaceProgress>(
      context, [&] { return StartPickAndPlaceStream(*request, registry_, store_, pool_, context); });
}

}  // namespace graspsim::rpc
