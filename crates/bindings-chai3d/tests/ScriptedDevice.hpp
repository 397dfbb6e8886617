// cScriptedDevice: a cGenericHapticDevice that replays a list of hub positions and
// rotations, one per haptic tick, and records the force and torque it is given.
#pragma once

#include <atomic>
#include <utility>
#include <vector>

#include "chai3d.h"

struct ScriptedPose {
  chai3d::cVector3d hub_m;
  chai3d::cMatrix3d rotation;
};

class cScriptedDevice : public chai3d::cGenericHapticDevice {
 public:
  explicit cScriptedDevice(std::vector<ScriptedPose> script) : m_script(std::move(script)), m_tick(0) {
    m_specifications.m_modelName = "needle-haptics scripted device";
    m_specifications.m_sensedPosition = true;
    m_specifications.m_sensedRotation = true;
    m_specifications.m_actuatedPosition = true;
    m_specifications.m_actuatedRotation = true;
    m_deviceAvailable = true;
    forces.resize(m_script.size());
    torques.resize(m_script.size());
  }
  bool open() override { return (m_deviceReady = true); }
  bool close() override { m_deviceReady = false; return true; }
  bool calibrate(bool) override { return true; }
  bool getPosition(chai3d::cVector3d &p) override { p = m_script[m_tick].hub_m; return true; }
  bool getRotation(chai3d::cMatrix3d &r) override { r = m_script[m_tick].rotation; return true; }
  bool setForceAndTorqueAndGripperForce(const chai3d::cVector3d &f, const chai3d::cVector3d &t, double) override {
    forces[m_tick] = f;
    torques[m_tick] = t;
    m_prevForce = f;
    m_prevTorque = t;
    return true;
  }
  // The next scripted pose; false after the last one.
  bool advance() { return ++m_tick < m_script.size(); }
  size_t tick() const { return m_tick; }
  size_t size() const { return m_script.size(); }

  std::vector<chai3d::cVector3d> forces, torques;

 private:
  std::vector<ScriptedPose> m_script;
  size_t m_tick;
};
