// PanTiltPtu46: non-blocking PTU-D46 driver (command queue, reply parsing, timeouts, re-init).
#include "hal/linux/pan_tilt_ptu46.h"

#include <cmath>
#include <cstdio>

namespace boticelli::hal_linux {

using codec::ptu46::Axis;
using codec::ptu46::Query;
using codec::ptu46::Reply;
using codec::ptu46::ReplyKind;
using codec::ptu46::Setting;

PanTiltPtu46::PanTiltPtu46(hal::SerialPort& port, hal::Clock& clock,
                           const PanTiltPtu46Config& config)
    : port_(port), clock_(clock), config_(config) {}

bool PanTiltPtu46::push_back(const Command& c) {
  if (count_ == kQueueCapacity) return false;
  queue_[(head_ + count_) % kQueueCapacity] = c;
  ++count_;
  return true;
}

bool PanTiltPtu46::push_front(const Command& c) {
  if (count_ == kQueueCapacity) return false;
  if (outstanding_) {
    // Keep the command in flight at the front: insert right behind it.
    Command moved = c;
    for (std::size_t i = 1; i <= count_; ++i) {
      Command& slot = queue_[(head_ + i) % kQueueCapacity];
      if (i == count_) {
        slot = moved;
        break;
      }
      const Command tmp = slot;
      slot = moved;
      moved = tmp;
    }
    ++count_;
    return true;
  }
  head_ = (head_ + kQueueCapacity - 1) % kQueueCapacity;
  queue_[head_] = c;
  ++count_;
  return true;
}

void PanTiltPtu46::pop_front() {
  if (count_ == 0) return;
  head_ = (head_ + 1) % kQueueCapacity;
  --count_;
  outstanding_ = false;
  sent_bytes_ = 0;
}

bool PanTiltPtu46::queued(Kind kind) const {
  for (std::size_t i = 0; i < count_; ++i) {
    if (queue_[(head_ + i) % kQueueCapacity].kind == kind) return true;
  }
  return false;
}

void PanTiltPtu46::drop_queued(Kind kind) {
  // Removes not-yet-sent commands of one kind, keeping the order of the others.
  const std::size_t first = outstanding_ ? 1 : 0;
  std::size_t kept = first;
  for (std::size_t i = first; i < count_; ++i) {
    const Command& c = queue_[(head_ + i) % kQueueCapacity];
    if (c.kind == kind) continue;
    queue_[(head_ + kept) % kQueueCapacity] = c;
    ++kept;
  }
  count_ = kept;
}

bool PanTiltPtu46::queue_query(Axis a, Query q, bool last) {
  Command c;
  c.kind = Kind::kQuery;
  c.axis = a;
  c.query = q;
  c.last_of_init = last;
  c.length = static_cast<std::uint8_t>(codec::ptu46::encode_query(a, q, c.text, sizeof c.text));
  return push_back(c);
}

bool PanTiltPtu46::queue_setting(Setting s, Kind kind) {
  Command c;
  c.kind = kind;
  c.length = static_cast<std::uint8_t>(codec::ptu46::encode_setting(s, c.text, sizeof c.text));
  return push_back(c);
}

void PanTiltPtu46::start_sequence() {
  count_ = 0;
  head_ = 0;
  outstanding_ = false;
  sent_bytes_ = 0;
  lines_.reset();
  axes_ = {};
  // Discard whatever the unit sent before (echo, banners, half lines).
  std::uint8_t scratch[64];
  for (int i = 0; i < 64 && port_.read(scratch, sizeof scratch) > 0; ++i) {
  }
  queue_setting(Setting::kTerse, Kind::kSetting);
  queue_setting(Setting::kEchoOff, Kind::kSetting);
  queue_setting(Setting::kIndependentMode, Kind::kSetting);
  for (Axis a : {Axis::kPan, Axis::kTilt}) queue_query(a, Query::kResolution);
  for (Axis a : {Axis::kPan, Axis::kTilt}) {
    queue_query(a, Query::kMinPosition);
    queue_query(a, Query::kMaxPosition);
  }
  queue_query(Axis::kPan, Query::kMaxSpeed);
  queue_query(Axis::kTilt, Query::kMaxSpeed);
  queue_query(Axis::kPan, Query::kPosition);
  queue_query(Axis::kTilt, Query::kPosition, true);
  phase_ = Phase::kInitialising;
  state_.moving = false;
}

bool PanTiltPtu46::init() {
  if (!port_.open()) {
    std::snprintf(error_, sizeof error_, "PTU: cannot open the serial port: %s", port_.error());
    state_.fault = true;
    phase_ = Phase::kBackoff;
    retry_at_us_ = clock_.now_us() + std::uint64_t{config_.retry_backoff_ms} * 1000U;
    return false;
  }
  error_[0] = '\0';
  state_.fault = false;
  start_sequence();
  return true;
}

void PanTiltPtu46::enter_fault(const char* what, const char* detail) {
  if (detail != nullptr) {
    std::snprintf(error_, sizeof error_, "PTU: %s%s", what, detail);
  } else {
    std::snprintf(error_, sizeof error_, "PTU: %s", what);
  }
  state_.fault = true;
  state_.moving = false;
  phase_ = Phase::kBackoff;
  count_ = 0;
  outstanding_ = false;
  retry_at_us_ = clock_.now_us() + std::uint64_t{config_.retry_backoff_ms} * 1000U;
}

void PanTiltPtu46::update() {
  const std::uint64_t now = clock_.now_us();
  if (phase_ == Phase::kIdle) return;
  if (phase_ == Phase::kBackoff) {
    if (now < retry_at_us_) return;
    // Re-open (the device may have been unplugged) and re-run the start-up sequence; the
    // fault flag and error stay until the unit answers the whole sequence.
    if (!port_.open()) {
      retry_at_us_ = now + std::uint64_t{config_.retry_backoff_ms} * 1000U;
      return;
    }
    start_sequence();
  }
  read_replies(now);
  if (phase_ == Phase::kBackoff) return;
  if (outstanding_) {
    const Command& c = queue_[head_];
    const std::uint32_t timeout_ms = c.kind == Kind::kReset || c.kind == Kind::kAwait
                                         ? config_.reset_timeout_ms
                                         : config_.reply_timeout_ms;
    if (now - sent_at_us_ > std::uint64_t{timeout_ms} * 1000U) {
      ++timeouts_;
      char detail[40];
      std::snprintf(detail, sizeof detail, "'%.*s'", static_cast<int>(c.length), c.text);
      enter_fault("no reply to ", detail);
      return;
    }
  }
  // Position polls while moving, whatever else is queued (a move_to() every cycle keeps
  // the queue busy), but never two pending at once.
  if (phase_ == Phase::kReady && state_.moving && now >= next_poll_us_ && !queued(Kind::kQuery)) {
    queue_query(Axis::kPan, Query::kPosition);
    queue_query(Axis::kTilt, Query::kPosition);
    next_poll_us_ = now + std::uint64_t{config_.position_poll_ms} * 1000U;
  }
  // Liveness while idle: a unit that died (power, cable) must be noticed before the next
  // move needs it; any answer counts, so this only asks when the line has been quiet.
  if (phase_ == Phase::kReady && count_ == 0 && config_.idle_query_ms > 0 &&
      now >= next_liveness_us_) {
    queue_query(Axis::kPan, Query::kPosition);
    next_liveness_us_ = now + std::uint64_t{config_.idle_query_ms} * 1000U;
  }
  send_next(now);
}

void PanTiltPtu46::send_next(std::uint64_t now_us) {
  if (count_ == 0) return;
  Command& c = queue_[head_];
  if (outstanding_ && sent_bytes_ >= c.length) return;
  const std::ptrdiff_t n = port_.write(reinterpret_cast<const std::uint8_t*>(c.text) + sent_bytes_,
                                       c.length - sent_bytes_);
  if (n < 0) {
    enter_fault("serial write failed: ", port_.error());
    return;
  }
  if (!outstanding_) sent_at_us_ = now_us;  // the reply timeout runs from the first byte
  outstanding_ = true;
  sent_bytes_ += static_cast<std::size_t>(n);
}

void PanTiltPtu46::read_replies(std::uint64_t now_us) {
  std::uint8_t buf[64];
  // Bounded: at 9600 baud at most ~1 kB/s arrive, so a few reads drain the line each frame.
  for (int i = 0; i < 8; ++i) {
    const std::ptrdiff_t n = port_.read(buf, sizeof buf);
    if (n < 0) {
      enter_fault("serial read failed: ", port_.error());
      return;
    }
    for (std::ptrdiff_t k = 0; k < n; ++k) {
      if (lines_.push(static_cast<char>(buf[k]))) {
        handle_line(lines_.line(), now_us);
        if (phase_ == Phase::kBackoff) return;
      }
    }
    if (n < static_cast<std::ptrdiff_t>(sizeof buf)) break;
  }
}

void PanTiltPtu46::handle_line(std::string_view line, std::uint64_t now_us) {
  if (lines_.line_corrupt()) {
    ++garbage_lines_;
    return;
  }
  const Reply r = codec::ptu46::parse_reply(line);
  if (r.kind == ReplyKind::kGarbage) {
    ++garbage_lines_;
    return;
  }
  if (r.skipped > 0) ++garbage_lines_;  // echo or noise before the marker; the reply counts
  const bool in_reset = outstanding_ && queue_[head_].kind == Kind::kReset;
  if (r.kind == ReplyKind::kLimitPan || r.kind == ReplyKind::kLimitTilt) {
    if (in_reset) return;  // the reset runs each axis into its limits on purpose
    // A report of its own, not an answer: the command in flight (a move of that axis too)
    // still gets its '*', so nothing is taken off the queue, or every later reply would be
    // matched with the command after its own.
    const Axis a = r.kind == ReplyKind::kLimitPan ? Axis::kPan : Axis::kTilt;
    std::snprintf(error_, sizeof error_, "PTU: %s axis hit a limit",
                  a == Axis::kPan ? "pan" : "tilt");
    state_.fault = true;
    axis(a).moving = false;
    if (phase_ == Phase::kReady) queue_query(a, Query::kPosition);
    refresh_state();
    return;
  }
  if (!outstanding_ || sent_bytes_ < queue_[head_].length) {
    ++garbage_lines_;  // a reply nobody asked for (stale, or from before a resync)
    return;
  }
  next_liveness_us_ = now_us + std::uint64_t{config_.idle_query_ms} * 1000U;
  complete(r, now_us);
}

void PanTiltPtu46::complete(const Reply& r, std::uint64_t now_us) {
  const Command c = queue_[head_];
  pop_front();
  if (r.kind == ReplyKind::kError) {
    char detail[120];
    std::snprintf(detail, sizeof detail, "'%.*s' rejected: %.*s", static_cast<int>(c.length),
                  c.text, static_cast<int>(r.text.size() > 80 ? 80 : r.text.size()), r.text.data());
    if (phase_ == Phase::kInitialising) {
      enter_fault("start-up ", detail);
      return;
    }
    std::snprintf(error_, sizeof error_, "PTU: %s", detail);
    state_.fault = true;
    if (c.kind == Kind::kMove) {
      axis(c.axis).moving = false;
      queue_query(c.axis, Query::kPosition);
    }
    refresh_state();
    return;
  }
  AxisData& ax = axis(c.axis);
  switch (c.kind) {
    case Kind::kQuery: {
      if (!r.has_value) {
        enter_fault("query answered without a number: ", c.text);
        return;
      }
      const double v = r.value;
      const bool integral = v == std::floor(v) && std::fabs(v) < 2147483647.0;
      switch (c.query) {
        case Query::kResolution:
          if (!(v > 0.0 && v < 3600.0)) {
            enter_fault("implausible resolution [arc-seconds/count] from ", c.text);
            return;
          }
          ax.arcsec_per_count = v;
          ax.have_resolution = true;
          break;
        case Query::kMinPosition:
        case Query::kMaxPosition:
        case Query::kMaxSpeed:
        case Query::kSpeed:
        case Query::kPosition:
          if (!integral) {
            enter_fault("non-integral count from ", c.text);
            return;
          }
          if (c.query == Query::kMinPosition) {
            ax.min_counts = static_cast<std::int32_t>(v);
            ax.have_min = true;
          } else if (c.query == Query::kMaxPosition) {
            ax.max_counts = static_cast<std::int32_t>(v);
            ax.have_max = true;
          } else if (c.query == Query::kMaxSpeed) {
            ax.max_speed_counts_s = static_cast<std::int32_t>(v);
          } else if (c.query == Query::kPosition) {
            ax.position_counts = static_cast<std::int32_t>(v);
            if (ax.moving && ax.position_counts == ax.target_counts) ax.moving = false;
          }
          break;
      }
      if (c.last_of_init) finish_init();
      break;
    }
    case Kind::kMove:
      next_poll_us_ = now_us;  // start polling the position
      break;
    case Kind::kHalt:
      for (AxisData& a : axes_) a.moving = false;
      queue_query(Axis::kPan, Query::kPosition);
      queue_query(Axis::kTilt, Query::kPosition);
      break;
    case Kind::kReset:
    case Kind::kAwait:
      for (AxisData& a : axes_) a.moving = false;
      queue_query(Axis::kPan, Query::kPosition);
      queue_query(Axis::kTilt, Query::kPosition);
      break;
    case Kind::kSetting:
    case Kind::kSpeed:
      break;
  }
  refresh_state();
}

void PanTiltPtu46::finish_init() {
  for (const AxisData& a : axes_) {
    if (!a.have_resolution || !a.have_min || !a.have_max || a.min_counts >= a.max_counts) {
      enter_fault("start-up: inconsistent limits or resolution from the unit");
      return;
    }
  }
  const AxisData& p = axes_[0];
  const AxisData& t = axes_[1];
  limits_.pan_min_rad =
      static_cast<float>(codec::ptu46::counts_to_rad(p.min_counts, p.arcsec_per_count));
  limits_.pan_max_rad =
      static_cast<float>(codec::ptu46::counts_to_rad(p.max_counts, p.arcsec_per_count));
  limits_.tilt_min_rad =
      static_cast<float>(codec::ptu46::counts_to_rad(t.min_counts, t.arcsec_per_count));
  limits_.tilt_max_rad =
      static_cast<float>(codec::ptu46::counts_to_rad(t.max_counts, t.arcsec_per_count));
  limits_.pan_resolution_rad =
      static_cast<float>(codec::ptu46::counts_to_rad(1.0, p.arcsec_per_count));
  limits_.tilt_resolution_rad =
      static_cast<float>(codec::ptu46::counts_to_rad(1.0, t.arcsec_per_count));
  phase_ = Phase::kReady;
  next_liveness_us_ = clock_.now_us() + std::uint64_t{config_.idle_query_ms} * 1000U;
  state_.fault = false;
  error_[0] = '\0';
}

void PanTiltPtu46::refresh_state() {
  state_.pan_rad = static_cast<float>(
      codec::ptu46::counts_to_rad(axes_[0].position_counts, axes_[0].arcsec_per_count));
  state_.tilt_rad = static_cast<float>(
      codec::ptu46::counts_to_rad(axes_[1].position_counts, axes_[1].arcsec_per_count));
  state_.moving = axes_[0].moving || axes_[1].moving;
}

bool PanTiltPtu46::move_to(float pan_rad, float tilt_rad) {
  if (phase_ != Phase::kReady) return false;
  std::int32_t counts[2] = {0, 0};
  const float rad[2] = {pan_rad, tilt_rad};
  for (int i = 0; i < 2; ++i) {
    const AxisData& a = axes_[static_cast<std::size_t>(i)];
    if (!codec::ptu46::rad_to_counts(static_cast<double>(rad[i]), a.arcsec_per_count, counts[i]) ||
        counts[i] < a.min_counts || counts[i] > a.max_counts) {
      return false;
    }
  }
  drop_queued(Kind::kMove);  // a newer target replaces moves not yet sent
  if (kQueueCapacity - count_ < 2) return false;
  for (int i = 0; i < 2; ++i) {
    const Axis ax = i == 0 ? Axis::kPan : Axis::kTilt;
    Command c;
    c.kind = Kind::kMove;
    c.axis = ax;
    c.argument = counts[i];
    c.length = static_cast<std::uint8_t>(
        codec::ptu46::encode_position(ax, counts[i], c.text, sizeof c.text));
    push_back(c);
    AxisData& a = axis(ax);
    a.target_counts = counts[i];
    a.moving = a.position_counts != counts[i];
  }
  state_.fault = false;
  error_[0] = '\0';
  refresh_state();
  if (!state_.moving) {
    // Already there: still send the commands (cheap), but nothing to wait for.
  }
  return true;
}

void PanTiltPtu46::halt() {
  if (phase_ != Phase::kReady) return;
  drop_queued(Kind::kMove);
  drop_queued(Kind::kSpeed);
  Command c;
  c.kind = Kind::kHalt;
  c.length = static_cast<std::uint8_t>(
      codec::ptu46::encode_setting(Setting::kHalt, c.text, sizeof c.text));
  push_front(c);
}

bool PanTiltPtu46::set_speed(float pan_rad_s, float tilt_rad_s) {
  if (phase_ != Phase::kReady) return false;
  std::int32_t counts[2] = {0, 0};
  const float rad_s[2] = {pan_rad_s, tilt_rad_s};
  for (int i = 0; i < 2; ++i) {
    const AxisData& a = axes_[static_cast<std::size_t>(i)];
    if (!(rad_s[i] > 0.0F) ||
        !codec::ptu46::rad_to_counts(static_cast<double>(rad_s[i]), a.arcsec_per_count,
                                     counts[i]) ||
        counts[i] < 1 || (a.max_speed_counts_s > 0 && counts[i] > a.max_speed_counts_s)) {
      return false;
    }
  }
  drop_queued(Kind::kSpeed);
  if (kQueueCapacity - count_ < 2) return false;
  for (int i = 0; i < 2; ++i) {
    const Axis ax = i == 0 ? Axis::kPan : Axis::kTilt;
    Command c;
    c.kind = Kind::kSpeed;
    c.axis = ax;
    c.argument = counts[i];
    c.length =
        static_cast<std::uint8_t>(codec::ptu46::encode_speed(ax, counts[i], c.text, sizeof c.text));
    push_back(c);
  }
  return true;
}

bool PanTiltPtu46::reset() {
  if (phase_ != Phase::kReady) return false;
  drop_queued(Kind::kMove);
  for (AxisData& a : axes_) a.moving = true;
  refresh_state();
  return queue_setting(Setting::kReset, Kind::kReset);
}

bool PanTiltPtu46::await_move() {
  if (phase_ != Phase::kReady) return false;
  return queue_setting(Setting::kAwait, Kind::kAwait);
}

}  // namespace boticelli::hal_linux
