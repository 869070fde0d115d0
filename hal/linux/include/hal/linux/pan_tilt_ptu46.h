// PanTiltPtu46: hal::PanTilt for a Directed Perception / FLIR PTU-D46 on a serial line.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/clock.h"
#include "hal/codec/ptu46_codec.h"
#include "hal/pan_tilt.h"
#include "hal/serial_port.h"

namespace boticelli::hal_linux {

struct PanTiltPtu46Config {
  std::uint32_t reply_timeout_ms = 1000;   // a command without an answer by then is a fault
  std::uint32_t reset_timeout_ms = 30000;  // R runs both axes to their limits and back
  std::uint32_t position_poll_ms = 100;    // position queries while a move is in progress
  std::uint32_t idle_query_ms = 1000;      // a position query after this long quiet (0: none)
  std::uint32_t retry_backoff_ms = 2000;   // wait before re-initialising after a fault
};

// Non-blocking driver: every call returns at once; update() writes the next queued command,
// reads and parses replies (one command outstanding at a time, as the unit answers in
// order) and detects timeouts. init() opens the port and queues the start-up sequence
// FT ED CI PR TR PN PX TN TX PU TU PP TP; the unit is ready when all were answered with
// sane values. While ready, a quiet line gets a position query every idle_query_ms, so a
// unit that went away is a fault (reply timeout) before the next move. After a fault (timeout,
// serial error, bad init reply) the driver re-opens the port and re-runs the sequence after
// retry_backoff_ms. The serial port (SerialTermios at 9600 8N1 for the real unit) and the clock are
// borrowed and must outlive the driver.
class PanTiltPtu46 final : public hal::PanTilt {
 public:
  PanTiltPtu46(hal::SerialPort& port, hal::Clock& clock, const PanTiltPtu46Config& config = {});

  bool init() override;
  void update() override;
  bool move_to(float pan_rad, float tilt_rad) override;
  void halt() override;
  hal::PanTiltState state() const override { return state_; }
  hal::PanTiltLimits limits() const override { return limits_; }
  // Speeds [rad/s] > 0 and not above the unit's PU/TU upper speed limits.
  bool set_speed(float pan_rad_s, float tilt_rad_s) override;
  const char* error() const override { return error_; }

  // Queues R (reset/home: both axes run to their limits and back); false unless ready.
  bool reset();
  // Queues A (await): the unit answers once the last move has completed. While it waits it
  // does not process commands, so a halt() is delayed until then; prefer polling.
  bool await_move();
  bool ready() const { return phase_ == Phase::kReady; }
  // Diagnostics: lines that were not replies (noise, echo, stray), command timeouts.
  std::uint32_t garbage_lines() const { return garbage_lines_; }
  std::uint32_t timeouts() const { return timeouts_; }
  std::int32_t pan_counts() const { return axes_[0].position_counts; }
  std::int32_t tilt_counts() const { return axes_[1].position_counts; }

 private:
  enum class Phase : std::uint8_t { kIdle, kInitialising, kReady, kBackoff };
  enum class Kind : std::uint8_t { kSetting, kQuery, kMove, kSpeed, kHalt, kReset, kAwait };
  struct Command {
    Kind kind = Kind::kSetting;
    codec::ptu46::Axis axis = codec::ptu46::Axis::kPan;
    codec::ptu46::Query query = codec::ptu46::Query::kPosition;
    std::int32_t argument = 0;
    bool last_of_init = false;
    std::uint8_t length = 0;
    char text[codec::ptu46::kMaxCommandLength] = {};
  };
  struct AxisData {
    double arcsec_per_count = 0.0;
    std::int32_t min_counts = 0;
    std::int32_t max_counts = 0;
    std::int32_t max_speed_counts_s = 0;
    std::int32_t position_counts = 0;
    std::int32_t target_counts = 0;
    bool moving = false;
    bool have_resolution = false;
    bool have_min = false;
    bool have_max = false;
  };
  static constexpr std::size_t kQueueCapacity = 24;

  bool push_back(const Command& c);
  bool push_front(const Command& c);
  void pop_front();
  bool queue_query(codec::ptu46::Axis axis, codec::ptu46::Query query, bool last = false);
  bool queue_setting(codec::ptu46::Setting setting, Kind kind);
  void start_sequence();
  void enter_fault(const char* what, const char* detail = nullptr);
  void drop_queued(Kind kind);
  bool queued(Kind kind) const;
  void read_replies(std::uint64_t now_us);
  void handle_line(std::string_view line, std::uint64_t now_us);
  void complete(const codec::ptu46::Reply& reply, std::uint64_t now_us);
  void finish_init();
  void send_next(std::uint64_t now_us);
  void refresh_state();
  AxisData& axis(codec::ptu46::Axis a) { return axes_[a == codec::ptu46::Axis::kPan ? 0 : 1]; }

  hal::SerialPort& port_;
  hal::Clock& clock_;
  PanTiltPtu46Config config_;
  Phase phase_ = Phase::kIdle;
  std::array<Command, kQueueCapacity> queue_{};
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  bool outstanding_ = false;    // queue_[head_] was sent and awaits its reply
  std::size_t sent_bytes_ = 0;  // of the front command (partial writes)
  std::uint64_t sent_at_us_ = 0;
  std::uint64_t retry_at_us_ = 0;
  std::uint64_t next_poll_us_ = 0;
  std::uint64_t next_liveness_us_ = 0;
  codec::ptu46::LineAssembler lines_;
  std::array<AxisData, 2> axes_{};
  hal::PanTiltState state_{};
  hal::PanTiltLimits limits_{};
  std::uint32_t garbage_lines_ = 0;
  std::uint32_t timeouts_ = 0;
  char error_[160] = "";
};

}  // namespace boticelli::hal_linux
