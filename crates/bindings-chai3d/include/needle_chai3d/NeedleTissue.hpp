// cNeedleTissue: a tissue block in a CHAI3D world that renders needle-haptics' wrench.
//
// Every haptic tick, update(device) reads the device's position (the needle's hub) and
// rotation (its z axis from tip to hub), turns them into the library's needle pose
// relative to the block (frames.hpp), evaluates the model through the C API (the FE
// surrogate, needle_wrench; or the whole insertion through a tissue stack,
// needle_insertion_step, after useInsertion) and applies the wrench to the device with
// setForceAndTorque in the world frame (N; N*m about the hub).
#pragma once

#include <string>

#include "chai3d.h"
#include "needle.h"
#include "needle_chai3d/frames.hpp"

namespace needle_chai3d {

// One tick's result, in the library's units and frame, and what went to the device.
struct TissueTick {
  NeedlePose pose;         // the pose, in double, before rounding to the library's f32
  needle_pose_t pose_f32;  // what the library got
  needle_wrench_t wrench;  // the library's wrench (N, N*mm about the hub)
  uint8_t status;          // its status bits
  uint16_t phase;          // insertion phase code (0 with the surrogate alone)
  chai3d::cVector3d force_n, torque_nm;  // applied to the device, world frame
};

class cNeedleTissue : public chai3d::cGenericObject {
 public:
  cNeedleTissue();
  // The whole insertion through the stack `stack` at `period_s` per tick: a compiled-in
  // name, or a tissue file's path ending in ".toml" (loaded now, checked as the build
  // checks a compiled-in stack: needle_insertion_init_file). Returns false (and keeps the
  // surrogate alone) for an unknown stack, a refused file or a bad period; then `why`
  // (when given) says so, a refused file with FILE:LINE.
  bool useInsertion(const std::string &stack, float period_s = 0.001f, std::string *why = nullptr);
  // One haptic tick: reads the device, evaluates, applies the force and torque.
  TissueTick update(chai3d::cGenericHapticDevice &device);
  // The tick without a device: the hub and the rotation in world coordinates.
  TissueTick evaluate(const chai3d::cVector3d &hub_world_m, const chai3d::cMatrix3d &tool_rotation);

 private:
  double m_hubFromTipMm;
  bool m_insertion;
  needle_insertion_t m_state;
};

}  // namespace needle_chai3d
