// MJCF geoms: MuJoCo's primitives as graspsim's (box, sphere, cylinder, mesh), capsules as a cylinder and two
// spheres, ellipsoids as meshes, planes as thin boxes; and each geom's mass properties as MuJoCo's compiler
// computes them for inertiafromgeom (density × volume, or the geom's mass; closed forms for the primitives).
#include "import/mjcf_geometry.h"

#include <array>
#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "core/format.h"
#include "core/validate.h"
#include "import/mass_properties.h"
#include "import/primitive_shapes.h"

namespace graspsim::import::mjcf {
namespace {

// A plane of size 0 (infinite in MuJoCo) becomes a square of this edge, and every plane a slab this thick below
// its surface: graspsim has no unbounded shapes.
constexpr double kInfinitePlaneEdge = 100;  // m

std::string Format(double value) { return FormatNumber(value); }

// Mass properties of a solid in its own frame (centre at the origin, principal axes along x, y, z).
struct LocalMass {
  double volume = 0;
  Vec3 inertia_per_mass = Vec3::Zero();  // diagonal, m^2
};

Inertial Place(const Pose& pose, double mass, const Vec3& inertia_per_mass) {
  Inertial inertial;
  inertial.mass = mass;
  inertial.center_of_mass = pose.position;
  const Mat3 rotation = pose.orientation.toRotationMatrix();
  const Mat3 local = (mass * inertia_per_mass).asDiagonal();
  const Mat3 in_body = rotation * local * rotation.transpose();
  inertial.inertia = 0.5 * (in_body + in_body.transpose());
  return inertial;
}

}  // namespace

void Warnings::Repair(const std::string& element, const std::string& value, const std::string& action) {
  if (strict_) ThrowInvalidArgument(element + ": " + value + " would need a repair (" + action + "); strict loading");
  out_->push_back({element, value, action});
}

void Warnings::Note(const std::string& element, const std::string& value, const std::string& action) {
  out_->push_back({element, value, action});
}

void Warnings::NoteOnce(const std::string& element, const std::string& value, const std::string& action) {
  if (noted_[element]) return;
  noted_[element] = true;
  Note(element, value, action);
}

MeshVolume LegacyMeshVolume(const TriangleMesh& mesh) {
  // Each triangle's area, unit normal and centre (MuJoCo's triangle()).
  const auto triangle = [&](const std::array<uint32_t, 3>& t, const Vec3& shift, Vec3* normal, Vec3* centre) {
    const Vec3 a = mesh.vertices[t[0]].cast<double>() - shift, b = mesh.vertices[t[1]].cast<double>() - shift,
               c = mesh.vertices[t[2]].cast<double>() - shift;
    const Vec3 cross = (b - a).cross(c - a);
    const double norm = cross.norm();
    *normal = norm > 0 ? Vec3(cross / norm) : Vec3::Zero();
    *centre = (a + b + c) / 3;
    return norm / 2;
  };
  Vec3 normal, centre, face_centroid = Vec3::Zero();
  double area = 0;
  for (const auto& t : mesh.triangles) {
    const double a = triangle(t, Vec3::Zero(), &normal, &centre);
    face_centroid += a * centre;
    area += a;
  }
  MeshVolume out;
  if (!(area > 1e-14)) return out;
  face_centroid /= area;
  double volume = 0;
  Vec3 centroid = Vec3::Zero();
  for (const auto& t : mesh.triangles) {
    const double a = triangle(t, Vec3::Zero(), &normal, &centre);
    const double v = std::abs((centre - face_centroid).dot(normal) * a / 3);
    volume += v;
    centroid += v * (centre * 0.75 + face_centroid * 0.25);
  }
  if (!(volume > 1e-14)) return out;
  out.centroid = centroid / volume;
  // Second moments of the pyramids from the centroid (ComputeInertia), which also give the volume MuJoCo keeps.
  double products[6] = {0, 0, 0, 0, 0, 0};
  constexpr int k[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
  volume = 0;
  for (const auto& t : mesh.triangles) {
    const double a = triangle(t, out.centroid, &normal, &centre);
    const double v = std::abs(centre.dot(normal) * a / 3);
    volume += v;
    const Vec3 d = mesh.vertices[t[0]].cast<double>() - out.centroid;
    const Vec3 e = mesh.vertices[t[1]].cast<double>() - out.centroid;
    const Vec3 f = mesh.vertices[t[2]].cast<double>() - out.centroid;
    for (int j = 0; j < 6; ++j) {
      const int p = k[j][0], q = k[j][1];
      products[j] += v / 20 *
                     (2 * (d[p] * d[q] + e[p] * e[q] + f[p] * f[q]) + d[p] * e[q] + d[q] * e[p] + d[p] * f[q] +
                      d[q] * f[p] + e[p] * f[q] + e[q] * f[p]);
    }
  }
  out.volume = volume;
  out.inertia_per_density << products[1] + products[2], -products[3], -products[4],  //
      -products[3], products[0] + products[2], -products[5],                         //
      -products[4], -products[5], products[0] + products[1];
  return out;
}

GeomReader::GeomReader(const Document& document, const ImportOptions& options, const Limits& limits,
                       MeshFiles* meshes, Warnings* warnings)
    : document_(document), options_(options), limits_(limits), meshes_(meshes), warnings_(warnings) {
  ReadAssets();
}

void GeomReader::ReadAssets() {
  const std::string meshdir = document_.compiler().meshdir;
  for (const tinyxml2::XMLElement* asset = document_.root().FirstChildElement("asset"); asset != nullptr;
       asset = asset->NextSiblingElement("asset")) {
    for (const tinyxml2::XMLElement* xml = asset->FirstChildElement("mesh"); xml != nullptr;
         xml = xml->NextSiblingElement("mesh")) {
      const std::string line = " (line " + std::to_string(xml->GetLineNum()) + ")";
      const Element unnamed = document_.Read(*xml, "", "mjcf: <mesh>" + line);
      MeshAsset asset_mesh;
      asset_mesh.file = unnamed.String("file");
      std::string name = unnamed.String("name");
      if (name.empty()) {  // MuJoCo names an unnamed mesh after its file, without directory or extension
        name = std::filesystem::path(asset_mesh.file).stem().string();
      }
      if (name.empty()) ThrowInvalidArgument("mjcf: <mesh>" + line + " has neither name nor file");
      asset_mesh.field = "mjcf: mesh " + Quoted(name);
      const Element named = document_.Read(*xml, "", asset_mesh.field);
      asset_mesh.scale = named.Vector("scale", Vec3::Ones());
      const std::string inertia = named.String("inertia", "legacy");
      if (inertia != "legacy" && inertia != "exact" && inertia != "convex" && inertia != "shell") {
        ThrowInvalidArgument(asset_mesh.field + " inertia: " + Quoted(inertia) +
                             " is not convex, exact, legacy or shell");
      }
      if (inertia == "convex" || inertia == "shell") {
        warnings_->Note(asset_mesh.field + " inertia", Quoted(inertia), "the mesh's exact solid instead");
      }
      asset_mesh.legacy_inertia = inertia == "legacy";
      for (int axis = 0; axis < 3; ++axis) {
        if (asset_mesh.scale[axis] == 0) ThrowInvalidArgument(asset_mesh.field + " scale: an axis is 0");
      }
      if (!asset_mesh.file.empty()) {
        const bool absolute = asset_mesh.file.front() == '/';
        const std::string joined = absolute || meshdir.empty() ? asset_mesh.file : meshdir + "/" + asset_mesh.file;
        const std::string normal = StripMeshUri(joined);
        asset_mesh.candidates = {normal, normal.substr(normal.find_last_of('/') + 1)};
      } else {
        const std::vector<double> vertices = named.Numbers("vertex", 0, 3 * 10'000'000);
        const std::vector<double> faces = named.Numbers("face", 0, 3 * 10'000'000);
        if (vertices.empty() || faces.empty() || vertices.size() % 3 != 0 || faces.size() % 3 != 0) {
          // MuJoCo takes the convex hull of vertices given without faces; graspsim does not compute hulls here.
          ThrowInvalidArgument(asset_mesh.field + ": neither a file nor vertex and face lists (multiples of 3)");
        }
        auto inline_mesh = std::make_shared<TriangleMesh>();
        for (size_t i = 0; i < vertices.size(); i += 3) {
          inline_mesh->vertices.push_back(
              Vec3(vertices[i], vertices[i + 1], vertices[i + 2]).cwiseProduct(asset_mesh.scale).cast<float>());
        }
        for (size_t i = 0; i < faces.size(); i += 3) {
          std::array<uint32_t, 3> triangle{};
          for (int k = 0; k < 3; ++k) {
            const double index = faces[i + k];
            if (index < 0 || index >= static_cast<double>(inline_mesh->vertices.size()) || index != std::floor(index)) {
              ThrowInvalidArgument(asset_mesh.field + " face: " + Format(index) + " is not a vertex index");
            }
            triangle[k] = static_cast<uint32_t>(index);
          }
          inline_mesh->triangles.push_back(triangle);
        }
        ValidateMesh(*inline_mesh, asset_mesh.field, limits_.max_triangles_per_mesh);
        asset_mesh.inline_mesh = std::move(inline_mesh);
      }
      if (!assets_.emplace(name, std::move(asset_mesh)).second) {
        ThrowInvalidArgument("mjcf: mesh " + Quoted(name) + " is defined twice");
      }
    }
  }
  std::vector<MeshFiles::Request> files;
  for (const auto& [name, asset] : assets_) {
    if (asset.inline_mesh == nullptr) files.push_back({asset.field, asset.candidates, asset.scale});
  }
  meshes_->Prefetch(files);
}

bool GeomReader::LoadMesh(const Element& geom, Geometry* geometry, const MeshAsset** found) {
  const std::string name = geom.String("mesh");
  if (name.empty()) ThrowInvalidArgument(geom.field() + " is a mesh geom without a mesh attribute");
  const auto it = assets_.find(name);
  if (it == assets_.end()) ThrowInvalidArgument(geom.field() + " mesh: " + Quoted(name) + " is not an <asset><mesh>");
  const MeshAsset& asset = it->second;
  *found = &asset;
  geometry->kind = Geometry::Kind::kMesh;
  if (asset.inline_mesh != nullptr) {
    geometry->mesh = asset.inline_mesh;
    return true;
  }
  return meshes_->Load(asset.field, asset.file, asset.candidates, asset.scale, geometry);
}

GeomResult GeomReader::Read(const Element& geom, const Pose& frame, bool with_mass) {
  GeomResult result;
  const std::string type = geom.String("type", geom.Has("mesh") ? "mesh" : "sphere");
  const bool visual = geom.Number("contype", 1) == 0 && geom.Number("conaffinity", 1) == 0;
  if (visual && !with_mass) return result;
  if (type == "hfield" || type == "sdf") {
    if (!visual) warnings_->Repair(geom.field(), type, "dropped: graspsim has no " + type + " geometry");
    return result;
  }
  std::vector<double> size = geom.Numbers("size", 0, 3);
  size.resize(3, 0.0);

  // The geom frame; fromto (capsule, cylinder, box, ellipsoid) places it at the segment's middle, z along it.
  Pose local = FramePose(geom, document_.compiler());
  if (const std::vector<double> fromto = geom.Numbers("fromto", 6, 6);
      !fromto.empty() && (type == "capsule" || type == "cylinder" || type == "box" || type == "ellipsoid")) {
    const Vec3 from(fromto[0], fromto[1], fromto[2]), to(fromto[3], fromto[4], fromto[5]);
    const double length = (to - from).norm();
    if (!(length > 1e-10)) ThrowInvalidArgument(geom.field() + " fromto: the two points coincide");
    local = {(from + to) / 2, QuatZToVector(to - from)};
    size[type == "capsule" || type == "cylinder" ? 1 : 2] = length / 2;
  }
  const Pose pose = frame * local;
  CheckFinite(geom.field() + " pos", pose.position);

  const auto positive = [&](int index, const char* what) {
    if (!(size[index] > 0)) {
      ThrowInvalidArgument(geom.field() + " size: " + what + " " + Format(size[index]) + " is not positive (size " +
                           Quoted(geom.String("size")) + ")");
    }
    return size[index];
  };
  LocalMass local_mass;
  const MeshAsset* mesh_asset = nullptr;
  std::vector<Geometry> shapes;
  const auto shape = [&](Geometry::Kind kind, const Pose& at) -> Geometry& {
    Geometry g;
    g.kind = kind;
    g.origin = at;
    shapes.push_back(g);
    return shapes.back();
  };
  if (type == "sphere") {
    const double r = positive(0, "radius");
    shape(Geometry::Kind::kSphere, pose).radius = r;
    local_mass = {4.0 / 3.0 * M_PI * r * r * r, Vec3::Constant(0.4 * r * r)};
  } else if (type == "box") {
    const Vec3 half(positive(0, "x half size"), positive(1, "y half size"), positive(2, "z half size"));
    shape(Geometry::Kind::kBox, pose).box_size = 2 * half;
    const Vec3 sq = half.cwiseProduct(half);
    local_mass = {8 * half.prod(), Vec3(sq.y() + sq.z(), sq.x() + sq.z(), sq.x() + sq.y()) / 3};
  } else if (type == "cylinder" || type == "capsule") {
    const double r = positive(0, "radius"), h = positive(1, "half length");
    Geometry& cylinder = shape(Geometry::Kind::kCylinder, pose);
    cylinder.radius = r;
    cylinder.length = 2 * h;
    const double cylinder_volume = M_PI * r * r * 2 * h;
    if (type == "cylinder") {
      local_mass = {cylinder_volume, Vec3((3 * r * r + 4 * h * h) / 12, (3 * r * r + 4 * h * h) / 12, r * r / 2)};
    } else {  // the union of the cylinder and the spheres at its ends: exact (MuJoCo's closed form)
      shape(Geometry::Kind::kSphere, pose * Pose{Vec3(0, 0, h), Quat::Identity()}).radius = r;
      shape(Geometry::Kind::kSphere, pose * Pose{Vec3(0, 0, -h), Quat::Identity()}).radius = r;
      const double sphere_volume = 4.0 / 3.0 * M_PI * r * r * r;
      const double volume = cylinder_volume + sphere_volume;
      const double fs = sphere_volume / volume, fc = cylinder_volume / volume;  // mass fractions
      const double height = 2 * h;
      const double across = fc * (3 * r * r + height * height) / 12 + fs * 0.4 * r * r +
                            fs * height * (3 * r + 2 * height) / 8;
      local_mass = {volume, Vec3(across, across, fc * r * r / 2 + fs * 0.4 * r * r)};
    }
  } else if (type == "ellipsoid") {
    const Vec3 radii(positive(0, "x radius"), positive(1, "y radius"), positive(2, "z radius"));
    shape(Geometry::Kind::kMesh, pose).mesh = EllipsoidMesh(radii);
    const Vec3 sq = radii.cwiseProduct(radii);
    local_mass = {4.0 / 3.0 * M_PI * radii.prod(), Vec3(sq.y() + sq.z(), sq.x() + sq.z(), sq.x() + sq.y()) / 5};
  } else if (type == "plane") {
    if (visual) return result;
    Vec3 box(2 * size[0], 2 * size[1], kPlaneThickness);
    for (int axis = 0; axis < 2; ++axis) {
      if (size[axis] < 0) ThrowInvalidArgument(geom.field() + " size: " + Format(size[axis]) + " is negative");
      if (size[axis] == 0) box[axis] = kInfinitePlaneEdge;
    }
    warnings_->Repair(geom.field(), "plane " + Quoted(geom.String("size", "0 0 0")),
                      "a box " + Format(box.x()) + " x " + Format(box.y()) + " m, " + Format(kPlaneThickness) +
                          " m thick below the plane");
    shape(Geometry::Kind::kBox, pose * Pose{Vec3(0, 0, -kPlaneThickness / 2), Quat::Identity()}).box_size = box;
    result.collision = std::move(shapes);
    return result;  // MuJoCo gives planes no mass
  } else if (type == "mesh") {
    Geometry& mesh = shape(Geometry::Kind::kMesh, pose);
    if (!LoadMesh(geom, &mesh, &mesh_asset)) return result;  // reported missing with the others
  } else {
    ThrowInvalidArgument(geom.field() + " type: " + Quoted(type) +
                         " is not plane, hfield, sphere, capsule, ellipsoid, cylinder, box, mesh or sdf");
  }

  if (with_mass) {
    const bool mass_given = geom.Has("mass");
    const double given_mass = geom.Number("mass", 0);
    const double density = geom.Number("density", options_.density);
    CheckNonNegative(geom.field() + " mass (kg)", given_mass);
    CheckNonNegative(geom.field() + " density (kg/m^3)", density);
    result.has_mass = true;
    if (type == "mesh") {  // MuJoCo's legacy integrals by default, the exact solid when the asset asks for it
      Inertial unit;  // at density 1, in the body frame
      if (mesh_asset->legacy_inertia) {
        const MeshVolume legacy = LegacyMeshVolume(*shapes[0].mesh);
        const Mat3 rotation = pose.orientation.toRotationMatrix();
        unit.mass = legacy.volume;
        unit.center_of_mass = pose * legacy.centroid;
        unit.inertia = rotation * legacy.inertia_per_density * rotation.transpose();
      } else {
        unit = SolidMassProperties(shapes, 1.0);
      }
      const double mass = mass_given ? given_mass : density * unit.mass;
      result.mass = unit;
      result.mass.mass = unit.mass > 0 ? mass : 0;
      result.mass.inertia = unit.mass > 0 ? Mat3(unit.inertia * (mass / unit.mass)) : Mat3::Zero();
    } else {
      result.mass = Place(pose, mass_given ? given_mass : density * local_mass.volume, local_mass.inertia_per_mass);
    }
  }
  if (!visual) result.collision = std::move(shapes);
  return result;
}

}  // namespace graspsim::import::mjcf
