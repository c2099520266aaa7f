// SDF text → RobotDescription through libsdformat 12 (import/robot_import.h ImportSdf): parsing, libsdformat's
// errors, the choice of model; sdf_model.cpp turns the model into a tree, sdf_links.cpp its links. libsdformat never
// reads a file here: <include> is refused before parsing (it would search the disk), and its console log is kept
// off the disk (QuietConsole).
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <tinyxml2.h>

#include "core/error.h"
#include "import/sdf_internal.h"

namespace graspsim {
namespace {

using import::Quoted;

// libsdformat's console opens $HOME/.sdformat/sdformat.log the first time anything logs and appends every warning
// to it (flushed per message): hostile input could grow it without bound. Creating the console once, at static
// initialisation (single-threaded), with HOME pointing nowhere leaves it without a log file; SetQuiet keeps its
// messages off stderr (the caller gets errors in its status).
struct QuietConsole {
  QuietConsole() {
    const char* home = std::getenv("HOME");
    const std::string saved = home != nullptr ? home : "";
    setenv("HOME", "/nonexistent/graspsim-no-sdformat-log", 1);
    sdf::Console::Instance()->SetQuiet(true);
    if (home != nullptr) {
      setenv("HOME", saved.c_str(), 1);
    } else {
      unsetenv("HOME");
    }
  }
};
const QuietConsole kQuietConsole;

// <include> makes libsdformat search the disk (and SDF_PATH) for the model: refused before parsing, naming the URI.
void RefuseIncludes(const std::string& text) {
  for (size_t at = text.find("<include"); at != std::string::npos; at = text.find("<include", at + 1)) {
    const size_t after = at + 8;
    if (after < text.size() && !std::isspace(static_cast<unsigned char>(text[after])) && text[after] != '>' &&
        text[after] != '/') {
      continue;
    }
    std::string uri = "(no <uri>)";
    const size_t end = text.find("</include>", at);
    const size_t open = text.find("<uri>", at);
    if (open != std::string::npos && (end == std::string::npos || open < end)) {
      const size_t close = text.find("</uri>", open);
      if (close != std::string::npos) uri = Quoted(text.substr(open + 5, std::min<size_t>(close - open - 5, 200)));
    }
    const size_t line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
    ThrowInvalidArgument("sdf: <include> of " + uri + " at line " + std::to_string(line) +
                         ": included models are not supported; put the model's <model> element in the file");
  }
}

// libsdformat copies an element's whole schema for every element it reads: about 1.6 ms per <link>, 0.8 per
// <joint>, 7 per nested <model>, 13 per <world>, 0.3 per <collision> or <visual>, 15 us per small element (measured
// on this machine). Counted before parsing, so that no text keeps it busy for more than a few seconds: links and
// joints up to the scene's body limit, the rest to generous bounds no real robot approaches. A URDF (libsdformat
// would convert it with its own copy of urdfdom) is sent to the URDF loader instead.
void CheckElements(const std::string& text, const Limits& limits) {
  std::map<std::string, size_t> counts;
  size_t total = 0;
  std::string first;
  for (size_t at = text.find('<'); at != std::string::npos; at = text.find('<', at + 1)) {
    if (text.compare(at, 4, "<!--") == 0) {
      at = text.find("-->", at);
      if (at == std::string::npos) break;
      continue;
    }
    size_t end = at + 1;
    while (end < text.size() && (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_')) ++end;
    if (end == at + 1) continue;  // "</", "<?", "<!"
    ++total;
    const std::string tag = text.substr(at + 1, end - at - 1);
    ++counts[tag];
    if (first.empty()) first = tag;
  }
  if (first == "robot") ThrowInvalidArgument("sdf: the root element is <robot>: a URDF; send it as urdf");
  const size_t bodies = limits.max_bodies_per_scene;
  const struct {
    std::vector<const char*> tags;
    size_t limit;
  } bounds[] = {{{"link"}, bodies},
                {{"joint"}, bodies},
                {{"model", "world", "actor"}, 128},
                {{"collision", "visual", "sensor", "light"}, 8 * bodies},
                {{}, 100'000}};
  for (const auto& bound : bounds) {
    size_t count = bound.tags.empty() ? total : 0;
    std::string names;
    for (const char* tag : bound.tags) {
      const auto it = counts.find(tag);
      count += it == counts.end() ? 0 : it->second;
      names += (names.empty() ? "<" : ", <") + std::string(tag) + ">";
    }
    if (count > bound.limit) {
      ThrowResourceExhausted("sdf: the text has " + std::to_string(count) + " " +
                             (names.empty() ? std::string("elements") : names + " elements") + ", above the limit of " +
                             std::to_string(bound.limit));
    }
  }
}

// libsdformat's errors that PyBullet's files trigger and graspsim handles itself: inertia it judges with
// ResolveInertials, collisions whose names repeat (read from the element), a link named "world".
bool Tolerated(const sdf::Error& error) {
  const std::string message = error.Message();
  switch (error.Code()) {
    case sdf::ErrorCode::LINK_INERTIA_INVALID: return true;
    case sdf::ErrorCode::DUPLICATE_NAME:
      return message.starts_with("collision with name") || message.starts_with("visual with name") ||
             message.starts_with("model with name");
    case sdf::ErrorCode::RESERVED_NAME: return message.find("link name [world]") != std::string::npos;
    default: return false;
  }
}

}  // namespace

ImportedRobot ImportSdf(const std::string& text, const FileLookup& files, const ImportOptions& options,
                        const Limits& limits) {
  import::CheckXmlText("sdf", text);
  RefuseIncludes(text);
  CheckElements(text, limits);
  {
    // libsdformat prints an XML syntax error to its console and reports only that the text is not SDF.
    tinyxml2::XMLDocument document;
    if (document.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
      ThrowInvalidArgument("sdf: XML error at line " + std::to_string(document.ErrorLineNum()) + ": " +
                           document.ErrorStr());
    }
  }
  // libsdformat makes no promise about threads (its console and schema cache are process-wide); imports are rare
  // and short, so one at a time.
  static std::mutex libsdformat;
  const std::lock_guard<std::mutex> lock(libsdformat);
  sdf::ParserConfig config;
  config.SetFindCallback([](const std::string&) { return std::string(); });
  config.SetWarningsPolicy(sdf::EnforcementPolicy::LOG);
  config.SetUnrecognizedElementsPolicy(sdf::EnforcementPolicy::LOG);
  config.SetDeprecatedElementsPolicy(sdf::EnforcementPolicy::LOG);
  sdf::Root root;
  sdf::Errors errors;
  try {
    // Root::LoadSdfString builds SDF's schema (every element's description, from libsdformat's embedded files)
    // anew for each text, about 25 ms; copying one built once takes half that. Otherwise the same steps.
    static const sdf::ElementPtr schema = [] {
      const auto description = std::make_shared<sdf::SDF>();
      sdf::init(description);
      return description->Root();
    }();
    const auto parsed = std::make_shared<sdf::SDF>();
    parsed->Root(schema->Clone());
    if (sdf::readString(text, config, parsed, errors)) {
      const sdf::Errors loaded = root.Load(parsed, config);
      errors.insert(errors.end(), loaded.begin(), loaded.end());
    } else if (errors.empty()) {
      errors.emplace_back(sdf::ErrorCode::STRING_READ, "the text is not SDF (nor URDF, which libsdformat converts)");
    }
  } catch (const std::exception& e) {
    ThrowInvalidArgument(std::string("sdf: libsdformat could not read the file: ") + e.what());
  }
  std::string refused;
  size_t count = 0;
  std::vector<std::string> repeated_models;  // libsdformat keeps the first model of a name (model2.sdf has two)
  for (const sdf::Error& error : errors) {
    if (error.Code() == sdf::ErrorCode::DUPLICATE_NAME && error.Message().starts_with("model with name")) {
      repeated_models.push_back(error.Message());
    }
    if (Tolerated(error) || error.Message().starts_with("Failed to load a world")) continue;
    if (++count <= 5) refused += (refused.empty() ? "" : "; ") + import::Describe(error);
  }
  if (count > 5) refused += "; and " + std::to_string(count - 5) + " more";
  if (count > 0 || (!errors.empty() && root.Model() == nullptr && root.WorldCount() == 0)) {
    ThrowInvalidArgument("sdf: " + (refused.empty() ? import::Describe(errors[0]) : refused));
  }

  std::vector<std::pair<const sdf::Model*, Pose>> models;
  if (const sdf::Model* model = root.Model(); model != nullptr) {
    models.emplace_back(model, import::ToPose(model->RawPose(), "sdf: model " + Quoted(model->Name()) + " pose"));
  }
  for (uint64_t w = 0; w < root.WorldCount(); ++w) {
    const sdf::World* world = root.WorldByIndex(w);
    for (uint64_t m = 0; m < world->ModelCount(); ++m) {
      const sdf::Model* model = world->ModelByIndex(m);
      ignition::math::Pose3d pose = model->RawPose();
      model->SemanticPose().Resolve(pose, "world");  // on error the raw pose stays: the world frame is the default
      models.emplace_back(model, import::ToPose(pose, "sdf: model " + Quoted(model->Name()) + " pose"));
    }
  }
  if (models.empty()) ThrowInvalidArgument("sdf: the file has no <model>");
  size_t chosen = 0;
  if (!options.model_name.empty()) {
    std::string names;
    for (chosen = 0; chosen < models.size() && models[chosen].first->Name() != options.model_name; ++chosen) {
      names += (names.empty() ? "" : ", ") + Quoted(models[chosen].first->Name());
    }
    if (chosen == models.size()) {
      ThrowInvalidArgument("sdf: model_name " + Quoted(options.model_name) + ": the file has no such model (it has " +
                           names + ")");
    }
  }
  ImportedRobot robot = import::ConvertSdfModel(*models[chosen].first, models[chosen].second, files, options, limits);
  import::SdfRepairs repairs(options.strict, &robot.warnings);
  for (const std::string& message : repeated_models) {
    repairs.Warn("sdf: <world>", "(" + message + ")", "only the first model of that name can be loaded");
  }
  return robot;
}

}  // namespace graspsim
