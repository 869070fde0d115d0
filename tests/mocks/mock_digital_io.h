// MockDigitalIn / MockDigitalOut: CppUMock mocks of the GPIO interfaces ("DigitalIn.read", ...).
#pragma once

#include "hal/digital_io.h"

#include "CppUTestExt/MockSupport.h"

namespace boticelli::mocks {

class MockDigitalIn final : public hal::DigitalIn {
 public:
  bool read() override {
    return mock().actualCall("DigitalIn.read").onObject(this).returnBoolValueOrDefault(false);
  }
  bool activated_since_last_poll() override {
    return mock()
        .actualCall("DigitalIn.activated_since_last_poll")
        .onObject(this)
        .returnBoolValueOrDefault(false);
  }
};

class MockDigitalOut final : public hal::DigitalOut {
 public:
  void write(bool active) override {
    mock().actualCall("DigitalOut.write").onObject(this).withParameter("active", active);
  }
};

}  // namespace boticelli::mocks
