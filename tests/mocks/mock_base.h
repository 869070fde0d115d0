// MockBase: CppUMock mock of hal::Base ("Base.set_velocity" with "v_m_s", "omega_rad_s", ...).
#pragma once

#include "hal/base.h"

#include "CppUTestExt/MockSupport.h"

namespace boticelli::mocks {

// health() returns an int expectation value (a BaseHealth) or set_health()'s value;
// odometry() returns set_odometry()'s value unless the expectation returns a pointer.
class MockBase final : public hal::Base {
 public:
  void set_health(hal::BaseHealth h) { health_ = h; }
  void set_odometry(const hal::Odometry& o) { odometry_ = o; }

  bool init() override {
    return mock().actualCall("Base.init").onObject(this).returnBoolValueOrDefault(true);
  }
  void update() override { mock().actualCall("Base.update").onObject(this); }
  void set_velocity(float v_m_s, float omega_rad_s) override {
    mock()
        .actualCall("Base.set_velocity")
        .onObject(this)
        .withParameter("v_m_s", static_cast<double>(v_m_s))
        .withParameter("omega_rad_s", static_cast<double>(omega_rad_s));
  }
  void stop() override { mock().actualCall("Base.stop").onObject(this); }
  bool resume() override {
    return mock().actualCall("Base.resume").onObject(this).returnBoolValueOrDefault(true);
  }
  hal::BaseHealth health() const override {
    return static_cast<hal::BaseHealth>(mock()
                                            .actualCall("Base.health")
                                            .onObject(this)
                                            .returnIntValueOrDefault(static_cast<int>(health_)));
  }
  hal::Odometry odometry() const override {
    return *static_cast<const hal::Odometry*>(mock()
                                                  .actualCall("Base.odometry")
                                                  .onObject(this)
                                                  .returnConstPointerValueOrDefault(&odometry_));
  }
  const char* error() const override {
    return mock().actualCall("Base.error").onObject(this).returnStringValueOrDefault("");
  }

 private:
  hal::BaseHealth health_ = hal::BaseHealth::kReady;
  hal::Odometry odometry_{};
};

}  // namespace boticelli::mocks
