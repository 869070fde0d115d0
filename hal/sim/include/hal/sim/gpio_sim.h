// GPIO on the sim board: e-stop and bumper inputs (from SimWorld), status LED output.
#pragma once

#include <cstdint>

#include "hal/digital_io.h"
#include "hal/sim/sim_world.h"

namespace boticelli::hal::sim {

// The e-stop button; press it with SimWorld::set_estop_pressed() or schedule_estop().
class EstopInputSim final : public DigitalIn {
 public:
  explicit EstopInputSim(SimWorld& world) : world_(world) {}
  bool read() override { return world_.estop_pressed(); }
  bool activated_since_last_poll() override {
    const bool edge = world_.estop_presses() != seen_;
    seen_ = world_.estop_presses();
    return edge;
  }

 private:
  SimWorld& world_;
  std::uint32_t seen_ = 0;
};

// The bumper ring: active while the robot's cylinder touches an obstacle.
class BumperInputSim final : public DigitalIn {
 public:
  explicit BumperInputSim(SimWorld& world) : world_(world) {}
  bool read() override { return world_.in_contact(); }
  bool activated_since_last_poll() override {
    const bool edge = world_.contacts() != seen_;
    seen_ = world_.contacts();
    return edge;
  }

 private:
  SimWorld& world_;
  std::uint32_t seen_ = 0;
};

class LedOutputSim final : public DigitalOut {
 public:
  explicit LedOutputSim(SimWorld& world) : world_(world) {}
  void write(bool active) override { world_.set_led(active); }

 private:
  SimWorld& world_;
};

}  // namespace boticelli::hal::sim
