// PerceptionService: requests become the perception library's inputs here (validated: field and value in every
// error), results become messages. CompleteShape is one pool job per call that streams a message per stage.
#include "rpc/perception_service.h"

#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "edits/scene_edits.h"
#include "perception/mesh_metrics.h"
#include "perception/observation.h"
#include "perception/segmentation.h"
#include "perception/shape_completion.h"
#include "rpc/call.h"
#include "rpc/failed_call.h"
#include "rpc/perception_decode.h"
#include "rpc/convert.h"
#include "rpc/packed_arrays.h"
#include "rpc/progress_run.h"
#include "rpc/run_reactor.h"

namespace graspsim::rpc {
namespace {

constexpr char kCompleteShape[] = "PerceptionService/CompleteShape";
constexpr double kDefaultMass = 0.1;  // kg

v1::CompleteShapeProgress Stage(const std::string& stage, double fraction) {
  v1::CompleteShapeProgress message;
  message.set_stage(stage);
  message.set_fraction(fraction);
  return message;
}

void ResultToProto(const CompletionResult& result, v1::CompleteShapeProgress* out) {
  if (result.plane) {
    ToProto(result.plane->point, out->mutable_plane()->mutable_point());
    ToProto(result.plane->normal, out->mutable_plane()->mutable_normal());
    out->mutable_plane()->set_score(result.plane->score);
    out->mutable_plane()->set_angle_deg(result.plane->angle_deg);
    out->mutable_plane()->set_hypotheses(uint32_t(result.plane->hypotheses));
  }
  ToProto(result.mesh, out->mutable_mesh());
  auto* t = out->mutable_timings();
  t->set_observe_ms(result.ms.observe_ms);
  t->set_filter_ms(result.ms.filter_ms);
  t->set_symmetry_ms(result.ms.symmetry_ms);
  t->set_normals_ms(result.ms.normals_ms);
  t->set_surface_ms(result.ms.surface_ms);
  t->set_total_ms(result.ms.total_ms);
  out->set_input_points(uint32_t(result.input_points));
  out->set_filtered_points(uint32_t(result.filtered_points));
  out->set_surface_points(uint32_t(result.surface_points));
}

using CompletionRun = ProgressRun<v1::CompleteShapeProgress>;

// The plane and the added body, for the viewer; the plane is drawn as large as the completed mesh.
SceneOverlays::Completion CompletionOverlay(const CompletionResult& result, const std::string& body_id) {
  SceneOverlays::Completion overlay;
  overlay.body_id = body_id;
  const Vec3& point = result.plane->point;
  const Vec3& normal = result.plane->normal;
  overlay.point = {point.x(), point.y(), point.z()};
  overlay.normal = {normal.x(), normal.y(), normal.z()};
  overlay.score = result.plane->score;
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& v : result.mesh.vertices) box.extend(v);
  overlay.size = box.isEmpty() ? 0.0 : double(box.diagonal().norm());
  return overlay;
}

void RunCompletion(const v1::CompleteShapeRequest& request, SceneRegistry* registry, SceneOverlays* overlays,
                   RecordingLog* recordings, const std::shared_ptr<CompletionRun>& run) {
  try {
    const Limits& limits = registry->limits();
    const CompletionOptions options = OptionsFromProto(request, limits);
    std::shared_ptr<Scene> scene;
    if (!request.add_to_scene_id().empty()) {
      scene = registry->Get(request.add_to_scene_id());  // NOT_FOUND before the work, not after
      if (!request.object_name().empty()) CheckName("object_name", request.object_name());
    }
    if (!std::isfinite(request.object_mass()) || request.object_mass() < 0) {
      ThrowInvalidArgument("object_mass: " + FormatNumber(request.object_mass()) + " kg must be ≥ 0 (0 = 0.1)");
    }
    const PartialView view = ViewFromProto(request, limits);
    const auto result = CompleteShape(view, options, [&](const std::string& stage, double fraction) {
      return run->Progress(Stage(stage, fraction));
    });
    if (!result) return;  // cancelled: the reactor already ends the call
    ValidateMesh(result->mesh, "mesh", limits.max_triangles_per_mesh);
    v1::CompleteShapeProgress last = Stage("done", 1);
    ResultToProto(*result, &last);
    if (scene) {
      const double mass = request.object_mass() > 0 ? request.object_mass() : kDefaultMass;
      if (recordings) {  // what the camera saw, in the scene's recording (if any) beside the object it became
        recordings->AppendPointCloud(scene->id(), "/completion/points", Observe(view, options.max_points).points);
      }
      static std::atomic<uint64_t> completed{0};
      const std::string name =
          request.object_name().empty() ? "completed_" + std::to_string(++completed) : request.object_name();
      edits::AddObject(scene.get(), edits::UniformSolidObject("add_to_scene_id", name, result->mesh, mass), limits);
      last.set_body_id(name);
      if (overlays && result->plane) {
        overlays->SetCompletion(request.add_to_scene_id(), CompletionOverlay(*result, last.body_id()));
      }
    }
    run->Finish(std::move(last), grpc::Status::OK);
  } catch (...) {
    run->Finish(std::nullopt, StatusOfException(kCompleteShape, std::current_exception()));
  }
}

}  // namespace

grpc::ServerWriteReactor<v1::CompleteShapeProgress>* PerceptionServiceImpl::CompleteShape(
    Context* context, const v1::CompleteShapeRequest* request) {
  return StartStream<v1::CompleteShapeProgress>(context, [&] {
    auto* reactor = new RunReactor<v1::CompleteShapeProgress, CompletionRun>(context, kCompleteShape);
    pool_->Post([request, registry = registry_, overlays = overlays_, recordings = recordings_, run = reactor->run()] {
      RunCompletion(*request, registry, overlays, recordings, run);
    });
    return reactor;
  });
}

grpc::ServerUnaryReactor* PerceptionServiceImpl::SegmentScene(Context* context, const v1::SegmentSceneRequest* request,
                                                              v1::SegmentSceneResponse* response) {
  return RunUnary(context, "PerceptionService/SegmentScene", pool_, [=, this] {
    SegmentationParams params;
    if (request->cluster_tolerance() != 0) params.cluster_tolerance = request->cluster_tolerance();
    if (request->plane_threshold() != 0) params.plane_threshold = request->plane_threshold();
    if (request->min_cluster_points() != 0) params.min_cluster_points = int(std::min(request->min_cluster_points(), 1u << 30));
    const std::vector<Vec3> points =
        PointsFromBytes("cloud.points", request->cloud().points(), registry_->limits().max_cloud_points);
    const SceneSegmentation segmentation = graspsim::SegmentScene(points, params);
    ToProto(segmentation.table_normal, response->mutable_table_normal());
    response->set_table_offset(segmentation.table_offset);
    for (const auto& object : segmentation.objects) response->add_objects()->set_points(PackFloat32Xyz(object));
  });
}

}  // namespace graspsim::rpc
