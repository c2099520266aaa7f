// Robot files as the community writes them → RobotDescription: URDF (urdfdom), MJCF (MuJoCo's XML), SDF
// (libsdformat). Each loader validates what it reads and throws Error(kInvalidArgument) naming the file's element
// and value; it never returns half a model. Where PyBullet or MuJoCo would repair a file (a zero-mass frame link,
// an inertia tensor that is not physical, a link with geometry and no inertial), the loader repairs it the same way
// and says so in a warning, unless the options ask for strict loading (docs/import.md).
#pragma once

#include <string>
#include <vector>

#include "core/limits.h"
#include "world/loaders.h"
#include "world/model.h"

namespace graspsim {

// Where a link's mass properties come from (MuJoCo's <compiler inertiafromgeom>, PyBullet's
// URDF_USE_INERTIA_FROM_FILE).
enum class InertiaSource {
  kAuto,          // the file's where they are physical; else from the collision geometry (with a warning)
  kFromFile,      // the file's; a link whose mass or inertia is not physical is refused
  kFromGeometry,  // every link with collision geometry: the solid geometry at `density`
};

struct ImportOptions {
  InertiaSource inertia = InertiaSource::kAuto;
  double density = 1000;  // kg/m^3, solid geometry for inertia from geometry (water, as MuJoCo's default)
  bool strict = false;    // refuse anything that would need a repair (notes on elements not imported remain)
  std::string model_name; // SDF <world> with several models: the one to load (empty = the only or first one)
};

// One repair made so that a file loads, for the client to see.
struct ImportWarning {
  std::string element;  // what was repaired, as the file names it: "urdf: link 'panda_link8' inertial mass (kg)"
  std::string value;    // the value found: "0"
  std::string action;   // what was done: "massless frame, merged into its parent link 'panda_link7'"
};

struct ImportedRobot {
  RobotDescription description;
  std::vector<ImportWarning> warnings;
};

// Each throws Error(kInvalidArgument) naming the element and value; files the text names and that `files` does not
// hold are listed all at once in one error ("... were not uploaded: 'a.stl', 'b.stl'").
ImportedRobot ImportUrdf(const std::string& text, const FileLookup& files, const ImportOptions& options,
                         const Limits& limits);
ImportedRobot ImportMjcf(const std::string& text, const FileLookup& files, const ImportOptions& options,
                         const Limits& limits);
ImportedRobot ImportSdf(const std::string& text, const FileLookup& files, const ImportOptions& options,
                        const Limits& limits);

// The mass properties of a moving object given by geometry without an inertial (AddObject): the solid geometry at
// options.density, with a warning. Error(kInvalidArgument) naming `field` when the options say from_file or strict
// (an inertial is then required, as in API v1) or the geometry encloses no volume.
Inertial ObjectInertialFromGeometry(const std::string& field, const std::vector<Geometry>& geometry,
                                    const ImportOptions& options, std::vector<ImportWarning>* warnings);

// Strict URDF loading (no repairs), for the built-in models and graspsim's own files: links with collision geometry
// need an <inertial> with positive mass and a positive definite inertia; a link without inertial or geometry is a
// massless frame when fixed to its parent (or the root), else 1 g. Joints: revolute, continuous, prismatic, fixed;
// mimic joints; graspsim's <tactile_array> elements.
RobotDescription LoadUrdf(const std::string& urdf_text, const FileLookup& files, const Limits& limits);

}  // namespace graspsim
