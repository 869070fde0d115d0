// Console over a real pseudo-terminal pair: the test types on the master side like picocom, the
// console owns the slave.
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <string>

#include "fake_clock.h"
#include "firmware/console/console.h"
#include "firmware/executive/executive.h"
#include "firmware_fakes.h"
#include "hal/linux/serial_termios.h"

#include "CppUTest/TestHarness.h"

using namespace boticelli::firmware;
using namespace boticelli::test;

namespace {

class PtyView final : public MissionView {
 public:
  const char* state_name() const override { return "idle"; }
  boticelli::core::Pose2 pose() const override { return {0.5F, 0.25F, 0.0F}; }
  float pan_rad() const override { return 0.0F; }
};

class NoopTask final : public Task {
 public:
  void run(std::uint64_t) override {}
};

}  // namespace

TEST_GROUP(ConsoleOverPty) {
  int master = -1;
  char slave_path[128] = "";
  boticelli::fakes::FakeClock clock{0};
  Executive exec{clock};
  NoopTask noop;
  FakeInput button, bumper;
  FakeBase base;
  Safety safety{button, bumper, base};
  PtyView view;
  ParameterTable parameters;
  boticelli::hal_linux::SerialTermios* port = nullptr;
  Console* console = nullptr;
  std::uint64_t now_us = 0;

  void setup() override {
    master = posix_openpt(O_RDWR | O_NOCTTY);
    CHECK(master >= 0);
    CHECK_EQUAL(0, grantpt(master));
    CHECK_EQUAL(0, unlockpt(master));
    CHECK_EQUAL(0, ptsname_r(master, slave_path, sizeof slave_path));
    fcntl(master, F_SETFL, fcntl(master, F_GETFL) | O_NONBLOCK);
    port = new boticelli::hal_linux::SerialTermios({slave_path, 115200});
    CHECK_TEXT(port->open(), port->error());
    const char* error = "";
    CHECK(exec.add_task({"console", 10000, 1500}, noop, &error));
    CHECK(exec.start(ExecutiveConfig{}, &error));
    console = new Console(*port, exec, safety, view, parameters);
    CHECK(console->register_parameters());
    console->set_telemetry_ms(0.0F);
  }
  void teardown() override {
    delete console;
    delete port;
    close(master);
  }
  void type(const std::string& text) {
    CHECK_EQUAL(static_cast<ssize_t>(text.size()), write(master, text.data(), text.size()));
  }
  // Services the console and collects what arrives on the master until `until` shows up
  // (or 3 s pass: a failure, not a timing assumption).
  std::string read_until(const std::string& until) {
    std::string got;
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(3);
    while (got.find(until) == std::string::npos && std::chrono::steady_clock::now() < give_up) {
      console->service(now_us);
      now_us += 10000;
      pollfd p{master, POLLIN, 0};
      if (poll(&p, 1, 5) > 0) {
        char buf[512];
        const ssize_t n = read(master, buf, sizeof buf);
        if (n > 0) got.append(buf, static_cast<std::size_t>(n));
      }
    }
    return got;
  }
};

TEST(ConsoleOverPty, AnswersACommandTypedWithCarriageReturnLikePicocom) {
  type("status\r");
  const std::string got = read_until("OK\r\n");
  STRCMP_CONTAINS("status state=idle estop=none", got.c_str());
  STRCMP_CONTAINS("OK\r\n", got.c_str());
}

TEST(ConsoleOverPty, TakesLineFeedEndsBackspacesAndEchoesForTerminals) {
  type("set echo 1\n");
  CHECK(read_until("OK\r\n").find("OK\r\n") != std::string::npos);
  type(
      "posx\x7f"
      "e\r");
  const std::string got = read_until("OK\r\n");
  STRCMP_CONTAINS("posx\b \be\r\npose x_m=0.500 y_m=0.250", got.c_str());
}

TEST(ConsoleOverPty, RejectsAnOverlongLineAndKeepsWorking) {
  type(std::string(1000, 'x') + "\r");
  std::string got = read_until("ERR line too long\r\n");
  STRCMP_CONTAINS("ERR line too long\r\n", got.c_str());
  type("estop\r");
  got = read_until("OK\r\n");
  STRCMP_CONTAINS("OK\r\n", got.c_str());
  CHECK(safety.engaged());
}
