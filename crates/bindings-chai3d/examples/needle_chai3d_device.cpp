// needle_chai3d_device: the tissue block under a real haptic device (the first one
// CHAI3D's cHapticDeviceHandler finds: Phantom/Touch, Force Dimension, Novint, ...), in a
// window. The block's top surface is 8 cm below the device's origin; hold the stylus
// upright (its z axis from the needle's tip to the hub) and lower it. The haptic loop
// runs at 1 kHz on CHAI3D's haptic thread; the window (GLFW, OpenGL) draws the block, the
// needle and the depth and force. Esc or closing the window ends it. Built only when
// CMake finds GLFW and OpenGL (the display libraries); the headless parts of the binding
// build without them.
//
//   needle_chai3d_device [stack]      e.g. liver: the whole insertion; none: the surrogate
#include <cstdio>
#include <string>

#include "chai3d.h"
#include "needle_chai3d/NeedleTissue.hpp"
// after chai3d.h: GLEW's header must come before any other OpenGL header
#include <GLFW/glfw3.h>

using namespace chai3d;

static const double SURFACE_Z_M = -0.08;  // the block's top surface, world metres
static cGenericHapticDevicePtr g_device;
static needle_chai3d::cNeedleTissue *g_tissue;
static volatile bool g_stop = false;
static needle_chai3d::TissueTick g_last;
static cVector3d g_hub_m;
static cMatrix3d g_rotation;

static void haptics(void) {
  cPrecisionClock clock;
  clock.start(true);
  double next = 0;
  while (!g_stop) {
    while (clock.getCurrentTimeSeconds() < next) {
    }
    next += 0.001;
    g_last = g_tissue->update(*g_device);
    g_device->getPosition(g_hub_m);
    g_device->getRotation(g_rotation);
  }
  g_device->setForceAndTorque(cVector3d(0, 0, 0), cVector3d(0, 0, 0));
}

static void on_key(GLFWwindow *window, int key, int, int action, int) {
  if (key == GLFW_KEY_ESCAPE && action == GLFW_PRESS) glfwSetWindowShouldClose(window, GLFW_TRUE);
}

int main(int argc, char **argv) {
  cHapticDeviceHandler handler;
  if (handler.getNumDevices() == 0 || !handler.getDevice(g_device, 0) || !g_device->open()) {
    std::printf("no haptic device found\n");
    return 1;
  }
  g_device->calibrate();
  if (!glfwInit()) {
    std::printf("no display: GLFW could not start\n");
    return 1;
  }
  GLFWwindow *window = glfwCreateWindow(800, 600, "needle-haptics: CHAI3D", nullptr, nullptr);
  if (!window) {
    std::printf("no display: GLFW could not open a window\n");
    glfwTerminate();
    return 1;
  }
  glfwMakeContextCurrent(window);
  glfwSetKeyCallback(window, on_key);
  glfwSwapInterval(1);
#ifdef GLEW_VERSION
  glewInit();
#endif

  cWorld *world = new cWorld();
  world->m_backgroundColor.setWhite();
  cCamera *camera = new cCamera(world);
  world->addChild(camera);
  camera->set(cVector3d(0.25, 0.0, 0.0), cVector3d(0.0, 0.0, SURFACE_Z_M), cVector3d(0.0, 0.0, 1.0));
  camera->setClippingPlanes(0.01, 10.0);
  cDirectionalLight *light = new cDirectionalLight(world);
  world->addChild(light);
  light->setEnabled(true);
  light->setDir(-1.0, 0.0, -1.0);

  g_tissue = new needle_chai3d::cNeedleTissue();
  g_tissue->setLocalPos(0.0, 0.0, SURFACE_Z_M);
  world->addChild(g_tissue);
  // The block drawn: 50 x 50 mm, 30 mm deep, below the surface (docs/architecture.md, section 3).
  cShapeBox *block = new cShapeBox(0.05, 0.05, 0.03);
  block->setLocalPos(0.0, 0.0, -0.015);
  block->m_material->setPinkLight();
  block->setUseTransparency(true);
  block->setTransparencyLevel(0.5f);
  g_tissue->addChild(block);
  cShapeLine *needle = new cShapeLine(cVector3d(0, 0, 0), cVector3d(0, 0, 0));
  needle->setLineWidth(3.0);
  world->addChild(needle);
  cLabel *label = new cLabel(NEW_CFONT_CALIBRI_20());
  label->m_fontColor.setBlack();
  camera->m_frontLayer->addChild(label);
  world->computeGlobalPositions(true);

  if (argc > 1 && std::string(argv[1]) != "none" && !g_tissue->useInsertion(argv[1])) {
    std::printf("no tissue stack %s in this build\n", argv[1]);
    return 1;
  }
  cThread thread;
  thread.start(haptics, CTHREAD_PRIORITY_HAPTICS);
  char text[160];
  while (!glfwWindowShouldClose(window)) {
    int width, height;
    glfwGetFramebufferSize(window, &width, &height);
    cVector3d hub = g_hub_m, axis = g_rotation.getCol2();
    needle->m_pointA = hub;
    needle->m_pointB = hub - (needle_hub_from_tip_mm() * 1e-3) * axis;  // the tip
    needle_chai3d::TissueTick t = g_last;
    std::snprintf(text, sizeof text, "depth %.2f mm   fy %.4f N   status 0x%02x   phase 0x%03x", t.pose.depth_mm, t.wrench.fy_n, t.status, t.phase);
    label->setText(text);
    label->setLocalPos(10, 10);
    world->updateShadowMaps(false, false);
    camera->renderView(width, height);
    glfwSwapBuffers(window);
    glfwPollEvents();
  }
  g_stop = true;
  cSleepMs(10);
  g_device->close();
  glfwDestroyWindow(window);
  glfwTerminate();
  return 0;
}
