// PerceptionService's requests → the perception library's inputs: packed float32 clouds, depth images, completion
// options. Validated at the boundary (field and value in every error); perception/observation.h's Observe checks
// the rest (sizes against the intrinsics, finiteness). Moved out of perception_service.cpp unchanged so the
// decoders can be fuzzed without a network (tests/fuzz/perception_fuzz.cpp).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/limits.h"
#include "core/math.h"
#include "graspsim/v1/perception.pb.h"
#include "perception/observation.h"
#include "perception/shape_completion.h"

namespace graspsim::rpc {

// Packed float32 x y z triplets → points; kResourceExhausted beyond `max_points`.
std::vector<Vec3> PointsFromBytes(const std::string& field, const std::string& bytes, size_t max_points);
DepthImage ImageFromProto(const v1::DepthImage& in, size_t max_points);
CompletionOptions OptionsFromProto(const v1::CompleteShapeRequest& request, const Limits& limits);
// camera_pose and the input (depth_image or cloud) of a CompleteShape request.
PartialView ViewFromProto(const v1::CompleteShapeRequest& request, const Limits& limits);

}  // namespace graspsim::rpc
