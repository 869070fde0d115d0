// libFuzzer target: console commands through the dispatcher. Most inputs are made into lines
// of printable text first (so they pass the line assembler and reach the command parser and
// handlers); inputs whose first byte is odd are fed raw, control bytes and all.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "fake_clock.h"
#include "fake_serial_port.h"
#include "firmware/console/console.h"
#include "firmware/executive/executive.h"
#include "firmware/common/parameters.h"
#include "firmware/safety/safety.h"
#include "firmware_fakes.h"

namespace fw = boticelli::firmware;

namespace {

class FuzzView final : public fw::MissionView {
 public:
  const char* state_name() const override { return "look"; }
  boticelli::core::Pose2 pose() const override { return {1.25F, -0.5F, 0.75F}; }
  float pan_rad() const override { return 0.5F; }
  std::uint32_t pieces() const override { return 17; }
  std::string_view model_text() override {
    return "VARIABLES 3\nOUTPUT 3\nLINEARFORMS 1\n0 0 0.01 0\nBLOCKS\n";
  }
};

class IdleTask final : public fw::Task {
 public:
  void run(std::uint64_t) override {}
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  boticelli::fakes::FakeClock clock(5000000);
  boticelli::fakes::FakeSerialPort port;
  fw::Executive exec(clock);
  boticelli::test::FakeInput button;
  boticelli::test::FakeInput bumper;
  boticelli::test::FakeBase base;
  fw::Safety safety(button, bumper, base);
  FuzzView view;
  fw::ParameterTable parameters;
  fw::Console console(port, exec, safety, view, parameters);
  IdleTask idle;
  float gain = 2.0F;
  const char* error = "";
  if (!exec.add_task({"estop", 10000, 200}, idle, &error) || !exec.start({}, &error) ||
      !console.register_parameters() ||
      !parameters.add({"gain", &gain, 0.0F, 10.0F, false, "a gain [1]"})) {
    std::abort();
  }
  const bool raw = (data[0] & 1U) != 0;
  std::string input;
  input.reserve(size + 1);
  for (std::size_t i = 1; i < size; ++i) {
    const auto c = static_cast<char>(data[i]);
    if (raw || (data[i] >= 0x20 && data[i] <= 0x7E)) {
      input += c;
    } else {
      input += data[i] < 0x20 ? '\r' : ' ';
    }
  }
  input += '\r';
  port.feed(input);
  std::uint64_t now_us = 5000000;
  // Enough services to read everything (64 bytes each) and send the replies.
  for (std::size_t i = 0; i < input.size() / fw::Console::kReadChunkBytes + 8; ++i) {
    console.service(now_us);
    now_us += 10000;
    clock.advance_us(10000);
    if (console.shutdown_requested()) break;
  }
  // Every reply line ends in CRLF and holds printable text only (raw input may be echoed).
  // With echo on, a line the console sends while a command is half typed first clears the
  // terminal's line ("\r\x1b[K", VT100) and types the command again after it: taken out.
  std::string out = port.written();
  constexpr std::string_view kClearLine = "\r\x1b[K";
  for (std::size_t at = out.find(kClearLine); at != std::string::npos; at = out.find(kClearLine)) {
    out.erase(at, kClearLine.size());
  }
  for (std::size_t i = 0; i < out.size() && !raw; ++i) {
    const auto u = static_cast<unsigned char>(out[i]);
    if (u == '\r' && (i + 1 >= out.size() || out[i + 1] != '\n')) std::abort();
    if (u == '\n' && (i == 0 || out[i - 1] != '\r')) std::abort();
    if (u != '\r' && u != '\n' && (u < 0x20 || u > 0x7E)) std::abort();
  }
  if (!(gain >= 0.0F && gain <= 10.0F)) std::abort();  // set is range checked
  return 0;
}
