// replay_golden: the headless CHAI3D test. The golden vectors of the fitter
// (golden-f32.csv) grouped into insertion trajectories (consecutive rows at one lateral
// pose, the depth stepping down), presented by a scripted cGenericHapticDevice as the
// hub's position and the tool's rotation, one row per tick of CHAI3D's haptic thread
// (cThread, CTHREAD_PRIORITY_HAPTICS) paced at 1 kHz by cPrecisionClock; a cNeedleTissue
// in a cWorld turns each into the library's pose and applies the wrench. Checks, per row:
// the pose the tissue object computed is the golden pose (f32 bits), the status is the
// golden status, the force on the device is the golden force widened to double (N, world
// frame = the block's local frame rotated into the library's), the torque the golden
// moment times 1e-3 (N*mm -> N*m). Prints the tick period's distribution.
//
//   replay_golden <golden-f32.csv>
//
// Rows a device cannot present are not replayed (counted and printed): not finite, a
// tilt beyond 80 degrees, |x|, |z| or depth beyond 1 m, a depth below 0 (above the
// surface the surrogate alone gives no contact), a non-zero value below 1e-6 (mm or
// degrees: beneath any device's resolution; the tissue object takes below 1e-9 as 0).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "HapticReplay.hpp"
#include "chai3d.h"
#include "needle.h"
#include "needle_chai3d/NeedleTissue.hpp"

using namespace chai3d;
using needle_chai3d::NeedlePose;
using needle_chai3d::Vec3;

struct GoldenRow {
  int line;
  float pose[5];
  unsigned status;
  float wrench[6];
};

static float f32(unsigned long bits) {
  uint32_t b = (uint32_t)bits;
  float f;
  std::memcpy(&f, &b, 4);
  return f;
}

static bool presentable(const GoldenRow &r) {
  for (int c = 0; c < 5; c++) {
    float v = r.pose[c];
    if (!std::isfinite(v) || (v != 0.0f && std::fabs(v) < 1e-6f)) return false;
  }
  return std::fabs(r.pose[2]) <= 80 && std::fabs(r.pose[3]) <= 80 && std::fabs(r.pose[0]) <= 1000 && std::fabs(r.pose[1]) <= 1000 &&
         r.pose[4] >= 0 && r.pose[4] <= 1000 && !std::signbit(r.pose[4]);
}


int main(int argc, char **argv) {
  if (argc != 2) {
    std::printf("usage: replay_golden <golden-f32.csv>\n");
    return 2;
  }
  std::ifstream in(argv[1]);
  std::string line;
  if (!std::getline(in, line)) {
    std::printf("cannot read %s\n", argv[1]);
    return 2;
  }
  std::vector<GoldenRow> rows;
  int lineno = 1, total = 0;
  while (std::getline(in, line)) {
    lineno++;
    total++;
    GoldenRow r;
    r.line = lineno;
    std::stringstream ss(line);
    std::string field;
    unsigned long v[12];
    for (int i = 0; i < 12; i++) {
      if (!std::getline(ss, field, ',')) {
        std::printf("line %d: malformed\n", lineno);
        return 2;
      }
      v[i] = std::stoul(field, nullptr, 16);
    }
    for (int c = 0; c < 5; c++) r.pose[c] = f32(v[c]);
    r.status = (unsigned)v[5];
    for (int c = 0; c < 6; c++) r.wrench[c] = f32(v[6 + c]);
    if (presentable(r)) rows.push_back(r);
  }
  // Trajectories: consecutive rows at the same lateral pose.
  int trajectories = 0;
  for (size_t i = 0; i < rows.size(); i++)
    if (i == 0 || std::memcmp(rows[i].pose, rows[i - 1].pose, 4 * sizeof(float)) != 0) trajectories++;

  // The world: a tissue block at the origin, its local frame the world's.
  cWorld *world = new cWorld();
  needle_chai3d::cNeedleTissue *tissue = new needle_chai3d::cNeedleTissue();
  world->addChild(tissue);
  world->computeGlobalPositions(true);
  std::vector<ScriptedPose> script;
  for (const GoldenRow &r : rows) script.push_back(presenting(r.pose, needle_hub_from_tip_mm()));
  cScriptedDevice device(script);
  device.open();
  std::vector<double> periods;
  std::vector<needle_chai3d::TissueTick> ticks = replay_on_haptic_thread(device, *tissue, periods);

  int pose_mismatch = 0, wrench_mismatch = 0;
  for (size_t i = 0; i < rows.size(); i++) {
    const GoldenRow &r = rows[i];
    const needle_chai3d::TissueTick &t = ticks[i];
    float got[5] = {t.pose_f32.x_mm, t.pose_f32.z_mm, t.pose_f32.theta_x_deg, t.pose_f32.theta_z_deg, t.pose_f32.depth_mm};
    bool pose_ok = t.pose.valid;
    for (int c = 0; c < 5; c++) pose_ok = pose_ok && f32_bits(got[c]) == f32_bits(r.pose[c] == 0.0f ? 0.0f : r.pose[c]);
    if (!pose_ok) {
      if (pose_mismatch++ < 5)
        std::printf("golden line %d: pose (%.9g %.9g %.9g %.9g %.9g) from the device, want (%.9g %.9g %.9g %.9g %.9g)\n", r.line, got[0], got[1], got[2],
                    got[3], got[4], r.pose[0], r.pose[1], r.pose[2], r.pose[3], r.pose[4]);
      continue;
    }
    cVector3d want_f, want_t;
    expected_on_device(r.wrench, want_f, want_t);
    const cVector3d &f = device.forces[i], &m = device.torques[i];
    bool ok = t.status == r.status && f.x() == want_f.x() && f.y() == want_f.y() && f.z() == want_f.z() && m.x() == want_t.x() && m.y() == want_t.y() &&
              m.z() == want_t.z();
    if (!ok && wrench_mismatch++ < 5)
      std::printf("golden line %d: status 0x%02x force (%.17g %.17g %.17g) torque (%.17g %.17g %.17g), want 0x%02x (%.17g %.17g %.17g) (%.17g %.17g %.17g)\n",
                  r.line, t.status, f.x(), f.y(), f.z(), m.x(), m.y(), m.z(), r.status, want_f.x(), want_f.y(), want_f.z(), want_t.x(), want_t.y(),
                  want_t.z());
  }
  std::printf("chai3d-replay golden_rows=%d replayed=%zu trajectories=%d not_presentable=%zu\n", total, rows.size(), trajectories, (size_t)total - rows.size());
  print_periods("chai3d-replay", periods);
  std::printf("chai3d-replay pose_mismatches=%d wrench_mismatches=%d\n", pose_mismatch, wrench_mismatch);
  bool pass = pose_mismatch == 0 && wrench_mismatch == 0 && rows.size() > 4000;
  std::printf("chai3d: %d passed, %d failed\n", pass ? 1 : 0, pass ? 0 : 1);
  return pass ? 0 : 1;
}
