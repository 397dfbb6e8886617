// needle_chai3d_device: the tissue block under a real haptic device (the first one
// CHAI3D's cHapticDeviceHandler finds: Phantom/Touch, Force Dimension, Novint, ...).
// The block's top surface is 8 cm below the device's origin; hold the stylus upright
// (its z axis from the needle's tip to the hub) and lower it. Console only, 1 kHz on
// CHAI3D's haptic thread; prints the depth and Fy twice a second; Ctrl-C ends it.
//
//   needle_chai3d_device [stack]      e.g. liver: the whole insertion; none: the surrogate
#include <csignal>
#include <cstdio>
#include <string>

#include "chai3d.h"
#include "needle_chai3d/NeedleTissue.hpp"

using namespace chai3d;

static cGenericHapticDevicePtr g_device;
static needle_chai3d::cNeedleTissue *g_tissue;
static volatile std::sig_atomic_t g_stop = 0;
static needle_chai3d::TissueTick g_last;

static void haptics(void) {
  cPrecisionClock clock;
  clock.start(true);
  double next = 0;
  while (!g_stop) {
    while (clock.getCurrentTimeSeconds() < next) {
    }
    next += 0.001;
    g_last = g_tissue->update(*g_device);
  }
  g_device->setForceAndTorque(cVector3d(0, 0, 0), cVector3d(0, 0, 0));
}

int main(int argc, char **argv) {
  std::signal(SIGINT, [](int) { g_stop = 1; });
  cHapticDeviceHandler handler;
  if (handler.getNumDevices() == 0 || !handler.getDevice(g_device, 0) || !g_device->open()) {
    std::printf("no haptic device found\n");
    return 1;
  }
  g_device->calibrate();
  cWorld *world = new cWorld();
  g_tissue = new needle_chai3d::cNeedleTissue();
  g_tissue->setLocalPos(0.0, 0.0, -0.08);
  world->addChild(g_tissue);
  world->computeGlobalPositions(true);
  if (argc > 1 && std::string(argv[1]) != "none" && !g_tissue->useInsertion(argv[1])) {
    std::printf("no tissue stack %s in this build\n", argv[1]);
    return 1;
  }
  cThread thread;
  thread.start(haptics, CTHREAD_PRIORITY_HAPTICS);
  while (!g_stop) {
    cSleepMs(500);
    std::printf("depth %.2f mm  fy %.4f N  status 0x%02x\n", g_last.pose.depth_mm, g_last.wrench.fy_n, g_last.status);
  }
  cSleepMs(10);
  g_device->close();
  return 0;
}
