// Turning files into models: mesh files (Assimp: STL, OBJ, PLY, DAE) and the built-in model library (server/models,
// compiled into the binary); robot formats are in import/robot_import.h. Every loader validates what it reads and
// throws Error(kInvalidArgument) naming the field, the file and the problem; it never returns half a model.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/limits.h"
#include "core/math.h"
#include "core/mesh.h"
#include "world/model.h"

namespace graspsim {

// Looks up a file the client uploaded to the scene (or sent inline) by its relative path; nullptr if absent.
using FileLookup = std::function<const std::string*(const std::string& path)>;

// Parses mesh bytes; the format is taken from the path's extension (.stl, .obj, .ply, .dae). Scale is applied
// per axis. All triangles of all sub-meshes are merged into one mesh in the file's root frame.
// `field` names the request field for error messages.
TriangleMesh LoadMeshFile(const std::string& field, const std::string& path, std::string_view bytes,
                          const Vec3& scale, const Limits& limits);
// The same mesh, shared (read-only) with every other load of the same bytes and scale: parsed meshes are kept by
// content (world/parsed_mesh_cache.h), so a robot added to many scenes holds its triangles once.
std::shared_ptr<const TriangleMesh> LoadSharedMeshFile(const std::string& field, const std::string& path,
                                                       std::string_view bytes, const Vec3& scale, const Limits& limits);


struct BuiltinModelInfo {
  std::string name;         // "schunk_pg70", "table", "cube_5cm"
  std::string kind;         // "robot" or "object"
  bool is_static = false;   // objects only: the table never moves
  std::string description;  // what it is; the datasheet its dimensions come from
};

const std::vector<BuiltinModelInfo>& BuiltinModels();
// The model's URDF text; throws Error(kNotFound) naming the model and listing the known names.
const std::string& BuiltinModelUrdf(const std::string& name);

}  // namespace graspsim
