// GPIO on the sim board: e-stop and bumper inputs (from SimWorld), status LED output.
#pragma once

#include <cstdint>

#include "hal/digital_io.h"
#include "hal/sim/sim_world.h"

namespace boticelli::hal::sim {

// An input line under injected faults: off = the wire broken, which the normally closed
// wiring reads as active (pressed, in contact); stuck = held active; intermittent = active
// in its failing slots (a chattering contact). An edge is reported when a fault makes the
// line active, as the GPIO driver's edge events would.
class FaultyLine {
 public:
  explicit FaultyLine(FaultDevice device) : device_(device) {}
  // True while a fault holds the line active.
  bool forced(const SimWorld& world) const {
    FaultType type = FaultType::kOff;
    return world.faults().failing(device_, type);
  }
  // An edge from the fault (inactive → active since the last call).
  bool edge(const SimWorld& world) {
    const bool now = forced(world);
    const bool e = now && !was_forced_;
    was_forced_ = now;
    return e;
  }

 private:
  FaultDevice device_;
  bool was_forced_ = false;
};

// The e-stop button; press it with SimWorld::set_estop_pressed() or schedule_estop().
class EstopInputSim final : public DigitalIn {
 public:
  explicit EstopInputSim(SimWorld& world) : world_(world) {}
  bool read() override { return world_.estop_pressed() || line_.forced(world_); }
  bool activated_since_last_poll() override {
    const bool edge = world_.estop_presses() != seen_;
    seen_ = world_.estop_presses();
    return line_.edge(world_) || edge;
  }

 private:
  SimWorld& world_;
  FaultyLine line_{FaultDevice::kEstop};
  std::uint32_t seen_ = 0;
};

// The bumper ring: active while the robot's cylinder touches an obstacle.
class BumperInputSim final : public DigitalIn {
 public:
  explicit BumperInputSim(SimWorld& world) : world_(world) {}
  bool read() override { return world_.in_contact() || line_.forced(world_); }
  bool activated_since_last_poll() override {
    const bool edge = world_.contacts() != seen_;
    seen_ = world_.contacts();
    return line_.edge(world_) || edge;
  }

 private:
  SimWorld& world_;
  FaultyLine line_{FaultDevice::kBumper};
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
