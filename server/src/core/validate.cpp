#include "core/validate.h"

#include <cmath>

#include <Eigen/Eigenvalues>

#include "core/error.h"
#include "core/format.h"

namespace graspsim {
namespace {

std::string Format(double value) { return FormatNumber(value); }

std::string Format(const Vec3& v) { return "(" + Format(v.x()) + ", " + Format(v.y()) + ", " + Format(v.z()) + ")"; }

}  // namespace

void CheckFinite(const std::string& field, double value) {
  if (!std::isfinite(value)) ThrowInvalidArgument(field + ": " + Format(value) + " is not a finite number");
}

void CheckFinite(const std::string& field, const Vec3& value) {
  if (!value.allFinite()) ThrowInvalidArgument(field + ": " + Format(value) + " is not finite");
}

void CheckPositive(const std::string& field, double value) {
  CheckFinite(field, value);
  if (!(value > 0)) ThrowInvalidArgument(field + ": " + Format(value) + " must be > 0");
}

void CheckNonNegative(const std::string& field, double value) {
  CheckFinite(field, value);
  if (value < 0) ThrowInvalidArgument(field + ": " + Format(value) + " must be >= 0");
}

Quat CheckQuaternion(const std::string& field, const Quat& q) {
  const Eigen::Vector4d c = q.coeffs();
  if (!c.allFinite()) {
    ThrowInvalidArgument(field + ": quaternion (w=" + Format(q.w()) + ", x=" + Format(q.x()) + ", y=" +
                         Format(q.y()) + ", z=" + Format(q.z()) + ") is not finite");
  }
  const double norm = c.norm();
  // A larger error means the client sent something other than a rotation; silently normalising would hide it.
  if (std::abs(norm - 1.0) > 1e-3) {
    ThrowInvalidArgument(field + ": quaternion (w=" + Format(q.w()) + ", x=" + Format(q.x()) + ", y=" +
                         Format(q.y()) + ", z=" + Format(q.z()) + ") has norm " + Format(norm) +
                         ", not 1 (tolerance 1e-3)");
  }
  return q.normalized();
}

void CheckPose(const std::string& field, Pose* pose) {
  CheckFinite(field + ".position", pose->position);
  pose->orientation = CheckQuaternion(field + ".orientation", pose->orientation);
}

void CheckInertia(const std::string& field, const Mat3& inertia) {
  if (!inertia.allFinite()) ThrowInvalidArgument(field + ": inertia tensor is not finite");
  if ((inertia - inertia.transpose()).cwiseAbs().maxCoeff() > 1e-12 * (1 + inertia.cwiseAbs().maxCoeff())) {
    ThrowInvalidArgument(field + ": inertia tensor is not symmetric");
  }
  const Vec3 principal = Eigen::SelfAdjointEigenSolver<Mat3>(inertia).eigenvalues();
  if (!(principal.minCoeff() > 0)) {
    ThrowInvalidArgument(field + ": inertia tensor is not positive definite (principal moments " +
                         Format(principal) + " kg m^2)");
  }
  // Principal moments of a real body satisfy I_a <= I_b + I_c; allow rounding of thin shapes.
  const double tolerance = 1e-9 * principal.sum();
  for (int a = 0; a < 3; ++a) {
    if (principal[a] > principal[(a + 1) % 3] + principal[(a + 2) % 3] + tolerance) {
      ThrowInvalidArgument(field + ": principal moments " + Format(principal) +
                           " kg m^2 violate the triangle inequality I_a <= I_b + I_c of a physical body");
    }
  }
}

void CheckName(const std::string& field, const std::string& name) {
  const bool length_ok = !name.empty() && name.size() <= 64;
  bool chars_ok = true;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    chars_ok = chars_ok && ok;
  }
  if (!length_ok || !chars_ok) {
    ThrowInvalidArgument(field + ": '" + name.substr(0, 80) +
                         "' is not a valid name (1..64 characters of letters, digits, '_', '-', '.')");
  }
}

void CheckRelativePath(const std::string& field, const std::string& path) {
  const bool bad = path.empty() || path.size() > 256 || path.front() == '/' ||
                   path.find('\\') != std::string::npos || path.find('\0') != std::string::npos ||
                   path == ".." || path.starts_with("../") || path.find("/../") != std::string::npos ||
                   path.ends_with("/..");
  if (bad) {
    ThrowInvalidArgument(field + ": '" + path.substr(0, 80) +
                         "' is not a relative path (1..256 characters, no leading '/', no '..', no '\\')");
  }
}

}  // namespace graspsim
