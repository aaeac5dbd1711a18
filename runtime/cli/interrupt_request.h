#pragma once
// Ctrl-C (SIGINT) or a batch system's time limit (SIGTERM) during a long run. The first
// signal is only noted, so that the run can end after its current step and still write
// its frames, mesh and report; the handlers then fall back to the default, so a second
// signal ends the process at once.
namespace dgtex::cli {

class InterruptRequest {
 public:
  InterruptRequest();   // catches SIGINT and SIGTERM from now on
  ~InterruptRequest();  // restores the handlers there were before
  InterruptRequest(const InterruptRequest&) = delete;
  InterruptRequest& operator=(const InterruptRequest&) = delete;

  // The signal that asked the run to stop (SIGINT or SIGTERM), 0 while none did.
  int signal() const;
};

// "SIGINT" or "SIGTERM" (the two signals InterruptRequest catches).
const char* signal_name(int signal);

}  // namespace dgtex::cli
