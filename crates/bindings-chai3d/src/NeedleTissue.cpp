// cNeedleTissue (NeedleTissue.hpp).
#include "needle_chai3d/NeedleTissue.hpp"

#include <cstring>

using chai3d::cMatrix3d;
using chai3d::cVector3d;

namespace needle_chai3d {

cNeedleTissue::cNeedleTissue() : m_hubFromTipMm(needle_hub_from_tip_mm()), m_insertion(false) { std::memset(&m_state, 0, sizeof m_state); }

bool cNeedleTissue::useInsertion(const std::string &stack, float period_s, std::string *why) {
  const std::string toml = ".toml";
  bool is_file = stack.size() > toml.size() && stack.compare(stack.size() - toml.size(), toml.size(), toml) == 0;
  char message[1024] = "";
  int32_t rc = is_file ? needle_insertion_init_file(&m_state, stack.c_str(), period_s, 0.005f, message, sizeof message)
                       : needle_insertion_init(&m_state, stack.c_str(), period_s, 0.005f);
  m_insertion = rc == NEEDLE_OK;
  if (why != nullptr) {
    if (is_file || rc == NEEDLE_OK) *why = message;
    else *why = rc == NEEDLE_E_ARG ? "no tissue stack '" + stack + "' in this build" : "period_s must be finite and > 0";
  }
  return m_insertion;
}

TissueTick cNeedleTissue::update(chai3d::cGenericHapticDevice &device) {
  cVector3d hub;
  cMatrix3d rotation;
  device.getPosition(hub);
  device.getRotation(rotation);
  TissueTick t = evaluate(hub, rotation);
  device.setForceAndTorque(t.force_n, t.torque_nm);
  return t;
}

TissueTick cNeedleTissue::evaluate(const cVector3d &hub_world_m, const cMatrix3d &tool_rotation) {
  TissueTick t{};
  // World -> the block's local frame (its global position and rotation).
  cMatrix3d block_t = getGlobalRot();
  block_t.trans();
  cVector3d hub_local = block_t * (hub_world_m - getGlobalPos());
  cVector3d axis_local = block_t * tool_rotation.getCol2();
  t.pose = needle_pose({hub_local.x(), hub_local.y(), hub_local.z()}, {axis_local.x(), axis_local.y(), axis_local.z()}, m_hubFromTipMm);
  t.force_n.zero();
  t.torque_nm.zero();
  if (!t.pose.valid) return t;  // pointing away from the block: no contact
  t.pose_f32 = {(float)t.pose.x_mm, (float)t.pose.z_mm, (float)t.pose.theta_x_deg, (float)t.pose.theta_z_deg, (float)t.pose.depth_mm};
  if (m_insertion) {
    needle_insertion_result_t r;
    needle_insertion_step(&m_state, &t.pose_f32, &r);
    t.wrench = r.wrench;
    t.status = r.status;
    t.phase = r.phase;
  } else if (t.pose_f32.depth_mm >= 0.0f) {  // the surrogate alone: from the surface down
    t.status = needle_wrench(&t.pose_f32, &t.wrench);
  }
  // Library -> local -> world; forces N, moments N*mm -> N*m (about the hub = the device point).
  Vec3 f = local_from_lib({t.wrench.fx_n, t.wrench.fy_n, t.wrench.fz_n});
  Vec3 m = local_from_lib({t.wrench.mx_nmm * 1e-3, t.wrench.my_nmm * 1e-3, t.wrench.mz_nmm * 1e-3});
  t.force_n = getGlobalRot() * cVector3d(f.x, f.y, f.z);
  t.torque_nm = getGlobalRot() * cVector3d(m.x, m.y, m.z);
  return t;
}

}  // namespace needle_chai3d
