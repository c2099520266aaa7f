// The MJCF document: XML parsing (tinyxml2), <include>, <compiler>, <default> classes, attribute access and the
// five ways MJCF states an orientation.
#include "import/mjcf_document.h"

#include <charconv>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "import/loader_common.h"

namespace graspsim::import::mjcf {
namespace {

// <include> may nest; MuJoCo refuses cycles, this refuses more than this many (a cycle too).
constexpr int kMaxIncludes = 256;
// Nested <default> classes (tinyxml2 itself stops at 100 nested elements).
constexpr int kMaxDefaultDepth = 100;

std::string Line(const tinyxml2::XMLElement& xml) { return " (line " + std::to_string(xml.GetLineNum()) + ")"; }

}  // namespace

// ---- Element ---------------------------------------------------------------------------------------------------

const char* Element::Raw(const char* name) const {
  if (const char* value = xml_->Attribute(name); value != nullptr) return value;
  if (defaults_ != nullptr) {
    if (const auto it = defaults_->find(name); it != defaults_->end()) return it->second.c_str();
  }
  return nullptr;
}

std::string Element::String(const char* name, const std::string& fallback) const {
  const char* value = Raw(name);
  return value == nullptr ? fallback : std::string(value);
}

std::vector<double> Element::Numbers(const char* name, size_t min_count, size_t max_count) const {
  const char* text = Raw(name);
  if (text == nullptr) return {};
  const std::string attribute = field_ + " " + name;
  std::vector<double> numbers;
  std::istringstream words(text);
  for (std::string word; words >> word;) {
    const char* begin = word.data();
    if (*begin == '+') ++begin;
    double value = 0;
    const auto [end, error] = std::from_chars(begin, word.data() + word.size(), value);
    if (error != std::errc() || end != word.data() + word.size()) {
      ThrowInvalidArgument(attribute + ": " + Quoted(word) + " is not a number");
    }
    CheckFinite(attribute, value);
    if (numbers.size() == max_count) {
      ThrowInvalidArgument(attribute + ": " + Quoted(text) + " has more than " + std::to_string(max_count) +
                           " number(s)");
    }
    numbers.push_back(value);
  }
  if (numbers.size() < min_count) {
    ThrowInvalidArgument(attribute + ": " + Quoted(text) + " has fewer than " + std::to_string(min_count) +
                         " number(s)");
  }
  return numbers;
}

double Element::Number(const char* name, double fallback) const {
  const std::vector<double> numbers = Numbers(name, 1, 1);
  return numbers.empty() ? fallback : numbers[0];
}

Vec3 Element::Vector(const char* name, const Vec3& fallback) const {
  const std::vector<double> numbers = Numbers(name, 3, 3);
  return numbers.empty() ? fallback : Vec3(numbers[0], numbers[1], numbers[2]);
}

bool Element::Bool(const char* name, bool fallback, bool auto_value) const {
  const char* text = Raw(name);
  if (text == nullptr) return fallback;
  const std::string value = text;
  if (value == "true") return true;
  if (value == "false") return false;
  if (value == "auto") return auto_value;
  ThrowInvalidArgument(field_ + " " + name + ": " + Quoted(value) + " is not \"true\", \"false\" or \"auto\"");
}

// ---- Orientation -------------------------------------------------------------------------------------------------

Quat QuatZToVector(const Vec3& direction) {
  const Vec3 z = direction.normalized();
  const Vec3 axis = Vec3::UnitZ().cross(z);
  const double s = axis.norm();
  if (s < 1e-10) {  // parallel: identity, or half a turn about x when opposite (as MuJoCo)
    return z.z() > 0 ? Quat::Identity() : Quat(0, 1, 0, 0);
  }
  return Quat(Eigen::AngleAxisd(std::atan2(s, z.z()), axis / s));
}

Quat Orientation(const Element& element, const Compiler& compiler) {
  const char* kinds[] = {"quat", "axisangle", "euler", "xyaxes", "zaxis"};
  const char* given = nullptr;
  for (const char* kind : kinds) {
    if (element.xml().Attribute(kind) == nullptr) continue;
    if (given != nullptr) {
      ThrowInvalidArgument(element.field() + ": both " + given + " and " + kind +
                           " given; MJCF allows one orientation");
    }
    given = kind;
  }
  if (given == nullptr) {  // an orientation from the class
    for (const char* kind : kinds) {
      if (element.Has(kind)) {
        given = kind;
        break;
      }
    }
  }
  if (given == nullptr) return Quat::Identity();
  const std::string kind = given;
  const std::string field = element.field() + " " + kind;
  if (kind == "quat") {
    const std::vector<double> q = element.Numbers(given, 4, 4);
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(norm > 1e-10)) ThrowInvalidArgument(field + ": " + Quoted(element.String(given)) + " has zero length");
    return Quat(q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm);
  }
  if (kind == "axisangle") {
    const std::vector<double> a = element.Numbers(given, 4, 4);
    const Vec3 axis(a[0], a[1], a[2]);
    if (!(axis.norm() > 1e-10)) ThrowInvalidArgument(field + ": " + Quoted(element.String(given)) + " has a zero axis");
    return Quat(Eigen::AngleAxisd(a[3] * compiler.AngleScale(), axis.normalized()));
  }
  if (kind == "euler") {
    const std::vector<double> e = element.Numbers(given, 3, 3);
    Quat q = Quat::Identity();
    for (int i = 0; i < 3; ++i) {
      const char axis_name = compiler.eulerseq[i];
      const int axis = (axis_name | 0x20) - 'x';
      const Quat step(Eigen::AngleAxisd(e[i] * compiler.AngleScale(), Vec3::Unit(axis)));
      q = (axis_name >= 'a') ? q * step : step * q;  // moving axes compose on the right, fixed ones on the left
    }
    return q.normalized();
  }
  if (kind == "xyaxes") {
    const std::vector<double> a = element.Numbers(given, 6, 6);
    Vec3 x(a[0], a[1], a[2]);
    Vec3 y(a[3], a[4], a[5]);
    if (!(x.norm() > 1e-10)) ThrowInvalidArgument(field + ": " + Quoted(element.String(given)) + " has a zero x axis");
    x.normalize();
    y -= x * x.dot(y);
    if (!(y.norm() > 1e-10)) {
      ThrowInvalidArgument(field + ": " + Quoted(element.String(given)) + " has a y axis parallel to x or zero");
    }
    y.normalize();
    Mat3 rotation;
    rotation.col(0) = x;
    rotation.col(1) = y;
    rotation.col(2) = x.cross(y);
    return Quat(rotation).normalized();
  }
  const Vec3 z = element.Vector(given, Vec3::UnitZ());  // zaxis
  if (!(z.norm() > 1e-10)) ThrowInvalidArgument(field + ": " + Quoted(element.String(given)) + " has zero length");
  return QuatZToVector(z);
}

Pose FramePose(const Element& element, const Compiler& compiler) {
  return {element.Vector("pos", Vec3::Zero()), Orientation(element, compiler)};
}

// ---- Document ----------------------------------------------------------------------------------------------------

Document::Document(const std::string& text, const FileLookup& files) {
  CheckXmlText("mjcf", text);
  if (xml_.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
    const int line = xml_.ErrorLineNum();
    ThrowInvalidArgument("mjcf: XML error" + (line > 0 ? " at line " + std::to_string(line) : std::string()) + ": " +
                         (xml_.ErrorStr() != nullptr ? xml_.ErrorStr() : "not well-formed"));
  }
  root_ = xml_.RootElement();
  if (root_ == nullptr || std::string(root_->Name()) != "mujoco") {
    ThrowInvalidArgument("mjcf: the root element is " +
                         (root_ == nullptr ? std::string("missing") : "<" + std::string(root_->Name()) + ">") +
                         ", not <mujoco>");
  }
  ExpandIncludes(files);
  for (const tinyxml2::XMLElement* e = root_->FirstChildElement("compiler"); e != nullptr;
       e = e->NextSiblingElement("compiler")) {
    ReadCompiler(*e);
  }
  classes_["main"];
  for (const tinyxml2::XMLElement* e = root_->FirstChildElement("default"); e != nullptr;
       e = e->NextSiblingElement("default")) {
    ReadDefaults(*e, "", 0);
  }
}

void Document::ExpandIncludes(const FileLookup& files) {
  int included = 0;
  // Depth first over the whole tree; an <include> is replaced by the children of its file's <mujoco>, which are
  // then visited in turn (nested includes).
  std::vector<tinyxml2::XMLElement*> pending{const_cast<tinyxml2::XMLElement*>(root_)};
  while (!pending.empty()) {
    tinyxml2::XMLElement* parent = pending.back();
    pending.pop_back();
    for (tinyxml2::XMLElement* e = parent->FirstChildElement(); e != nullptr;) {
      if (std::string(e->Name()) != "include") {
        pending.push_back(e);
        e = e->NextSiblingElement();
        continue;
      }
      const char* file = e->Attribute("file");
      const std::string field = "mjcf: <include>" + Line(*e);
      if (file == nullptr || *file == '\0') ThrowInvalidArgument(field + " has no file attribute");
      if (++included > kMaxIncludes) {
        ThrowInvalidArgument(field + " file " + Quoted(file) + ": more than " + std::to_string(kMaxIncludes) +
                             " includes (a file that includes itself?)");
      }
      const std::string stripped = StripMeshUri(file);
      const std::string basename = stripped.substr(stripped.find_last_of('/') + 1);
      const std::string* bytes = nullptr;
      for (const std::string& candidate : {stripped, basename}) {
        if (bytes == nullptr && files && !candidate.empty()) bytes = files(candidate);
      }
      if (bytes == nullptr) ThrowInvalidArgument(field + " file " + Quoted(file) + " was not uploaded");
      CheckXmlText(field + " file " + Quoted(file), *bytes);
      tinyxml2::XMLDocument child;
      if (child.Parse(bytes->data(), bytes->size()) != tinyxml2::XML_SUCCESS) {
        ThrowInvalidArgument(field + " file " + Quoted(file) + ": XML error at line " +
                             std::to_string(child.ErrorLineNum()) + ": " +
                             (child.ErrorStr() != nullptr ? child.ErrorStr() : "not well-formed"));
      }
      const tinyxml2::XMLElement* child_root = child.RootElement();
      if (child_root == nullptr || std::string(child_root->Name()) != "mujoco") {
        ThrowInvalidArgument(field + " file " + Quoted(file) + ": the root element is not <mujoco>");
      }
      tinyxml2::XMLNode* after = e;
      for (const tinyxml2::XMLNode* node = child_root->FirstChild(); node != nullptr; node = node->NextSibling()) {
        if (node->ToElement() == nullptr) continue;
        after = parent->InsertAfterChild(after, node->DeepClone(&xml_));
      }
      tinyxml2::XMLElement* first_inserted = e->NextSiblingElement();
      parent->DeleteChild(e);
      // Visit what was inserted (it may include further files): go on at the first inserted element.
      e = first_inserted;
    }
  }
}

void Document::ReadCompiler(const tinyxml2::XMLElement& xml) {
  const Element compiler(xml, nullptr, "mjcf: <compiler>");
  if (const char* angle = compiler.Raw("angle"); angle != nullptr) {
    const std::string value = angle;
    if (value != "degree" && value != "radian") {
      ThrowInvalidArgument("mjcf: <compiler> angle: " + Quoted(value) + " is not \"degree\" or \"radian\"");
    }
    compiler_.degrees = value == "degree";
  }
  if (const char* seq = compiler.Raw("eulerseq"); seq != nullptr) {
    const std::string value = seq;
    if (value.size() != 3 || value.find_first_not_of("xyzXYZ") != std::string::npos) {
      ThrowInvalidArgument("mjcf: <compiler> eulerseq: " + Quoted(value) + " is not three of x, y, z, X, Y, Z");
    }
    compiler_.eulerseq = value;
  }
  if (const char* dir = compiler.Raw("assetdir"); dir != nullptr && compiler_.meshdir.empty()) compiler_.meshdir = dir;
  if (const char* dir = compiler.Raw("meshdir"); dir != nullptr) compiler_.meshdir = dir;
  if (const char* value = compiler.Raw("inertiafromgeom"); value != nullptr) {
    const std::string text = value;
    if (text == "true") {
      compiler_.inertia_from_geom = InertiaFromGeom::kTrue;
    } else if (text == "false") {
      compiler_.inertia_from_geom = InertiaFromGeom::kFalse;
    } else if (text == "auto") {
      compiler_.inertia_from_geom = InertiaFromGeom::kAuto;
    } else {
      ThrowInvalidArgument("mjcf: <compiler> inertiafromgeom: " + Quoted(text) + " is not true, false or auto");
    }
  }
  compiler_.autolimits = compiler.Bool("autolimits", compiler_.autolimits);
  compiler_.boundmass = compiler.Number("boundmass", compiler_.boundmass);
  compiler_.boundinertia = compiler.Number("boundinertia", compiler_.boundinertia);
  compiler_.settotalmass = compiler.Number("settotalmass", compiler_.settotalmass);
  if (const char* coordinate = compiler.Raw("coordinate"); coordinate != nullptr) {
    const std::string value = coordinate;
    if (value != "local" && value != "global") {
      ThrowInvalidArgument("mjcf: <compiler> coordinate: " + Quoted(value) + " is not \"local\" or \"global\"");
    }
    compiler_.global = value == "global";
  }
}

void Document::ReadDefaults(const tinyxml2::XMLElement& xml, const std::string& parent, int depth) {
  if (depth > kMaxDefaultDepth) ThrowInvalidArgument("mjcf: <default>" + Line(xml) + " nests too deeply");
  const char* class_attribute = xml.Attribute("class");
  std::string name;
  if (parent.empty()) {
    name = class_attribute == nullptr ? "main" : class_attribute;
  } else {
    if (class_attribute == nullptr || *class_attribute == '\0') {
      ThrowInvalidArgument("mjcf: <default>" + Line(xml) + " inside class " + Quoted(parent) + " has no class");
    }
    name = class_attribute;
    if (classes_.count(name) != 0) ThrowInvalidArgument("mjcf: default class " + Quoted(name) + " is defined twice");
    classes_[name] = classes_[parent];  // inherits every attribute of its parent
  }
  auto& own = classes_[name];
  for (const tinyxml2::XMLElement* e = xml.FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    const std::string tag = e->Name();
    if (tag == "default") continue;
    Attributes& attributes = own[tag];
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next()) {
      attributes[a->Name()] = a->Value();
    }
  }
  for (const tinyxml2::XMLElement* e = xml.FirstChildElement("default"); e != nullptr;
       e = e->NextSiblingElement("default")) {
    ReadDefaults(*e, name, depth + 1);
  }
}

Element Document::Read(const tinyxml2::XMLElement& xml, const std::string& child_class,
                       const std::string& field) const {
  const char* own = xml.Attribute("class");
  const std::string name = own != nullptr ? std::string(own) : child_class.empty() ? "main" : child_class;
  const auto it = classes_.find(name);
  if (it == classes_.end()) {
    ThrowInvalidArgument(field + " class: " + Quoted(name) + " is not a default class");
  }
  const auto tag = it->second.find(xml.Name());
  return Element(xml, tag == it->second.end() ? nullptr : &tag->second, field);
}

}  // namespace graspsim::import::mjcf
