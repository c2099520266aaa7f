// The drives of the built-in robots' joints: what a joint gets when nobody installed a motor of their own
// (SceneService.SetActuators without `motor`, and the work cycle).
#pragma once

#include "world/model.h"

namespace graspsim {

// The vertical linear axis of "schunk_pg70_on_z_axis": a ball screw (10 mm lead) driven by a 48 V servo motor,
// position-controlled stiffly enough to track a moving set-point within 1 mm at 0.2 m/s. An assumed generic
// axis, not a product; the numbers are in builtin_drives.cpp.
DcMotorParams ZAxisDriveParams();

// The drive of `joint` of `robot`: the PG70 finger drive for the built-in PG70s' fingers, ZAxisDriveParams for
// the z axis of "schunk_pg70_on_z_axis", DcMotorParams() otherwise.
DcMotorParams BuiltinDrive(const RobotSpec& robot, const JointSpec& joint);

}  // namespace graspsim
