#include "rpc/perception_decode.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/format.h"
#include "rpc/convert.h"
#include "rpc/packed_arrays.h"

namespace graspsim::rpc {
namespace {

// The table: given by table_pose (its z axis and the plane through its origin), else the world's up and unknown
// height (no cap under the object).
void TableFromProto(const v1::CompleteShapeRequest& request, CompletionOptions* options) {
  if (!request.has_table_pose()) return;
  const Pose table = PoseFromProto("table_pose", request.table_pose());
  options->symmetry.table_normal = table.orientation * Vec3::UnitZ();
  options->table_offset = options->symmetry.table_normal.dot(table.position);
}

}  // namespace

// Packed float32 x y z triplets → points.
std::vector<Vec3> PointsFromBytes(const std::string& field, const std::string& bytes, size_t max_points) {
  const size_t n = PackedCount(field, bytes.size(), 12, "float32 x y z per point");
  if (n > max_points) {  // checked before allocating
    ThrowResourceExhausted(field + ": " + std::to_string(n) + " points exceed the limit of " +
                           std::to_string(max_points) + " (--max-cloud-points)");
  }
  return UnpackFloat32Xyz<Vec3>(field, bytes);
}

DepthImage ImageFromProto(const v1::DepthImage& in, size_t max_points) {
  DepthImage image;
  const auto& k = in.intrinsics();
  image.intrinsics = {int(std::min<uint32_t>(k.width(), 1u << 30)), int(std::min<uint32_t>(k.height(), 1u << 30)),
                      k.fx(), k.fy(), k.cx(), k.cy()};
  const uint64_t pixels = uint64_t(k.width()) * k.height();
  if (pixels > max_points) {
    ThrowResourceExhausted("depth_image: " + std::to_string(k.width()) + " x " + std::to_string(k.height()) + " = " +
                           std::to_string(pixels) + " pixels exceed the limit of " + std::to_string(max_points) +
                           " (--max-cloud-points)");
  }
  image.depth = Unpack<float>("depth_image.depth", in.depth());
  image.mask.assign(in.mask().begin(), in.mask().end());
  return image;
}

CompletionOptions OptionsFromProto(const v1::CompleteShapeRequest& request, const Limits& limits) {
  CompletionOptions options;
  options.max_points = limits.max_cloud_points;
  const auto count = [](const char* field, uint32_t value, int lo, int hi, int fallback) {
    if (value == 0) return fallback;
    if (value < uint32_t(lo) || value > uint32_t(hi)) {
      ThrowInvalidArgument(std::string(field) + ": " + std::to_string(value) + " is outside " + std::to_string(lo) +
                           ".." + std::to_string(hi) + " (0 = " + std::to_string(fallback) + ")");
    }
    return int(value);
  };
  options.symmetry.orientations = count("orientations", request.orientations(), 1, 50, 7);
  options.symmetry.shifts = count("shifts", request.shifts(), 1, 50, 5);
  options.poisson.depth = count("octree_depth", request.octree_depth(), 5, 8, 6);
  if (request.refinements() > 5) {
    ThrowInvalidArgument("refinements: " + std::to_string(request.refinements()) + " is outside 0..5");
  }
  options.symmetry.refinements = int(request.refinements());
  if (request.has_fine_shifts()) {
    const uint32_t fine = request.fine_shifts();
    if (fine == 1 || fine > 100) {
      ThrowInvalidArgument("fine_shifts: " + std::to_string(fine) + " is outside 2..100 (0 = none, absent = " +
                           std::to_string(options.symmetry.fine_shifts) + ")");
    }
    options.symmetry.fine_shifts = int(fine);
  }
  if (!std::isfinite(request.voxel_size()) || request.voxel_size() < 0) {
    ThrowInvalidArgument("voxel_size: " + FormatNumber(request.voxel_size()) +
                         " m must be ≥ 0 (0 = automatic: above 1,500 points, a voxel for ~1,500)");
  }
  options.voxel_size = request.voxel_size();
  switch (request.method()) {
    case v1::COMPLETION_METHOD_MIRROR: options.method = CompletionMethod::kMirror; break;
    case v1::COMPLETION_METHOD_DELAUNAY: options.method = CompletionMethod::kDelaunay; break;
    default: ThrowInvalidArgument("method: " + std::to_string(int(request.method())) + " is not a CompletionMethod");
  }
  TableFromProto(request, &options);
  return options;
}

PartialView ViewFromProto(const v1::CompleteShapeRequest& request, const Limits& limits) {
  PartialView view;
  if (!request.has_camera_pose()) ThrowInvalidArgument("camera_pose: required (the pose the view was taken from)");
  view.camera_pose = PoseFromProto("camera_pose", request.camera_pose());
  switch (request.input_case()) {
    case v1::CompleteShapeRequest::kDepthImage:
      view.image = ImageFromProto(request.depth_image(), limits.max_cloud_points);
      break;
    case v1::CompleteShapeRequest::kCloud:
      view.points = PointsFromBytes("cloud.points", request.cloud().points(), limits.max_cloud_points);
      break;
    case v1::CompleteShapeRequest::INPUT_NOT_SET:
      ThrowInvalidArgument("input: give depth_image or cloud");
  }
  return view;
}

}  // namespace graspsim::rpc
