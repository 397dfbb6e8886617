// The frames between CHAI3D and needle-haptics (drawing and units: ../../README.md).
//
// CHAI3D: metres, N, N*m; the tissue object's local frame has its origin at the centre
// of the block's top surface and z along the surface's outward normal (up).
// The library (docs/architecture.md, section 3): mm and degrees; origin at the centre of
// the top surface, y up; x_lib = x_local, y_lib = z_local, z_lib = -y_local (a proper
// rotation, so moments transform like forces). The tool: the device's position is the
// needle's hub (where the hand holds it and where the library's moments are taken), the
// tool's z axis points from the tip to the hub (identity rotation: a vertical needle
// pointing down).
#pragma once

namespace needle_chai3d {

struct Vec3 {
  double x, y, z;
};

// Library coordinates of a vector given in the tissue object's local frame.
inline Vec3 lib_from_local(const Vec3 &v) { return {v.x, v.z, -v.y}; }
// The tissue object's local coordinates of a vector given in library coordinates.
inline Vec3 local_from_lib(const Vec3 &v) { return {v.x, -v.z, v.y}; }

// The needle pose of the library (its five inputs, still in double), or none when the
// needle does not point into the block (its tip-to-hub axis not upward).
struct NeedlePose {
  bool valid;
  double x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm;
};

// hub_local_m: the hub in the tissue object's local frame, metres; axis_local: the unit
// tip-to-hub axis in that frame; hub_from_tip_mm: needle_hub_from_tip_mm().
// The pose: theta_x = asin(a_z), theta_z = atan2(-a_x, a_y) (src/orientation.rs), the tip
// at hub - L a, the depth the tip's distance below the surface plane along the axis,
// the entry point where the axis crosses the surface. Values below 1e-9 (mm or degrees:
// far below any device's resolution) are taken as exact zeros, so that a centred or
// vertical needle is exactly centred or vertical.
NeedlePose needle_pose(const Vec3 &hub_local_m, const Vec3 &axis_local, double hub_from_tip_mm);

// The device pose that presents `pose` (the inverse of needle_pose, for scripted
// devices and tests): the hub in local metres and the unit tip-to-hub axis.
void device_pose(const NeedlePose &pose, double hub_from_tip_mm, Vec3 &hub_local_m, Vec3 &axis_local);

}  // namespace needle_chai3d
