// MJCF <geom> → graspsim collision geometry and MuJoCo's mass properties of the geom; <asset><mesh> lookup.
// Internal to import/ (mjcf_loader.cpp).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "import/loader_common.h"
#include "import/mjcf_document.h"

namespace graspsim::import::mjcf {

// Warnings of one import. A repair (something changed so that the file loads) is refused under
// ImportOptions::strict; a note (something MJCF describes that graspsim does not import) is always a warning.
class Warnings {
 public:
  Warnings(bool strict, std::vector<ImportWarning>* out) : strict_(strict), out_(out) {}
  void Repair(const std::string& element, const std::string& value, const std::string& action);
  void Note(const std::string& element, const std::string& value, const std::string& action);
  // One note per kind of element ("mjcf: <actuator>"), however many there are.
  void NoteOnce(const std::string& element, const std::string& value, const std::string& action);

 private:
  bool strict_;
  std::vector<ImportWarning>* out_;
  std::map<std::string, bool> noted_;
};

struct GeomResult {
  std::vector<Geometry> collision;  // empty for a visual-only or dropped geom
  bool has_mass = false;            // mass properties computed (asked for, and a solid geom)
  Inertial mass;                    // in the body frame
};

class GeomReader {
 public:
  GeomReader(const Document& document, const ImportOptions& options, const Limits& limits, MeshFiles* meshes,
             Warnings* warnings);

  // `geom` read under its class; `frame`: the geom's parent frame in the body frame (a <frame> element's pose,
  // or identity). `with_mass`: the body's inertia comes from its geoms.
  GeomResult Read(const Element& geom, const Pose& frame, bool with_mass);

 private:
  struct MeshAsset {
    std::string field;    // "mjcf: mesh 'name'"
    std::string file;     // as written
    std::vector<std::string> candidates;
    Vec3 scale = Vec3::Ones();
    std::shared_ptr<const TriangleMesh> inline_mesh;  // vertex= and face= given in the XML
    bool legacy_inertia = true;  // inertia="legacy" (MuJoCo's default) rather than "exact"
  };
  void ReadAssets();
  // Fills geometry's mesh; false when the file is missing (reported with the others). *asset: the mesh asset.
  bool LoadMesh(const Element& geom, Geometry* geometry, const MeshAsset** asset);

  const Document& document_;
  const ImportOptions& options_;
  const Limits& limits_;
  MeshFiles* meshes_;
  Warnings* warnings_;
  std::map<std::string, MeshAsset> assets_;
};

// MuJoCo's "legacy" mesh mass properties (user_mesh.cc, mjCMesh::Process, its default): the volume of the
// pyramids from the centroid to every triangle, each counted positive, so open and inconsistently wound meshes
// weigh something. Volume (m^3), centroid and inertia per unit density about it, in the mesh frame.
struct MeshVolume {
  double volume = 0;
  Vec3 centroid = Vec3::Zero();
  Mat3 inertia_per_density = Mat3::Zero();
};
MeshVolume LegacyMeshVolume(const TriangleMesh& mesh);


}  // namespace graspsim::import::mjcf
