// The pose mapping of frames.hpp.
#include "needle_chai3d/frames.hpp"

#include <cmath>

namespace needle_chai3d {

static const double DEG_PER_RAD = 180.0 / 3.14159265358979323846;
static const double ZERO_BELOW = 1e-9;

static double snap(double v) { return std::fabs(v) < ZERO_BELOW ? 0.0 : v; }

NeedlePose needle_pose(const Vec3 &hub_local_m, const Vec3 &axis_local, double hub_from_tip_mm) {
  NeedlePose p = {false, 0, 0, 0, 0, 0};
  Vec3 a = lib_from_local(axis_local);
  double n = std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
  if (!(n > 0) || !std::isfinite(n)) return p;
  a = {a.x / n, a.y / n, a.z / n};
  if (!(a.y > 0)) return p;
  Vec3 hub = lib_from_local(hub_local_m);
  hub = {hub.x * 1000.0, hub.y * 1000.0, hub.z * 1000.0};
  Vec3 tip = {hub.x - hub_from_tip_mm * a.x, hub.y - hub_from_tip_mm * a.y, hub.z - hub_from_tip_mm * a.z};
  double depth = -tip.y / a.y;
  p.valid = true;
  p.theta_x_deg = snap(std::asin(a.z) * DEG_PER_RAD);
  p.theta_z_deg = snap(std::atan2(-a.x, a.y) * DEG_PER_RAD);
  p.depth_mm = snap(depth);
  p.x_mm = snap(tip.x + depth * a.x);
  p.z_mm = snap(tip.z + depth * a.z);
  return p;
}

void device_pose(const NeedlePose &pose, double hub_from_tip_mm, Vec3 &hub_local_m, Vec3 &axis_local) {
  double tx = pose.theta_x_deg / DEG_PER_RAD, tz = pose.theta_z_deg / DEG_PER_RAD;
  Vec3 a = {-std::sin(tz) * std::cos(tx), std::cos(tz) * std::cos(tx), std::sin(tx)};
  double d = pose.depth_mm;
  Vec3 tip = {pose.x_mm - d * a.x, -d * a.y, pose.z_mm - d * a.z};
  Vec3 hub = {tip.x + hub_from_tip_mm * a.x, tip.y + hub_from_tip_mm * a.y, tip.z + hub_from_tip_mm * a.z};
  hub_local_m = local_from_lib({hub.x / 1000.0, hub.y / 1000.0, hub.z / 1000.0});
  axis_local = local_from_lib(a);
}

}  // namespace needle_chai3d
