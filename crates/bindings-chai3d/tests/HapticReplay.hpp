// What the headless replays share: a scripted device's poses from the library's poses
// (the inverse mapping of frames.hpp), the run on CHAI3D's haptic thread at 1 kHz, and
// the tick period's distribution.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <vector>

#include "ScriptedDevice.hpp"
#include "chai3d.h"
#include "needle_chai3d/NeedleTissue.hpp"

// The scripted device's pose that presents the library pose p (x_mm, z_mm, theta_x_deg,
// theta_z_deg, depth_mm) to a tissue object whose local frame is the world's: the hub in
// metres and a rotation whose z column is the tip-to-hub axis.
inline ScriptedPose presenting(const float p[5], double hub_from_tip_mm) {
  needle_chai3d::NeedlePose pose = {true, p[0], p[1], p[2], p[3], p[4]};
  needle_chai3d::Vec3 hub, axis;
  needle_chai3d::device_pose(pose, hub_from_tip_mm, hub, axis);
  chai3d::cVector3d z(axis.x, axis.y, axis.z), x = chai3d::cVector3d(1, 0, 0) - chai3d::cDot(chai3d::cVector3d(1, 0, 0), z) * z;
  x.normalize();
  chai3d::cMatrix3d rot;
  rot.setCol(x, chai3d::cCross(z, x), z);
  return ScriptedPose{chai3d::cVector3d(hub.x, hub.y, hub.z), rot};
}

// The force and torque a device must receive for the library's wrench w (N; N*mm about
// the hub), widened to double, in the world frame (x_world = x_lib, y_world = -z_lib,
// z_world = y_lib), moments in N*m.
inline void expected_on_device(const float w[6], chai3d::cVector3d &force_n, chai3d::cVector3d &torque_nm) {
  force_n.set((double)w[0], -(double)w[2], (double)w[1]);
  torque_nm.set((double)w[3] * 1e-3, -((double)w[5] * 1e-3), (double)w[4] * 1e-3);
}

inline uint32_t f32_bits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}

namespace haptic_replay {
struct Run {
  cScriptedDevice *device;
  needle_chai3d::cNeedleTissue *tissue;
  std::vector<needle_chai3d::TissueTick> ticks;
  std::vector<double> period_s;
  std::atomic<bool> done{false};
};

inline void loop(void *arg) {
  Run &r = *static_cast<Run *>(arg);
  chai3d::cPrecisionClock clock;
  clock.start(true);
  double next = 0.0, last = -1.0;
  do {
    while (clock.getCurrentTimeSeconds() < next) {
    }
    double now = clock.getCurrentTimeSeconds();
    if (last >= 0) r.period_s.push_back(now - last);
    last = now;
    next += 0.001;  // 1 kHz, an absolute schedule
    r.ticks[r.device->tick()] = r.tissue->update(*r.device);
  } while (r.device->advance());
  r.done = true;
}
}  // namespace haptic_replay

// Every scripted pose of `device`, one per tick of a cThread at CTHREAD_PRIORITY_HAPTICS
// paced by cPrecisionClock at 1 kHz, through tissue.update(device); the tissue's ticks
// in order, and the periods between ticks appended to `period_s`.
inline std::vector<needle_chai3d::TissueTick> replay_on_haptic_thread(cScriptedDevice &device, needle_chai3d::cNeedleTissue &tissue,
                                                                     std::vector<double> &period_s) {
  haptic_replay::Run run;
  run.device = &device;
  run.tissue = &tissue;
  run.ticks.resize(device.size());
  run.period_s.reserve(device.size());
  chai3d::cThread thread;
  thread.start(haptic_replay::loop, chai3d::CTHREAD_PRIORITY_HAPTICS, &run);
  while (!run.done) chai3d::cSleepMs(10);
  thread.stop();
  period_s.insert(period_s.end(), run.period_s.begin(), run.period_s.end());
  return run.ticks;
}

// Prints `<tag> tick_period_us min= p1= p50= mean= p99= max= over_1100us=N of M`.
inline void print_periods(const char *tag, std::vector<double> p) {
  std::sort(p.begin(), p.end());
  auto q = [&](double f) { return p.empty() ? 0.0 : p[std::min(p.size() - 1, (size_t)(f * (p.size() - 1)))] * 1e6; };
  double mean = 0;
  for (double v : p) mean += v;
  mean = p.empty() ? 0 : mean / p.size() * 1e6;
  size_t late = std::count_if(p.begin(), p.end(), [](double v) { return v > 0.0011; });
  std::printf("%s tick_period_us min=%.1f p1=%.1f p50=%.1f mean=%.1f p99=%.1f max=%.1f over_1100us=%zu of %zu\n", tag, q(0), q(0.01), q(0.5), mean,
              q(0.99), q(1.0), late, p.size());
}
