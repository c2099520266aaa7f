// TEMPORARY dev harness (removed before report).
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <gtest/gtest.h>
#include "core/error.h"
#include "import/robot_import.h"
namespace graspsim {
TEST(SdfDev, PybulletData) {
  const char* list = std::getenv("SDF_DEV_FILES");
  if (list == nullptr) GTEST_SKIP();
  std::istringstream files(list);
  for (std::string path; files >> path;) {
    std::ifstream f(path); std::stringstream ss; ss << f.rdbuf();
    const std::string dir = path.substr(0, path.find_last_of('/') + 1);
    std::map<std::string, std::string> cache;
    FileLookup lookup = [&](const std::string& p) -> const std::string* {
      auto it = cache.find(p);
      if (it != cache.end()) return &it->second;
      std::ifstream m(dir + p, std::ios::binary); if (!m) { std::cout << "   lookup miss " << p << "\n"; return nullptr; }
      std::stringstream b; b << m.rdbuf(); return &(cache[p] = b.str());
    };
    std::cout << "== " << path << "\n";
    try {
      ImportedRobot r = ImportSdf(ss.str(), lookup, ImportOptions{}, Limits{});
      std::cout << "  OK name=" << r.description.name << " root=" << r.description.root_link << " links=" << r.description.links.size() << " joints=" << r.description.joints.size() << "\n";
      for (auto& l : r.description.links) std::cout << "   link " << l.id << " m=" << l.inertial.mass << " geoms=" << l.collision.size() << "\n";
      for (auto& j : r.description.joints) std::cout << "   joint " << j.id << " t=" << int(j.type) << " " << j.parent_body << "->" << j.child_body << " o=" << j.origin.position.transpose() << " ax=" << j.axis.transpose() << " [" << j.lower << "," << j.upper << "]\n";
      for (auto& w : r.warnings) std::cout << "   WARN " << w.element << " | " << w.value << " | " << w.action << "\n";
    } catch (const std::exception& e) { std::cout << "  FAIL " << e.what() << "\n"; }
  }
}
}  // namespace graspsim
