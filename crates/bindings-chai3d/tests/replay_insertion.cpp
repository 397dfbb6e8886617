// replay_insertion: the CHAI3D object's insertion mode against the library's command
// line. Each file is `needle eval --poses <path>.csv --insertion STACK` run on a golden
// insertion path (`needle insertion-paths`: examples/common/insertion_paths.rs, the paths
// the firmware, the C API and wasm replay), one row per tick: the pose, the wrench, the
// status, the phase. A scripted cGenericHapticDevice presents each row's pose as the hub's
// position and the tool's rotation, one row per tick of CHAI3D's haptic thread (cThread,
// CTHREAD_PRIORITY_HAPTICS) paced at 1 kHz by cPrecisionClock, to a cNeedleTissue with
// useInsertion(STACK) (a fresh one per file: a path starts above the surface). Checks,
// per tick: the pose the tissue object computed has the file's f32 bits, the status and
// the phase are the file's, and the force and torque on the device equal the file's
// wrench widened to double (moments * 1e-3), compared with ==. Prints the tick period's
// distribution.
//
//   replay_insertion STACK <eval-output.csv>...
//
// STACK is a compiled-in name or a tissue file's path (.toml), loaded at run time.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "HapticReplay.hpp"
#include "chai3d.h"
#include "needle.h"
#include "needle_chai3d/NeedleTissue.hpp"

using namespace chai3d;

// The header `needle eval --poses FILE --insertion STACK` writes.
static const char *CLI_HEADER = "time_s,x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm,fx_n,fy_n,fz_n,mx_nmm,my_nmm,mz_nmm,status,phase,punctures,flags";

struct CliRow {
  int line;
  float pose[5];
  float wrench[6];
  unsigned status;
  unsigned phase;
};

// The phase code of the CLI's phase text (approach, deflecting:L, cutting:L, in-track:L).
static bool phase_code(const std::string &text, unsigned &code) {
  size_t colon = text.find(':');
  std::string kind = text.substr(0, colon);
  unsigned layer = colon == std::string::npos ? 0 : (unsigned)std::stoul(text.substr(colon + 1));
  if (kind == "approach") code = 0;
  else if (kind == "deflecting") code = 0x100 | layer;
  else if (kind == "cutting") code = 0x200 | layer;
  else if (kind == "in-track") code = 0x300 | layer;
  else return false;
  return true;
}

// The rows of one CLI output file; false (with the file:line) when it is not one.
static bool read_cli(const char *path, std::vector<CliRow> &rows) {
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line) || line != CLI_HEADER) {
    std::printf("%s:1: not the output of needle eval --insertion (header %s)\n", path, CLI_HEADER);
    return false;
  }
  for (int lineno = 2; std::getline(in, line); lineno++) {
    std::stringstream ss(line);
    std::string f[16];
    for (int i = 0; i < 16; i++)
      if (!std::getline(ss, f[i], ',')) {
        std::printf("%s:%d: column %d missing\n", path, lineno, i + 1);
        return false;
      }
    CliRow r;
    r.line = lineno;
    // strtof of the shortest text of an f32 gives that f32 back exactly
    for (int c = 0; c < 5; c++) r.pose[c] = std::strtof(f[1 + c].c_str(), nullptr);
    for (int c = 0; c < 6; c++) r.wrench[c] = std::strtof(f[6 + c].c_str(), nullptr);
    r.status = (unsigned)std::stoul(f[12], nullptr, 16);
    if (!phase_code(f[13], r.phase)) {
      std::printf("%s:%d: column phase: %s is not a phase\n", path, lineno, f[13].c_str());
      return false;
    }
    rows.push_back(r);
  }
  return !rows.empty();
}

// Replays one file; counts its mismatches (the first five printed).
static void replay(const char *stack, const char *path, const std::vector<CliRow> &rows, std::vector<double> &periods, int &pose_mismatch,
                   int &wrench_mismatch) {
  cWorld *world = new cWorld();
  needle_chai3d::cNeedleTissue *tissue = new needle_chai3d::cNeedleTissue();
  world->addChild(tissue);
  world->computeGlobalPositions(true);
  std::string why;
  if (!tissue->useInsertion(stack, 0.001f, &why)) {
    std::printf("useInsertion(%s): %s\n", stack, why.c_str());
    std::exit(2);
  }
  std::vector<ScriptedPose> script;
  for (const CliRow &r : rows) script.push_back(presenting(r.pose, needle_hub_from_tip_mm()));
  cScriptedDevice device(script);
  device.open();
  std::vector<needle_chai3d::TissueTick> ticks = replay_on_haptic_thread(device, *tissue, periods);
  for (size_t i = 0; i < rows.size(); i++) {
    const CliRow &r = rows[i];
    const needle_chai3d::TissueTick &t = ticks[i];
    float got[5] = {t.pose_f32.x_mm, t.pose_f32.z_mm, t.pose_f32.theta_x_deg, t.pose_f32.theta_z_deg, t.pose_f32.depth_mm};
    bool pose_ok = t.pose.valid;
    for (int c = 0; c < 5; c++) pose_ok = pose_ok && f32_bits(got[c]) == f32_bits(r.pose[c] == 0.0f ? 0.0f : r.pose[c]);
    if (!pose_ok && pose_mismatch++ < 5)
      std::printf("%s:%d: pose (%.9g %.9g %.9g %.9g %.9g) from the device, want (%.9g %.9g %.9g %.9g %.9g)\n", path, r.line, got[0], got[1], got[2], got[3],
                  got[4], r.pose[0], r.pose[1], r.pose[2], r.pose[3], r.pose[4]);
    cVector3d want_f, want_t;
    expected_on_device(r.wrench, want_f, want_t);
    const cVector3d &f = device.forces[i], &m = device.torques[i];
    bool ok = t.status == r.status && t.phase == r.phase && f.x() == want_f.x() && f.y() == want_f.y() && f.z() == want_f.z() && m.x() == want_t.x() &&
              m.y() == want_t.y() && m.z() == want_t.z();
    if (!ok && wrench_mismatch++ < 5)
      std::printf("%s:%d: status 0x%02x phase 0x%03x force (%.17g %.17g %.17g) torque (%.17g %.17g %.17g), want 0x%02x 0x%03x (%.17g %.17g %.17g) (%.17g %.17g %.17g)\n",
                  path, r.line, t.status, t.phase, f.x(), f.y(), f.z(), m.x(), m.y(), m.z(), r.status, r.phase, want_f.x(), want_f.y(), want_f.z(),
                  want_t.x(), want_t.y(), want_t.z());
  }
  delete world;
}

int main(int argc, char **argv) {
  if (argc < 3) {
    std::printf("usage: replay_insertion STACK <needle eval --insertion output.csv>...\n");
    return 2;
  }
  int pose_mismatch = 0, wrench_mismatch = 0;
  size_t total = 0;
  unsigned punctured = 0;
  std::vector<double> periods;
  for (int a = 2; a < argc; a++) {
    std::vector<CliRow> rows;
    if (!read_cli(argv[a], rows)) return 2;
    for (const CliRow &r : rows) punctured |= (r.phase & 0x300) == 0x300 ? 1u : 0u;
    replay(argv[1], argv[a], rows, periods, pose_mismatch, wrench_mismatch);
    total += rows.size();
  }
  std::printf("chai3d-insertion stack=%s paths=%d ticks=%zu in_track_seen=%s\n", argv[1], argc - 2, total, punctured ? "yes" : "no");
  print_periods("chai3d-insertion", periods);
  std::printf("chai3d-insertion pose_mismatches=%d wrench_mismatches=%d\n", pose_mismatch, wrench_mismatch);
  bool pass = pose_mismatch == 0 && wrench_mismatch == 0 && punctured && total > 0;
  std::printf("chai3d: %d passed, %d failed\n", pass ? 1 : 0, pass ? 0 : 1);
  return pass ? 0 : 1;
}
