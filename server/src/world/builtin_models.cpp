// The built-in model library: URDF files of server/models, compiled into the binary by
// server/cmake/EmbedModels.cmake (which generates graspsim::embedded::ModelFiles()).
#include <algorithm>
#include <array>
#include <utility>
#include <map>
#include <string>
#include <vector>

#include "core/error.h"
#include "world/loaders.h"

namespace graspsim {
namespace embedded {
// File name ("table.urdf") → contents; defined in the build's generated builtin_models_data.cpp.
const std::map<std::string, std::string>& ModelFiles();
}  // namespace embedded

namespace {

// A hand on an arm's flange: a built-in made from two others by joining their URDFs with a fixed joint. Every
// hand's root frame is its mounting face with +z the approach (server/models/README.md), so the joint is the
// identity: the hand's approach is the flange's +z.
struct ArmHandMount {
  std::string name, arm, hand, hand_root;
};

const std::vector<ArmHandMount>& ArmHandMounts() {
  static const std::vector<ArmHandMount> mounts = [] {
    std::vector<ArmHandMount> out;
    const std::pair<const char*, const char*> arms[] = {{"kuka_kr5_sixx_r850", "kuka_kr5_sixx_r850"},
                                                         {"mitsubishi_pa10", "mitsubishi_pa10"}};
    const std::array<std::array<const char*, 3>, 3> hands = {{{"barrett", "barrett_bh8_282", "palm"},
                                                              {"sdh2", "schunk_sdh2", "palm"},
                                                              {"pg70", "schunk_pg70", "base_link"}}};
    for (const auto& [prefix, arm] : arms) {
      for (const auto& [suffix, hand, root] : hands) {
        out.push_back({std::string(prefix) + "_" + suffix, arm, hand, root});
      }
    }
    return out;
  }();
  return mounts;
}

// The text between a URDF's <robot ...> tag and its </robot>.
std::string RobotBody(const std::string& urdf, const std::string& name) {
  const size_t open = urdf.find("<robot");
  const size_t body = open == std::string::npos ? open : urdf.find('>', open);
  const size_t close = urdf.rfind("</robot>");
  if (body == std::string::npos || close == std::string::npos || close < body) {
    throw Error(ErrorCode::kInternal, "builtin model '" + name + "' has no <robot> element");
  }
  return urdf.substr(body + 1, close - body - 1);
}

std::string MountedUrdf(const ArmHandMount& mount, const std::map<std::string, std::string>& files) {
  const std::string& arm = files.at(mount.arm + ".urdf");
  const std::string& hand = files.at(mount.hand + ".urdf");
  return "<?xml version=\"1.0\"?>\n<!-- " + mount.arm + " with " + mount.hand +
         " on its flange (built by server/src/world/builtin_models.cpp; sources in both files) -->\n<robot name=\"" +
         mount.name + "\">" + RobotBody(arm, mount.arm) + RobotBody(hand, mount.hand) +
         "  <joint name=\"flange_to_hand\" type=\"fixed\">\n    <parent link=\"flange\"/>\n    <child link=\"" +
         mount.hand_root + "\"/>\n    <origin xyz=\"0 0 0\"/>\n  </joint>\n</robot>\n";
}

}  // namespace

const std::vector<BuiltinModelInfo>& BuiltinModels() {
  static const std::vector<BuiltinModelInfo> models = {
      {"schunk_pg70", "robot", false,
       "Schunk PG 70 servo-electric parallel gripper (35 mm stroke per finger, 200 N) with a Weiss Robotics "
       "DSA 9205 tactile sensor (6 x 14 texels, 3.4 mm pitch) on each finger; Schunk PG 70 and Weiss DSA 9205 "
       "datasheets"},
      {"table", "object", true, "Table, 1.2 x 0.8 m top with its upper surface 0.75 m above the floor, 20 kg"},
      {"cube_5cm", "object", false, "Cube of 5 cm edge, 0.1 kg (density 800 kg/m^3, like hardwood)"},
      {"schunk_pg70_on_z_axis", "robot", false,
       "The Schunk PG 70 with its two DSA 9205 pads, pointing down from the carriage (1 kg) of a vertical linear "
       "axis (joint z_axis: 0.30 m travel, 0.2 m/s, 500 N): the set-up of the grasp work cycle "
       "(TactileService.RunWorkCycle); Schunk PG 70 and Weiss DSA 9205 datasheets, generic axis"},
      {"barrett_bh8_282", "robot", false,
       "Barrett Technology BarrettHand BH8-282: three fingers, coupled spread of fingers 1 and 2 (0-180 deg), "
       "flex joints 0-140 deg with the outer links coupled at 48/140; BH8-series user manual and data sheet"},
      {"schunk_sdh2", "robot", false,
       "SCHUNK SDH 2.0 dexterous hand: three fingers, seven joints (coupled rotation of fingers 1 and 3, "
       "proximal and distal flex joints -90..90 deg, phalanges 86.5 and 68.5 mm); SCHUNK SDH 2.0 data sheet"},
      {"kuka_kr5_sixx_r850", "robot", false,
       "KUKA KR 5 sixx R850: six-axis arm with a spherical wrist, 850 mm reach, tool frame `flange`; "
       "KUKA KR 5 sixx specification"},
      {"mitsubishi_pa10", "robot", false,
       "Mitsubishi PA10-7C: seven-axis redundant arm (d1 317, d3 450, d5 480, d7 70 mm), tool frame `flange`; "
       "MHI PA10 catalogue, D-H lengths from Bompos et al. 2007"},
  };
  // Every arm with every hand on its flange: "<arm>_<hand>".
  static const std::vector<BuiltinModelInfo> all = [] {
    std::vector<BuiltinModelInfo> out = models;
    for (const ArmHandMount& mount : ArmHandMounts()) {
      out.push_back({mount.name, "robot", false,
                     "The " + mount.arm + " with the " + mount.hand + " on its flange (fixed joint flange_to_hand, "
                     "the hand's +z along the flange's +z)"});
    }
    return out;
  }();
  return all;
}

const std::string& BuiltinModelUrdf(const std::string& name) {
  const std::vector<BuiltinModelInfo>& models = BuiltinModels();
  const bool known = std::any_of(models.begin(), models.end(), [&](const auto& m) { return m.name == name; });
  if (!known) {
    std::vector<std::string> names;
    for (const BuiltinModelInfo& model : models) names.push_back(model.name);
    std::sort(names.begin(), names.end());
    std::string list;
    for (const std::string& known_name : names) list += (list.empty() ? "" : ", ") + known_name;
    ThrowNotFound("builtin model '" + name + "' is not known; known: " + list);
  }
  const auto& files = embedded::ModelFiles();
  static const std::map<std::string, std::string> mounted = [&] {
    std::map<std::string, std::string> out;
    for (const ArmHandMount& mount : ArmHandMounts()) out[mount.name] = MountedUrdf(mount, files);
    return out;
  }();
  if (const auto it = mounted.find(name); it != mounted.end()) return it->second;
  const auto file = files.find(name + ".urdf");
  if (file == files.end()) {  // the build did not embed server/models/<name>.urdf
    throw Error(ErrorCode::kInternal, "builtin model '" + name + "' has no embedded " + name + ".urdf");
  }
  return file->second;
}

}  // namespace graspsim
