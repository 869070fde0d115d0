// Ptu46Emulator: a PTU-D46 on the master side of a pseudo-terminal, for driver tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace boticelli::fakes {

struct Ptu46EmulatorConfig {
  double pan_arcsec_per_count = 185.1428;  // PTU-D46-17 class resolutions
  double tilt_arcsec_per_count = 46.2857;
  std::int32_t pan_min = -3090;
  std::int32_t pan_max = 3090;
  std::int32_t tilt_min = -907;
  std::int32_t tilt_max = 604;
  std::int32_t pan_speed = 1000;  // counts/s
  std::int32_t tilt_speed = 1000;
  std::int32_t max_speed = 2902;  // PU / TU
  std::uint64_t reset_duration_us = 3000000;
  bool echo = true;  // as after power-up: echo on, verbose feedback
  bool terse = false;
};

// Keeps position, speed, limits and move timing; answers like the unit (echo and verbose
// until ED/FT). service(now) reads the commands the driver wrote, advances the motion to
// `now` and writes the replies. Faults can be injected: an "!" answer, silence, garbage,
// unsolicited limit reports. Single-threaded: the test calls service() between driver
// updates.
class Ptu46Emulator {
 public:
  explicit Ptu46Emulator(const Ptu46EmulatorConfig& config = {});
  ~Ptu46Emulator();
  Ptu46Emulator(const Ptu46Emulator&) = delete;
  Ptu46Emulator& operator=(const Ptu46Emulator&) = delete;

  // Opens the pty pair; slave_path() is what the driver opens.
  bool open();
  const char* slave_path() const { return slave_path_; }
  int master_fd() const { return master_; }
  void service(std::uint64_t now_us);

  // Fault injection.
  void answer_next_with_error(std::string_view message) { pending_error_ = message; }
  void set_silent(bool silent) { silent_ = silent; }
  void send_raw(std::string_view bytes);
  // Unit unplugged: closes the master (the driver's reads fail).
  void unplug();

  // Inspection.
  std::int32_t pan_counts() const { return static_cast<std::int32_t>(axes_[0].position); }
  std::int32_t tilt_counts() const { return static_cast<std::int32_t>(axes_[1].position); }
  std::int32_t pan_target() const { return axes_[0].target; }
  std::int32_t pan_speed() const { return axes_[0].speed; }
  std::int32_t tilt_speed() const { return axes_[1].speed; }
  bool terse() const { return terse_; }
  bool echo() const { return echo_; }
  const std::vector<std::string>& commands() const { return commands_; }
  std::size_t count_commands(std::string_view text) const;
  // Moves the pan axis to its limit and reports "!P" (a collision stopping the axis).
  void hit_pan_limit();

 private:
  struct AxisSim {
    double position = 0.0;
    std::int32_t target = 0;
    std::int32_t speed = 1000;
    std::int32_t min = 0;
    std::int32_t max = 0;
    double arcsec = 0.0;
  };
  void execute(const std::string& command);
  void reply_ok(std::string_view verbose_text, bool with_value, long long value);
  void reply_ok_text(std::string_view value_text);
  void reply_error(std::string_view message);
  void advance(std::uint64_t now_us);
  bool at_targets() const;
  void flush_output();

  Ptu46EmulatorConfig config_;
  int master_ = -1;
  char slave_path_[128] = "";
  AxisSim axes_[2];
  bool echo_;
  bool terse_;
  bool silent_ = false;
  std::string pending_error_;
  std::string input_;
  std::string output_;
  std::vector<std::string> commands_;
  std::uint64_t last_us_ = 0;
  bool have_time_ = false;
  bool awaiting_ = false;
  bool resetting_ = false;
  std::uint64_t reset_done_us_ = 0;
};

}  // namespace boticelli::fakes
