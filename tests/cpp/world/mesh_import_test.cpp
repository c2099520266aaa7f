// Mesh files are parsed in graspsim-mesh-import (world/mesh_import.h): files that crash, abort or exhaust Assimp
// in-process (found by tests/fuzz/mesh_fuzz.cpp, kept in tests/fuzz/regressions) answer an error naming the file
// here, and this process goes on.
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "source_tree.h"
#include "world/loaders.h"

namespace graspsim {
namespace {

// A fuzz input: its first byte picked the extension (stl, obj, ply, dae), the rest is the file.
struct FuzzFile {
  std::string path, bytes;
};

FuzzFile Regression(const std::string& name) {
  std::ifstream file(SourceTree() + "/tests/fuzz/regressions/" + name, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  const std::string data = text.str();
  EXPECT_FALSE(data.empty()) << name;
  static const char* const kExtensions[] = {"stl", "obj", "ply", "dae"};
  return {std::string("meshes/hostile.") + kExtensions[static_cast<unsigned char>(data[0]) % 4], data.substr(1)};
}

class HostileMeshFile : public testing::TestWithParam<const char*> {};

TEST_P(HostileMeshFile, IsAnErrorNamingTheFileNotACrash) {
  const FuzzFile file = Regression(GetParam());
  try {
    LoadMeshFile("geometry.mesh_file", file.path, file.bytes, Vec3(1, 1, 1), Limits{});
    FAIL() << GetParam() << " loaded";
  } catch (const Error& error) {
    EXPECT_TRUE(error.code() == ErrorCode::kInvalidArgument || error.code() == ErrorCode::kResourceExhausted)
        << error.what();
    EXPECT_NE(std::string(error.what()).find("geometry.mesh_file: mesh file '" + file.path + "'"), std::string::npos)
        << error.what();
  }
}

INSTANTIATE_TEST_SUITE_P(FuzzRegressions, HostileMeshFile,
                         testing::Values("mesh_ply_unterminated_header", "mesh_ply_face_count_abort",
                                         "mesh_dae_oom", "mesh_ply_cpu_spin"));

TEST(MeshImport, ParserErrorsKeepTheirCodeAndMessage) {
  // An unsupported extension is refused before a child starts; a file the parser rejects comes back as its
  // INVALID_ARGUMENT; a triangle limit is the child's RESOURCE_EXHAUSTED.
  EXPECT_THROW(LoadMeshFile("f", "a.xyz", "x", Vec3(1, 1, 1), Limits{}), Error);
  try {
    LoadMeshFile("f", "a.obj", "this is not an obj file\n", Vec3(1, 1, 1), Limits{});
    FAIL();
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::kInvalidArgument) << error.what();
    EXPECT_NE(std::string(error.what()).find("f: mesh file 'a.obj'"), std::string::npos) << error.what();
  }
  const std::string two_triangles = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
  Limits one;
  one.max_triangles_per_mesh = 1;
  try {
    LoadMeshFile("f", "a.obj", two_triangles, Vec3(1, 1, 1), one);
    FAIL();
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::kResourceExhausted) << error.what();
  }
  const TriangleMesh mesh = LoadMeshFile("f", "a.obj", two_triangles, Vec3(2, 2, 2), Limits{});
  ASSERT_EQ(mesh.triangles.size(), 2u);
  float max_x = 0;
  for (const auto& v : mesh.vertices) max_x = std::max(max_x, v.x());
  EXPECT_FLOAT_EQ(max_x, 2.0f);  // the scale applied in the child
}

}  // namespace
}  // namespace graspsim
