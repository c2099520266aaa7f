// MotionBenchMaker's Panda problems (Chamzas et al. 2022, as shipped by VAMP) for the motion suites: problems.txt
// (written by tests/data/mbm.py; format in its docstring) parsed, and a problem's scene built around the Panda of
// panda_spherized.urdf (whose collision geometry is VAMP's spheres).
#pragma once

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/limits.h"
#include "import/robot_import.h"
#include "motion/collision_checker.h"
#include "motion_test_scenes.h"
#include "source_tree.h"

namespace graspsim::motion_test {

constexpr const char* kMbmFetch = "build/venv/bin/python tests/data/mbm.py fetch";

struct MbmObstacle {
  std::string kind;  // "box", "cylinder", "sphere"
  std::string id;
  Vec3 size = Vec3::Zero();  // box: full edges; cylinder: (radius, length, 0); sphere: (radius, 0, 0)
  Pose pose;
};

struct MbmProblem {
  std::string scene;
  int index = 0;
  motion::VecX start, goal;  // panda_joint1..7, rad
  std::vector<MbmObstacle> obstacles;
};

// Throws std::runtime_error naming the line on anything malformed.
inline std::vector<MbmProblem> ParseMbmProblems(std::istream& in, const std::string& name = "problems.txt") {
  std::vector<MbmProblem> out;
  MbmProblem current;
  bool open = false;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    std::istringstream words(line);
    std::string head;
    if (!(words >> head)) continue;
    const auto fail = [&](const std::string& why) {
      throw std::runtime_error(name + ":" + std::to_string(number) + ": " + why + ": " + line);
    };
    const auto numbers = [&](size_t count) {
      std::vector<double> v;
      std::string word;
      while (words >> word) {
        char* end = nullptr;
        v.push_back(std::strtod(word.c_str(), &end));
        if (*end != '\0') fail("not a number '" + word + "'");
      }
      if (v.size() != count) fail(std::to_string(v.size()) + " numbers, " + std::to_string(count) + " expected");
      return v;
    };
    if (head == "problem") {
      if (open) fail("problem inside a problem");
      current = MbmProblem();
      if (!(words >> current.scene >> current.index)) fail("expected 'problem <scene> <index>'");
      open = true;
      continue;
    }
    if (!open) fail("outside a problem block");
    if (head == "start" || head == "goal") {
      const std::vector<double> v = numbers(7);
      (head == "start" ? current.start : current.goal) = Eigen::Map<const motion::VecX>(v.data(), 7);
    } else if (head == "box" || head == "cylinder" || head == "sphere") {
      MbmObstacle o;
      o.kind = head;
      if (!(words >> o.id)) fail("no id");
      const size_t dims = head == "box" ? 3 : head == "cylinder" ? 2 : 1;
      const std::vector<double> v = numbers(dims + (head == "sphere" ? 3 : 7));
      for (size_t i = 0; i < dims; ++i) o.size[i] = v[i];
      o.pose.position = Vec3(v[dims], v[dims + 1], v[dims + 2]);
      o.pose.orientation = head == "sphere" ? Quat::Identity()
                                            : Quat(v[dims + 6], v[dims + 3], v[dims + 4], v[dims + 5]).normalized();
      current.obstacles.push_back(o);
    } else if (head == "end") {
      if (current.start.size() != 7 || current.goal.size() != 7) fail("problem without start or goal");
      out.push_back(std::move(current));
      open = false;
    } else {
      fail("unknown line kind '" + head + "'");
    }
  }
  if (open) throw std::runtime_error(name + ": the last problem has no 'end'");
  return out;
}

// GRASPSIM_MBM_DIR, else <repo>/build/bench-data/mbm/panda.
inline std::string MbmDirectory() {
  const char* dir = std::getenv("GRASPSIM_MBM_DIR");
  return dir && *dir ? dir : SourceTree() + "/build/bench-data/mbm/panda";
}

inline bool ReadFile(const std::string& path, std::string* text) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return false;
  std::ostringstream s;
  s << file.rdbuf();
  *text = s.str();
  return true;
}

// The URDF without its <visual> elements (meshes the collision check never reads).
inline std::string WithoutVisuals(std::string urdf) {
  for (size_t at; (at = urdf.find("<visual")) != std::string::npos;) {
    const size_t end = urdf.find("</visual>", at);
    if (end == std::string::npos) throw std::runtime_error("unclosed <visual> in the URDF");
    urdf.erase(at, end + 9 - at);
  }
  return urdf;
}

inline Geometry MbmGeometry(const MbmObstacle& o) {
  if (o.kind == "box") return BoxGeometry(o.size);
  if (o.kind == "cylinder") return CylinderGeometry(o.size[0], o.size[1]);
  return SphereGeometry(o.size[0]);
}

// The Panda (robot "panda", base at the origin: MBM's world frame is panda_link0) among the problem's obstacles.
inline ArmScene MbmScene(const MbmProblem& problem, const std::string& urdf_text) {
  const ImportedRobot panda = ImportUrdf(urdf_text, nullptr, ImportOptions(), Limits());
  ArmScene out;
  out.scene = std::make_unique<Scene>("mbm", problem.scene, Limits());
  out.scene->AddRobot("panda", "mbm:panda_spherized.urdf", panda.description, Pose{});
  for (const MbmObstacle& o : problem.obstacles) AddStatic(out.scene.get(), o.id, MbmGeometry(o), o.pose);
  out.view = out.scene->View();
  return out;
}

// The problem's obstacles straight from the file (not through CollectObstacles), for the reference and for
// checkers of the other problems of a scene.
inline motion::Obstacles MbmObstacles(const MbmProblem& problem) {
  motion::Obstacles out;
  for (const MbmObstacle& o : problem.obstacles) {
    const uint32_t body = static_cast<uint32_t>(out.body_ids.size());
    out.body_ids.push_back(o.id);
    const Mat3 rotation = o.pose.orientation.toRotationMatrix();
    if (o.kind == "box") {
      out.boxes.push_back({rotation, o.pose.position, 0.5 * o.size, body});
    } else if (o.kind == "cylinder") {
      out.cylinders.push_back({rotation, o.pose.position, o.size[0], 0.5 * o.size[1], body});
    } else {
      out.balls.push_back({o.pose.position, o.size[0], body});
    }
  }
  return out;
}

}  // namespace graspsim::motion_test
