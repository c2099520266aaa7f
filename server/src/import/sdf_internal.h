// What the SDF loader's files share (sdf_loader.cpp: parsing; sdf_model.cpp: the model as a tree; sdf_links.cpp:
// links, collisions, inertials). Internal to import/sdf_*.cpp: the only header outside libsdformat that includes it.
#pragma once

#include <string>
#include <vector>

#include <sdf/sdf.hh>

#include "core/validate.h"
#include "import/loader_common.h"
#include "import/robot_import.h"

namespace graspsim::import {

inline Pose ToPose(const ignition::math::Pose3d& p, const std::string& field) {
  Pose pose{Vec3(p.Pos().X(), p.Pos().Y(), p.Pos().Z()), Quat(p.Rot().W(), p.Rot().X(), p.Rot().Y(), p.Rot().Z())};
  CheckPose(field, &pose);
  return pose;
}

inline Vec3 ToVec3(const ignition::math::Vector3d& v) { return Vec3(v.X(), v.Y(), v.Z()); }

// A libsdformat error with where it was found, when libsdformat knows.
inline std::string Describe(const sdf::Error& error) {
  std::string text = error.Message();
  if (text.size() > 300) text = text.substr(0, 300) + "...";  // some quote the whole input
  if (error.XmlPath()) text += " (at " + *error.XmlPath() + ")";
  if (error.LineNumber()) text += " (line " + std::to_string(*error.LineNumber()) + ")";
  return text;
}

// Repairs are warnings, or errors under options.strict.
class SdfRepairs {
 public:
  SdfRepairs(bool strict, std::vector<ImportWarning>* warnings) : strict_(strict), warnings_(warnings) {}
  void Warn(const std::string& element, const std::string& value, const std::string& action);

 private:
  bool strict_;
  std::vector<ImportWarning>* warnings_;
};

// One link's body (id = `name`, its collision geometry in the link frame). `field`: "sdf: model 'm' link 'l'".
// Mesh files not uploaded are recorded in *meshes, not thrown.
BodySpec ConvertSdfLink(const sdf::Link& link, const std::string& name, const std::string& field,
                        MeshFiles* meshes, SdfRepairs* repairs);

// The link's <inertial> as the file states it, entered as (*inertials)[name]; nothing for a link without one.
void ReadSdfInertial(const sdf::Link& link, const std::string& name, const std::string& field,
                     FileInertials* inertials);

// One model (nested models flattened) as a robot: `model_in_world` is the model frame in the world frame.
ImportedRobot ConvertSdfModel(const sdf::Model& model, const Pose& model_in_world, const FileLookup& files,
                              const ImportOptions& options, const Limits& limits);

}  // namespace graspsim::import
