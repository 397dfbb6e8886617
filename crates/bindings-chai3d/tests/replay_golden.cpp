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

#include "ScriptedDevice.hpp"
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

static uint32_t bits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}

static bool presentable(const GoldenRow &r) {
  for (int c = 0; c < 5; c++) {
    float v = r.pose[c];
    if (!std::isfinite(v) || (v != 0.0f && std::fabs(v) < 1e-6f)) return false;
  }
  return std::fabs(r.pose[2]) <= 80 && std::fabs(r.pose[3]) <= 80 && std::fabs(r.pose[0]) <= 1000 && std::fabs(r.pose[1]) <= 1000 &&
         r.pose[4] >= 0 && r.pose[4] <= 1000 && !std::signbit(r.pose[4]);
}


static cScriptedDevice *g_device;
static needle_chai3d::cNeedleTissue *g_tissue;
static std::vector<needle_chai3d::TissueTick> g_ticks;
static std::vector<double> g_period_s;
static std::atomic<bool> g_done(false);

static void haptics_loop(void *) {
  cPrecisionClock clock;
  clock.start(true);
  double next = 0.0, last = -1.0;
  do {
    while (clock.getCurrentTimeSeconds() < next) {
    }
    double now = clock.getCurrentTimeSeconds();
    if (last >= 0) g_period_s.push_back(now - last);
    last = now;
    next += 0.001;  // 1 kHz
    g_ticks[g_device->tick()] = g_tissue->update(*g_device);
  } while (g_device->advance());
  g_done = true;
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
  g_tissue = new needle_chai3d::cNeedleTissue();
  world->addChild(g_tissue);
  world->computeGlobalPositions(true);
  double hub_from_tip_mm = needle_hub_from_tip_mm();

  std::vector<ScriptedPose> script;
  for (const GoldenRow &r : rows) {
    NeedlePose p = {true, r.pose[0], r.pose[1], r.pose[2], r.pose[3], r.pose[4]};
    Vec3 hub, axis;
    needle_chai3d::device_pose(p, hub_from_tip_mm, hub, axis);
    // A rotation whose z column is the tip-to-hub axis.
    cVector3d z(axis.x, axis.y, axis.z), x = cVector3d(1, 0, 0) - cDot(cVector3d(1, 0, 0), z) * z;
    x.normalize();
    cMatrix3d rot;
    rot.setCol(x, cCross(z, x), z);
    script.push_back({cVector3d(hub.x, hub.y, hub.z), rot});
  }
  g_device = new cScriptedDevice(script);
  g_device->open();
  g_ticks.resize(script.size());
  g_period_s.reserve(script.size());

  cThread *thread = new cThread();
  thread->start(haptics_loop, CTHREAD_PRIORITY_HAPTICS, nullptr);
  while (!g_done) cSleepMs(10);

  int pose_mismatch = 0, wrench_mismatch = 0;
  for (size_t i = 0; i < rows.size(); i++) {
    const GoldenRow &r = rows[i];
    const needle_chai3d::TissueTick &t = g_ticks[i];
    float got[5] = {t.pose_f32.x_mm, t.pose_f32.z_mm, t.pose_f32.theta_x_deg, t.pose_f32.theta_z_deg, t.pose_f32.depth_mm};
    bool pose_ok = t.pose.valid;
    for (int c = 0; c < 5; c++) pose_ok = pose_ok && bits(got[c]) == bits(r.pose[c] == 0.0f ? 0.0f : r.pose[c]);
    if (!pose_ok) {
      if (pose_mismatch++ < 5)
        std::printf("golden line %d: pose (%.9g %.9g %.9g %.9g %.9g) from the device, want (%.9g %.9g %.9g %.9g %.9g)\n", r.line, got[0], got[1], got[2],
                    got[3], got[4], r.pose[0], r.pose[1], r.pose[2], r.pose[3], r.pose[4]);
      continue;
    }
    // Expected on the device: the golden wrench widened to double, in the world frame
    // (x_world = x_lib, y_world = -z_lib, z_world = y_lib), moments in N*m.
    const float *w = r.wrench;
    cVector3d want_f((double)w[0], -(double)w[2], (double)w[1]);
    cVector3d want_t((double)w[3] * 1e-3, -((double)w[5] * 1e-3), (double)w[4] * 1e-3);
    const cVector3d &f = g_device->forces[i], &m = g_device->torques[i];
    bool ok = t.status == r.status && f.x() == want_f.x() && f.y() == want_f.y() && f.z() == want_f.z() && m.x() == want_t.x() && m.y() == want_t.y() &&
              m.z() == want_t.z();
    if (!ok && wrench_mismatch++ < 5)
      std::printf("golden line %d: status 0x%02x force (%.17g %.17g %.17g) torque (%.17g %.17g %.17g), want 0x%02x (%.17g %.17g %.17g) (%.17g %.17g %.17g)\n",
                  r.line, t.status, f.x(), f.y(), f.z(), m.x(), m.y(), m.z(), r.status, want_f.x(), want_f.y(), want_f.z(), want_t.x(), want_t.y(),
                  want_t.z());
  }
  std::vector<double> p = g_period_s;
  std::sort(p.begin(), p.end());
  auto q = [&](double f) { return p.empty() ? 0.0 : p[std::min(p.size() - 1, (size_t)(f * (p.size() - 1)))] * 1e6; };
  double mean = 0;
  for (double v : p) mean += v;
  mean = p.empty() ? 0 : mean / p.size() * 1e6;
  size_t late = std::count_if(p.begin(), p.end(), [](double v) { return v > 0.0011; });
  std::printf("chai3d-replay golden_rows=%d replayed=%zu trajectories=%d not_presentable=%zu\n", total, rows.size(), trajectories, (size_t)total - rows.size());
  std::printf("chai3d-replay tick_period_us min=%.1f p1=%.1f p50=%.1f mean=%.1f p99=%.1f max=%.1f over_1100us=%zu of %zu\n", q(0), q(0.01), q(0.5), mean, q(0.99),
              q(1.0), late, p.size());
  std::printf("chai3d-replay pose_mismatches=%d wrench_mismatches=%d\n", pose_mismatch, wrench_mismatch);
  bool pass = pose_mismatch == 0 && wrench_mismatch == 0 && rows.size() > 4000;
  std::printf("chai3d: %d passed, %d failed\n", pass ? 1 : 0, pass ? 0 : 1);
  thread->stop();
  return pass ? 0 : 1;
}
