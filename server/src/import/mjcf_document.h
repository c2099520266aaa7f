// MJCF (MuJoCo's XML) as the loader reads it: the document with <include>s expanded, the <compiler> settings,
// the <default> classes flattened, and attribute access that falls back on an element's class the way MuJoCo's
// compiler does. Internal to import/ (mjcf_document.cpp, mjcf_geometry.cpp, mjcf_loader.cpp).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <tinyxml2.h>

#include "core/math.h"
#include "import/robot_import.h"

namespace graspsim::import::mjcf {

enum class InertiaFromGeom { kFalse, kTrue, kAuto };

// <compiler>, with MuJoCo's defaults.
struct Compiler {
  bool degrees = true;            // angle="degree" (MuJoCo's default!) or "radian"
  std::string eulerseq = "xyz";   // lower case: axes that move with the frame; upper case: fixed axes
  std::string meshdir;            // meshdir, else assetdir
  InertiaFromGeom inertia_from_geom = InertiaFromGeom::kAuto;
  bool autolimits = true;         // limited="auto": limited when a range is given
  double boundmass = 0;           // every body's mass at least this (0: no bound)
  double boundinertia = 0;        // every body's principal moments at least this
  double settotalmass = -1;       // > 0: the masses and inertias scaled so that the bodies weigh this
  bool global = false;            // coordinate="global" (MuJoCo 2.3.2 and older): poses in the world frame
  double AngleScale() const { return degrees ? M_PI / 180.0 : 1.0; }
};

using Attributes = std::map<std::string, std::string>;

// One element as MuJoCo's compiler sees it: its own attributes, then those its default class gives its tag.
// Every accessor names `field` and the attribute in its errors ("mjcf: body 'a' geom 2 size: 'x' is not a number").
class Element {
 public:
  Element(const tinyxml2::XMLElement& xml, const Attributes* defaults, std::string field)
      : xml_(&xml), defaults_(defaults), field_(std::move(field)) {}

  const tinyxml2::XMLElement& xml() const { return *xml_; }
  const std::string& field() const { return field_; }
  const char* Raw(const char* name) const;  // nullptr when neither the element nor its class sets it
  bool Has(const char* name) const { return Raw(name) != nullptr; }
  std::string String(const char* name, const std::string& fallback = "") const;
  // Between min_count and max_count finite numbers; empty when the attribute is absent.
  std::vector<double> Numbers(const char* name, size_t min_count, size_t max_count) const;
  double Number(const char* name, double fallback) const;
  Vec3 Vector(const char* name, const Vec3& fallback) const;
  // "true"/"false" (MuJoCo also reads "auto" for some attributes: returns `auto_value` then).
  bool Bool(const char* name, bool fallback, bool auto_value = false) const;

 private:
  const tinyxml2::XMLElement* xml_;
  const Attributes* defaults_;
  std::string field_;
};

// The orientation an element states (quat, axisangle, euler, xyaxes or zaxis; at most one), identity if none.
Quat Orientation(const Element& element, const Compiler& compiler);
// pos (default 0) and Orientation.
Pose FramePose(const Element& element, const Compiler& compiler);
// The rotation taking +z onto `direction` by the shortest arc (MuJoCo's mju_quatZ2Vec).
Quat QuatZToVector(const Vec3& direction);

class Document {
 public:
  // Parses `text` (Error naming the line for XML that is not well formed), expands <include file=...> from
  // `files`, reads <compiler> and <default>.
  Document(const std::string& text, const FileLookup& files);

  const tinyxml2::XMLElement& root() const { return *root_; }
  const Compiler& compiler() const { return compiler_; }
  // The element under its class: its class attribute, else `child_class` (a body's childclass), else "main".
  Element Read(const tinyxml2::XMLElement& xml, const std::string& child_class, const std::string& field) const;

 private:
  void ExpandIncludes(const FileLookup& files);
  void ReadCompiler(const tinyxml2::XMLElement& compiler);
  void ReadDefaults(const tinyxml2::XMLElement& element, const std::string& parent, int depth);

  tinyxml2::XMLDocument xml_;
  const tinyxml2::XMLElement* root_ = nullptr;
  Compiler compiler_;
  std::map<std::string, std::map<std::string, Attributes>> classes_;  // class → tag → attributes, inherited ones too
};

}  // namespace graspsim::import::mjcf
