#include "interrupt_request.h"

#include <unistd.h>

#include <csignal>

namespace dgtex::cli {
namespace {

volatile std::sig_atomic_t received_signal = 0;
struct sigaction previous_sigint, previous_sigterm;

extern "C" void note_interrupt(int signal) {
  received_signal = signal;
  // write() is safe in a handler; the step may take a while, so say at once what happens.
  static const char message[] =
      "\ndgtex run: interrupted: ending after this step and writing the results (interrupt again to stop at "
      "once)\n";
  [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, message, sizeof message - 1);
}

}  // namespace

InterruptRequest::InterruptRequest() {
  received_signal = 0;
  struct sigaction action {};
  action.sa_handler = note_interrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;  // the second signal takes the default action: the process ends
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
