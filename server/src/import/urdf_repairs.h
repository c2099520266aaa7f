// What the community's URDF files need before urdfdom reads them, done on the XML document (TinyXML) so urdfdom
// sees a file it accepts: names graspsim refuses made valid (with every reference to them), collision geometry
// urdfdom does not know taken out (a plane becomes a thin box, a capsule a cylinder and two spheres, anything
// else is dropped), and ball and floating joints marked for graspsim's joint chains. Each repair is a warning.
// Internal to import/.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <tinyxml.h>

#include "import/robot_import.h"

namespace graspsim::import {

struct UrdfRepairs {
  // Collision geometry to add to a link after urdfdom's, in the link frame.
  std::map<std::string, std::vector<Geometry>> extra_collision;
  // Joints urdfdom is told are fixed and that become chains: "ball" (spherical) or "free" (floating).
  std::map<std::string, std::string> chain_joints;
  // The document differs from the text: urdfdom must read it printed anew.
  bool document_changed = false;
};

// Repairs *robot in place, appending warnings. In strict mode it changes nothing (the caller refuses instead).
UrdfRepairs RepairUrdfDocument(TiXmlElement* robot, std::vector<ImportWarning>* warnings);

}  // namespace graspsim::import
