// PerceptionService's decoding of packed point clouds and depth images, without a network: the input's first
// byte picks the request type, the rest is parsed with ParseFromArray as that message, then the same steps run as
// in perception_service.cpp up to the expensive part:
//   CompleteShape: OptionsFromProto, ViewFromProto (rpc/perception_decode.h), Observe (perception/observation.h,
//                  the first stage of CompleteShape: sizes against the intrinsics, finiteness, the derived camera);
//   SegmentScene:  the service's parameter mapping, PointsFromBytes, and SegmentScene itself (PCL RANSAC and
//                  clustering) for clouds of at most 256 points, so the fuzzer keeps its pace.
// The cloud limit is lowered from 2,000,000 to 65,536 points/pixels: the checks are the same, the fuzzer's
// allocations stay small.
#include <algorithm>

#include "fuzz_common.h"
#include "graspsim/v1/perception.pb.h"
#include "perception/observation.h"
#include "perception/segmentation.h"
#include "rpc/perception_decode.h"

namespace {

void CompleteShape(const uint8_t* data, size_t size, const graspsim::Limits& limits) {
  graspsim::v1::CompleteShapeRequest request;
  if (!request.ParseFromArray(data, int(size))) return;
  graspsim::fuzz::Rejects([&] {
    graspsim::rpc::OptionsFromProto(request, limits);
    const graspsim::PartialView view = graspsim::rpc::ViewFromProto(request, limits);
    const graspsim::Observation obs = graspsim::Observe(view, limits.max_cloud_points);
    if (obs.depth.size() != size_t(obs.intrinsics.width) * size_t(obs.intrinsics.height) ||
        obs.mask.size() != obs.depth.size()) {
      graspsim::fuzz::Broken("Observe: depth or mask size differs from width x height");
    }
  });
}

void SegmentScene(const uint8_t* data, size_t size, const graspsim::Limits& limits) {
  graspsim::v1::SegmentSceneRequest request;
  if (!request.ParseFromArray(data, int(size))) return;
  graspsim::fuzz::Rejects([&] {
    // As PerceptionServiceImpl::SegmentScene maps them.
    graspsim::SegmentationParams params;
    if (request.cluster_tolerance() != 0) params.cluster_tolerance = request.cluster_tolerance();
    if (request.plane_threshold() != 0) params.plane_threshold = request.plane_threshold();
    if (request.min_cluster_points() != 0) params.min_cluster_points = int(std::min(request.min_cluster_points(), 1u << 30));
    const std::vector<graspsim::Vec3> points =
        graspsim::rpc::PointsFromBytes("cloud.points", request.cloud().points(), limits.max_cloud_points);
    if (points.size() <= 256) graspsim::SegmentScene(points, params);
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  graspsim::Limits limits;
  limits.max_cloud_points = 65'536;
  if (data[0] & 1) {
    SegmentScene(data + 1, size - 1, limits);
  } else {
    CompleteShape(data + 1, size - 1, limits);
  }
  return 0;
}
