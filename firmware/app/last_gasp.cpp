// LastGasp: fatal-signal handlers that brake the base before the process dies.
#include "firmware/app/last_gasp.h"

#include <signal.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstddef>

namespace boticelli::firmware {
namespace {

constexpr std::array<int, 5> kFatalSignals{SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT};
// The handler's own stack: a stack overflow leaves none to run on. Fixed, static (no
// allocation), larger than MINSIGSTKSZ everywhere we build.
alignas(16) std::array<std::byte, 64 * 1024> g_alt_stack;
std::atomic<hal::Base*> g_base{nullptr};
std::array<struct sigaction, kFatalSignals.size()> g_previous{};
stack_t g_previous_stack{};

std::size_t signal_index(int signal) {
  for (std::size_t i = 0; i < kFatalSignals.size(); ++i) {
    if (kFatalSignals[i] == signal) return i;
  }
  return 0;
}

extern "C" void on_fatal_signal(int signal, siginfo_t* info, void* /*context*/) {
  const int saved_errno = errno;
  // One gasp: a second fatal signal inside the first (the base's write faulting) finds none.
  hal::Base* base = g_base.exchange(nullptr);
  if (base != nullptr) base->last_gasp_stop();
  // The handler found at arm() takes over (the default action, or a sanitizer's report).
  (void)::sigaction(signal, &g_previous[signal_index(signal)], nullptr);
  errno = saved_errno;
  // A fault the kernel raised (a bad access, a bad instruction) happens again when the
  // instruction re-executes, with its own siginfo; a signal sent (abort(), kill) is sent again.
  if (info == nullptr || info->si_code <= 0) (void)::raise(signal);
}

}  // namespace

bool LastGasp::arm(hal::Base& base) {
  hal::Base* expected = nullptr;
  if (armed_ || !g_base.compare_exchange_strong(expected, &base)) return false;
  stack_t stack{};
  stack.ss_sp = g_alt_stack.data();
  stack.ss_size = g_alt_stack.size();
  stack.ss_flags = 0;
  if (::sigaltstack(&stack, &g_previous_stack) != 0) {
    g_base.store(nullptr);
    return false;
  }
  struct sigaction action {};
  action.sa_sigaction = on_fatal_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_SIGINFO | SA_ONSTACK | SA_NODEFER;
  for (std::size_t i = 0; i < kFatalSignals.size(); ++i) {
    ::sigaction(kFatalSignals[i], &action, &g_previous[i]);
  }
  armed_ = true;
  return true;
}

void LastGasp::disarm() {
  if (!armed_) return;
  for (std::size_t i = 0; i < kFatalSignals.size(); ++i) {
    ::sigaction(kFatalSignals[i], &g_previous[i], nullptr);
  }
  (void)::sigaltstack(&g_previous_stack, nullptr);
  g_base.store(nullptr);
  armed_ = false;
}

}  // namespace boticelli::firmware
