// MockPanTilt: CppUMock mock of hal::PanTilt ("PanTilt.move_to" with "pan_rad", "tilt_rad", ...).
#pragma once

#include "hal/pan_tilt.h"

#include "CppUTestExt/MockSupport.h"

namespace boticelli::mocks {

// state() and limits() return the values set with set_state()/set_limits() unless the
// expectation returns a pointer to another struct (andReturnValue(const void*)).
class MockPanTilt final : public hal::PanTilt {
 public:
  void set_state(const hal::PanTiltState& s) { state_ = s; }
  void set_limits(const hal::PanTiltLimits& l) { limits_ = l; }

  bool init() override {
    return mock().actualCall("PanTilt.init").onObject(this).returnBoolValueOrDefault(true);
  }
  void update() override { mock().actualCall("PanTilt.update").onObject(this); }
  bool move_to(float pan_rad, float tilt_rad) override {
    return mock()
        .actualCall("PanTilt.move_to")
        .onObject(this)
        .withParameter("pan_rad", static_cast<double>(pan_rad))
        .withParameter("tilt_rad", static_cast<double>(tilt_rad))
        .returnBoolValueOrDefault(true);
  }
  void halt() override { mock().actualCall("PanTilt.halt").onObject(this); }
  hal::PanTiltState state() const override {
    return *static_cast<const hal::PanTiltState*>(mock()
                                                      .actualCall("PanTilt.state")
                                                      .onObject(this)
                                                      .returnConstPointerValueOrDefault(&state_));
  }
  hal::PanTiltLimits limits() const override {
    return *static_cast<const hal::PanTiltLimits*>(mock()
                                                       .actualCall("PanTilt.limits")
                                                       .onObject(this)
                                                       .returnConstPointerValueOrDefault(&limits_));
  }
  bool set_speed(float pan_rad_s, float tilt_rad_s) override {
    return mock()
        .actualCall("PanTilt.set_speed")
        .onObject(this)
        .withParameter("pan_rad_s", static_cast<double>(pan_rad_s))
        .withParameter("tilt_rad_s", static_cast<double>(tilt_rad_s))
        .returnBoolValueOrDefault(true);
  }
  const char* error() const override {
    return mock().actualCall("PanTilt.error").onObject(this).returnStringValueOrDefault("");
  }

 private:
  hal::PanTiltState state_{};
  hal::PanTiltLimits limits_{};
};

}  // namespace boticelli::mocks
