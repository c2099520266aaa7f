// What the format loaders (urdf_loader, mjcf_loader, sdf_loader) share: mesh files looked up once and reported
// missing all at once, the file's inertials resolved into physical ones (or refused) per ImportOptions, and joints
// graspsim models as chains of its own (ball, free). Internal to import/.
#pragma once

#include <map>
#include <memory>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "import/robot_import.h"

namespace graspsim::import {

std::string Quoted(const std::string& name);

// A name graspsim accepts (core/validate.h CheckName): "::" (SDF scopes) → ".", any other character outside
// [A-Za-z0-9_.-] → '_', at most 64 characters; empty → "unnamed". *changed (if not null) is set when anything
// but the "::" replacement was needed.
std::string SanitiseName(const std::string& name, bool* changed);

// Only well-formed UTF-8 without NUL bytes reaches an XML parser: TinyXML 2.6 steps over a multi-byte sequence by
// its lead byte's length without looking, so a lead byte near the end of malformed text made it read past the
// terminating NUL (a heap overflow found by tests/fuzz/urdf_fuzz.cpp: tests/fuzz/regressions/
// urdf_tinyxml_read_past_end). Throws Error(kInvalidArgument) "<format>: ... at byte N".
void CheckXmlText(const std::string& format, const std::string& text);

// Loads each (file, scale) once per robot, however many links use it. A name that no candidate path finds is
// remembered, not thrown, so that ThrowIfMissing lists every missing file in one error.
class MeshFiles {
 public:
  MeshFiles(const FileLookup& files, const Limits& limits) : files_(files), limits_(limits) {}

  // `candidates`: the paths to try in order (e.g. the stripped "package://" path, then the basename).
  // Fills geometry->mesh and geometry->mesh_file and returns true, or records `as_written` as missing and
  // returns false (geometry->mesh stays null). Throws for a file that is there but does not parse.
  bool Load(const std::string& field, const std::string& as_written, const std::vector<std::string>& candidates,
            const Vec3& scale, Geometry* geometry);
  // Error(kInvalidArgument): "<format>: mesh files the model names were not uploaded: 'a.stl', 'b.obj'".
  void ThrowIfMissing(const std::string& format) const;

  // The meshes a model names, parsed ahead of Load as many at a time as the machine has cores (each parse is a
  // child process: the Panda's 10 meshes took 150 ms one after the other). Load then finds them parsed; what is
  // missing or does not parse is left for Load to report.
  struct Request {
    std::string field;
    std::vector<std::string> candidates;
    Vec3 scale = Vec3::Ones();
  };
  void Prefetch(const std::vector<Request>& requests);

 private:
  const FileLookup& files_;
  const Limits& limits_;
  std::map<std::tuple<std::string, double, double, double>, std::shared_ptr<const TriangleMesh>> cache_;
  std::vector<std::string> missing_;
  std::set<std::string> missing_set_;
};

// "package://pkg/meshes/a.stl" → "meshes/a.stl", "file:///x/a.stl" → "x/a.stl", "model://m/a.dae" → "m/a.dae";
// anything else as written; lexically normalised, leading "./" and "../" dropped.
std::string StripMeshUri(const std::string& filename);
// The upload paths a mesh reference is looked up under, in order: StripMeshUri's; for package:// also the path with
// the package directory ("pkg/meshes/a.stl", as PyBullet resolves it beside the file); then the basename.
std::vector<std::string> MeshPathCandidates(const std::string& filename);

// A link's inertial as the file states it, before any check. Loaders fill one per link that has one, keyed by
// link name (FileInertials); a link without an entry has no inertial in the file.
struct FileInertial {
  double mass = 0;            // kg as written (may be 0, negative, NaN: ResolveInertials judges)
  Pose origin;                // the inertial frame in the link frame
  Mat3 inertia = Mat3::Zero();  // kg m^2 about the centre of mass, in the inertial frame
  std::string field;          // how the file names it, for errors and warnings: "urdf: link 'a' inertial"
  // Massless by design, not a zero mass to repair: a link of a ball or free joint's chain (AppendBallJoint), a
  // joint-frame link, MJCF's world body.
  bool massless = false;
};
using FileInertials = std::map<std::string, FileInertial>;

// Sets every link's inertial (from file.at(link name), if any) per options.inertia, with the rules of
// docs/import.md:
// - a physical inertial (mass > 0, inertia positive definite and triangle inequality) is kept (kAuto, kFromFile);
// - zero mass on the root or on a link fixed to its parent: a massless frame (merged into its parent: it adds no
//   mass and keeps its frame for FK, tips and sensors);
// - zero mass behind a moving joint, a missing inertial on a link with geometry, or a tensor that is not physical:
//   from the collision geometry (kAuto; for a positive file mass, the geometry's inertia scaled to that mass), or
//   refused (kFromFile, strict);
// - kFromGeometry: every link with collision geometry takes the solid geometry's mass properties at the density.
// A link with neither inertial nor geometry is a 1 g frame (massless when fixed to its parent). Every repair
// appends a warning; options.strict refuses where a repair would be needed. Negative, NaN or Inf masses are always
// refused.
// `format` ("urdf", "mjcf", "sdf") prefixes the element names of warnings and errors.
void ResolveInertials(const std::string& format, const FileInertials& file, const ImportOptions& options,
                      RobotDescription* description, std::vector<ImportWarning>* warnings);

// Joints graspsim has no single joint type for, as chains of its own through massless links named
// "<child>__<suffix>" (docs/import.md): a ball joint as three revolute joints about x, y, z of the joint frame
// (continuous, or limited to ±limit when limit > 0); a free joint as prismatic x, y, z then a ball, so a floating
// base is the 6 joints of its chain. `joint` is the file's joint with parent_body, child_body, origin and id set;
// its type and axis are ignored. The chain's joints and links are appended in topological order (the child link
// must already be in description->links; the new links are inserted before it, and entered in *file as chain links).
void AppendBallJoint(const JointSpec& joint, double limit, RobotDescription* description, FileInertials* file);
void AppendFreeJoint(const JointSpec& joint, double translation_limit, RobotDescription* description,
                     FileInertials* file);

}  // namespace graspsim::import
