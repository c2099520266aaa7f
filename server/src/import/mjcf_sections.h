// MJCF's sections after the worldbody (<equality>, <actuator>, the ones graspsim does not import) and the
// compiler's mass settings. Internal to import/ (mjcf_loader.cpp).
#pragma once

#include <map>
#include <string>

#include "import/loader_common.h"
#include "import/mjcf_document.h"
#include "import/mjcf_geometry.h"

namespace graspsim::import::mjcf {

// <equality><joint> as mimic joints (linear polycoef; others dropped with a warning), actuator force ranges (and a
// motor's gear × ctrlrange) as effort limits of the joints without one, a note per kind of section not imported.
// `single_joints`: the MJCF name of each hinge and slide joint → its joint id in `description`.
void Sections(const Document& document, const std::map<std::string, std::string>& single_joints,
              RobotDescription* description, Warnings* warnings);

// <compiler boundmass boundinertia settotalmass>, as MuJoCo's compiler applies them to the bodies' inertials
// (chain links and the world excepted).
void CompilerMasses(const Compiler& compiler, FileInertials* inertials);

}  // namespace graspsim::import::mjcf
