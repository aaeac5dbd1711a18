#include "interrupt_request.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>

namespace dgtex::cli {
namespace {

// The first signal. Lock-free, so a handler may use it; exchanged, as the two signals may
// be handled at once on two of the process's threads.
std::atomic<int> received_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);
struct sigaction previous_sigint, previous_sigterm;

extern "C" void note_interrupt(int signal) {
  const int saved_errno = errno;
  // Either signal next takes the default action (the process ends): SA_RESETHAND reset the
  // delivered signal's handler only, so a SIGTERM after Ctrl-C was merely noted until
  // session 72. sigaction, raise and write are async-signal-safe.
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  sigaction(SIGINT, &default_action, nullptr);
  sigaction(SIGTERM, &default_action, nullptr);
  int none = 0;
  if (!received_signal.compare_exchange_strong(none, signal)) {
    // A second signal that reached this handler before the reset (on another thread): sent
    // again, it waits while this handler blocks it and then takes the default action.
    std::raise(signal);
    errno = saved_errno;
    return;
  }
  // The step may take a while, so say at once what happens.
  static const char message[] =
      "\ndgtex run: interrupted: ending after this step and writing the results (interrupt again to stop at "
      "once)\n";
  [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, message, sizeof message - 1);
  errno = saved_errno;
}

}  // namespace

InterruptRequest::InterruptRequest() {
  received_signal.store(0);
  struct sigaction action {};
  action.sa_handler = note_interrupt;
  sigemptyset(&action.sa_mask);
  sigaddset(&action.sa_mask, SIGINT);
  sigaddset(&action.sa_mask, SIGTERM);
  sigaction(SIGINT, &action, &previous_sigint);
  sigaction(SIGTERM, &action, &previous_sigterm);
}

InterruptRequest::~InterruptRequest() {
  sigaction(SIGINT, &previous_sigint, nullptr);
  sigaction(SIGTERM, &previous_sigterm, nullptr);
}

int InterruptRequest::signal() const { return received_signal; }

const char* signal_name(int signal) { return signal == SIGINT ? "SIGINT" : "SIGTERM"; }

}  // namespace dgtex::cli
