// LoadMeshFile against meshes whose triangle counts and bounds are known exactly. Vertices are float32, so
// bounds are compared to 1e-6 m.
#include <array>
#include <cstdint>
#include <cstring>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "world/loaders.h"

namespace graspsim {
namespace {

constexpr double kBoundsTolerance = 1e-6;  // m

using Triangle = std::array<Eigen::Vector3f, 3>;

// The 12 triangles of the cube [-0.5, 0.5]^3, counter-clockwise seen from outside.
std::vector<Triangle> UnitCubeTriangles() {
  const auto corner = [](int i) {
    return Eigen::Vector3f(i & 1 ? 0.5f : -0.5f, i & 2 ? 0.5f : -0.5f, i & 4 ? 0.5f : -0.5f);
  };
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<Triangle> triangles;
  for (const auto& f : faces) {
    triangles.push_back({corner(f[0]), corner(f[1]), corner(f[2])});
    triangles.push_back({corner(f[0]), corner(f[2]), corner(f[3])});
  }
  return triangles;
}

std::string AsciiStlCube() {
  std::ostringstream out;
  out << "solid cube\n";
  for (const Triangle& t : UnitCubeTriangles()) {
    const Eigen::Vector3f n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    out << " facet normal " << n.x() << ' ' << n.y() << ' ' << n.z() << "\n  outer loop\n";
    for (const auto& v : t) out << "   vertex " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
    out << "  endloop\n endfacet\n";
  }
  out << "endsolid cube\n";
  return out.str();
}

// 80-byte header (not starting with "solid", which would read as ASCII), uint32 count, 50 bytes per triangle.
std::string BinaryStlCube() {
  const std::vector<Triangle> triangles = UnitCubeTriangles();
  std::string bytes(80, '\0');
  bytes.replace(0, 10, "binary stl");
  const auto append = [&bytes](const void* data, size_t size) {
    bytes.append(static_cast<const char*>(data), size);
  };
  const uint32_t count = static_cast<uint32_t>(triangles.size());
  append(&count, sizeof(count));
  for (const Triangle& t : triangles) {
    const Eigen::Vector3f n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    append(n.data(), 12);
    for (const auto& v : t) append(v.data(), 12);
    const uint16_t attributes = 0;
    append(&attributes, sizeof(attributes));
  }
  return bytes;
}

// A right triangle in the x-y plane (legs 1000 mm) and one standing on it, in millimetres with Z_UP, placed by
// a node at z = 500 mm and instanced a second time at x = 2000 mm.
constexpr const char* kColladaMillimetres = R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="millimeter" meter="0.001"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="tri" name="tri"><mesh>
      <source id="pos"><float_array id="pos-array" count="12">0 0 0 1000 0 0 0 1000 0 0 0 1000</float_array>
        <technique_common><accessor source="#pos-array" count="4" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <vertices id="verts"><input semantic="POSITION" source="#pos"/></vertices>
      <triangles count="2"><input semantic="VERTEX" source="#verts" offset="0"/><p>0 1 2 0 3 1</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="scene">
    <node id="first"><translate>0 0 500</translate><instance_geometry url="#tri"/></node>
    <node id="second"><translate>2000 0 500</translate><instance_geometry url="#tri"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>)";

// A square pyramid: 5 vertices, a quad base (→ 2 triangles) and 4 side triangles.
constexpr const char* kPlyPyramid = R"(ply
format ascii 1.0
element vertex 5
property float x
property float y
property float z
element face 5
property list uchar int vertex_indices
end_header
-1 -1 0
1 -1 0
1 1 0
-1 1 0
0 0 2
4 3 2 1 0
3 0 1 4
3 1 2 4
3 2 3 4
3 3 0 4
)";

void ExpectBounds(const TriangleMesh& mesh, const Eigen::Vector3f& min, const Eigen::Vector3f& max) {
  Eigen::Vector3f lo, hi;
  MeshBounds(mesh, &lo, &hi);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(lo[i], min[i], kBoundsTolerance) << "min axis " << i;
    EXPECT_NEAR(hi[i], max[i], kBoundsTolerance) << "max axis " << i;
  }
}

// Divergence theorem: positive for a closed mesh whose triangles are counter-clockwise seen from outside.
double SignedVolume(const TriangleMesh& mesh) {
  double volume = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(), b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    volume += a.dot(b.cross(c)) / 6;
  }
  return volume;
}

void ExpectError(const std::function<void()>& load, ErrorCode code, const std::vector<std::string>& fragments) {
  try {
    load();
    ADD_FAILURE() << "no error thrown";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    for (const std::string& fragment : fragments) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << "'" << fragment << "' not in: " << e.what();
    }
  }
}

TEST(MeshLoaderTest, AsciiStlCubeScaled) {
  const TriangleMesh mesh = LoadMeshFile("f", "cube.stl", AsciiStlCube(), Vec3::Constant(0.1), Limits());
  EXPECT_EQ(mesh.TriangleCount(), 12u);
  ExpectBounds(mesh, Eigen::Vector3f::Constant(-0.05f), Eigen::Vector3f::Constant(0.05f));
  EXPECT_NEAR(SignedVolume(mesh), 1e-3, 1e-9);
}

TEST(MeshLoaderTest, BinaryStlCubeScaledPerAxisAndExtensionCaseInsensitive) {
  const TriangleMesh mesh = LoadMeshFile("f", "parts/CUBE.STL", BinaryStlCube(), Vec3(0.1, 0.2, 0.3), Limits());
  EXPECT_EQ(mesh.TriangleCount(), 12u);
  ExpectBounds(mesh, Eigen::Vector3f(-0.05f, -0.1f, -0.15f), Eigen::Vector3f(0.05f, 0.1f, 0.15f));
}

TEST(MeshLoaderTest, MirroringScaleKeepsTrianglesFacingOutward) {
  const TriangleMesh mesh = LoadMeshFile("f", "cube.stl", BinaryStlCube(), Vec3(-0.1, 0.1, 0.1), Limits());
  EXPECT_NEAR(SignedVolume(mesh), 1e-3, 1e-9);
}

TEST(MeshLoaderTest, ObjQuadBecomesTwoTriangles) {
  const std::string obj = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nf 1 2 3 4\n";
  const TriangleMesh mesh = LoadMeshFile("f", "quad.obj", obj, Vec3::Ones(), Limits());
  EXPECT_EQ(mesh.TriangleCount(), 2u);
  ExpectBounds(mesh, Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(2, 1, 0));
}

TEST(MeshLoaderTest, AsciiPlyPyramid) {
  const TriangleMesh mesh = LoadMeshFile("f", "pyramid.ply", kPlyPyramid, Vec3::Ones(), Limits());
  EXPECT_EQ(mesh.TriangleCount(), 6u);
  ExpectBounds(mesh, Eigen::Vector3f(-1, -1, 0), Eigen::Vector3f(1, 1, 2));
}

// Units: 1000 mm → 1 m; up axis: Z_UP is not rotated to Y_UP; node transforms and both instances are applied.
TEST(MeshLoaderTest, ColladaInMillimetresComesOutInMetresWithNodeTransforms) {
  const TriangleMesh mesh = LoadMeshFile("f", "part.dae", kColladaMillimetres, Vec3::Ones(), Limits());
  EXPECT_EQ(mesh.TriangleCount(), 4u);
  ExpectBounds(mesh, Eigen::Vector3f(0, 0, 0.5f), Eigen::Vector3f(3, 1, 1.5f));
}

TEST(MeshLoaderTest, RejectsUnknownOrMissingExtension) {
  for (const std::string path : {"part.step", "part", "dir.stl/part"}) {
    ExpectError([&] { LoadMeshFile("files[0]", path, AsciiStlCube(), Vec3::Ones(), Limits()); },
                ErrorCode::kInvalidArgument, {"files[0]", "'" + path + "'", ".stl, .obj, .ply, .dae"});
  }
}

TEST(MeshLoaderTest, RejectsBytesThatDoNotParse) {
  const std::string garbage = "\x01\x02 this is not a mesh \xff\xfe";
  for (const std::string path : {"bad.stl", "bad.ply", "bad.dae"}) {
    ExpectError([&] { LoadMeshFile("files[1]", path, garbage, Vec3::Ones(), Limits()); },
                ErrorCode::kInvalidArgument, {"files[1]", path});
  }
}

TEST(MeshLoaderTest, RejectsEmptyFile) {
  ExpectError([] { LoadMeshFile("f", "empty.obj", "", Vec3::Ones(), Limits()); }, ErrorCode::kInvalidArgument,
              {"empty.obj", "empty"});
}

TEST(MeshLoaderTest, RejectsFileWithoutTriangles) {
  ExpectError([] { LoadMeshFile("f", "points.obj", "v 0 0 0\nv 1 0 0\n", Vec3::Ones(), Limits()); },
              ErrorCode::kInvalidArgument, {"points.obj"});
}

TEST(MeshLoaderTest, RejectsZeroOrNonFiniteScale) {
  ExpectError([] { LoadMeshFile("f", "cube.stl", AsciiStlCube(), Vec3(1, 0, 1), Limits()); },
              ErrorCode::kInvalidArgument, {"scale"});
  ExpectError([] { LoadMeshFile("f", "cube.stl", AsciiStlCube(), Vec3(1, NAN, 1), Limits()); },
              ErrorCode::kInvalidArgument, {"scale"});
}

TEST(MeshLoaderTest, TriangleLimitIsResourceExhausted) {
  Limits limits;
  limits.max_triangles_per_mesh = 11;
  ExpectError([&] { LoadMeshFile("f", "cube.stl", BinaryStlCube(), Vec3::Ones(), limits); },
              ErrorCode::kResourceExhausted, {"12", "11"});
  limits.max_triangles_per_mesh = 12;
  EXPECT_EQ(LoadMeshFile("f", "cube.stl", BinaryStlCube(), Vec3::Ones(), limits).TriangleCount(), 12u);
}

}  // namespace
}  // namespace graspsim
