// MockCamera: CppUMock mock of hal::Camera ("Camera.init", "Camera.poll", ...).
#pragma once

#include "hal/camera.h"

#include "CppUTestExt/MockSupport.h"

namespace boticelli::mocks {

// poll() takes its result from the expectation's int return value (a CameraPoll) and fills
// `frame` from an output parameter "frame" when the test gives one:
//   mock().expectOneCall("Camera.poll").withOutputParameterReturning("frame", &f, sizeof f)
//       .andReturnValue(static_cast<int>(hal::CameraPoll::kFrame));
class MockCamera final : public hal::Camera {
 public:
  bool init() override {
    return mock().actualCall("Camera.init").onObject(this).returnBoolValueOrDefault(true);
  }
  hal::CameraPoll poll(hal::Frame& frame) override {
    const int r = mock()
                      .actualCall("Camera.poll")
                      .onObject(this)
                      .withOutputParameter("frame", &frame)
                      .returnIntValueOrDefault(static_cast<int>(hal::CameraPoll::kNoFrame));
    return static_cast<hal::CameraPoll>(r);
  }
  void release() override { mock().actualCall("Camera.release").onObject(this); }
  std::uint32_t width_px() const override {
    return mock()
        .actualCall("Camera.width_px")
        .onObject(this)
        .returnUnsignedIntValueOrDefault(640U);
  }
  std::uint32_t height_px() const override {
    return mock()
        .actualCall("Camera.height_px")
        .onObject(this)
        .returnUnsignedIntValueOrDefault(480U);
  }
  const char* error() const override {
    return mock().actualCall("Camera.error").onObject(this).returnStringValueOrDefault("");
  }
};

}  // namespace boticelli::mocks
