// Boundary checks shared by every loader and service. Each throws Error(kInvalidArgument) with a message
// naming the field and the bad value, e.g. "pose.orientation: norm 0.5 is not 1 (|q| - 1 = -0.5)".
#pragma once

#include <string>

#include "core/math.h"

namespace graspsim {

void CheckFinite(const std::string& field, double value);
void CheckFinite(const std::string& field, const Vec3& value);
void CheckPositive(const std::string& field, double value);
void CheckNonNegative(const std::string& field, double value);
// Returns the normalised quaternion; rejects a norm farther than 1e-3 from 1 (and NaN/Inf).
Quat CheckQuaternion(const std::string& field, const Quat& q);
void CheckPose(const std::string& field, Pose* pose);
// A symmetric positive-definite inertia tensor (kg m^2) that satisfies the triangle inequality of a real body.
void CheckInertia(const std::string& field, const Mat3& inertia);
// Names of scenes' bodies, robots, joints: 1..64 characters of [A-Za-z0-9_.-].
void CheckName(const std::string& field, const std::string& name);
// Relative file paths of uploads: 1..256 characters, no "..", no leading '/', no backslash or NUL.
void CheckRelativePath(const std::string& field, const std::string& path);

}  // namespace graspsim
