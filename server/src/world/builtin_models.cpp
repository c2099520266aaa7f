// The built-in model library: URDF files of server/models, compiled into the binary by
// server/cmake/EmbedModels.cmake (which generates graspsim::embedded::ModelFiles()).
#include <algorithm>
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
  };
  return models;
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
  const auto file = files.find(name + ".urdf");
  if (file == files.end()) {  // the build did not embed server/models/<name>.urdf
    throw Error(ErrorCode::kInternal, "builtin model '" + name + "' has no embedded " + name + ".urdf");
  }
  return file->second;
}

}  // namespace graspsim
