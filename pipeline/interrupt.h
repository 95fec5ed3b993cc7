// Stopping cleanly on SIGINT, SIGTERM and SIGHUP (Ctrl-C, `kill`, a closed terminal, ninja or the runner passing
// the signal on). Two ways to stop, because async-signal-unsafe work (freeing memory, writing files, printing) must
// not run inside a handler:
//  - A long loop (the simulation's time loop, the render's frame loop) runs in an InterruptPolling scope and calls
//    check_interrupt() between steps: the handler only sets a flag, the loop throws Interrupted at the next step and
//    the stack unwinds normally (AtomicFile destructors remove their temporary files; the simulation first writes a
//    checkpoint).
//  - Everywhere else (reading inputs, a library call that takes seconds, gnuplot), and at a second signal inside a
//    polling scope, the handler stops the process itself with async-signal-safe calls only: it kills the child
//    processes registered below, unlinks the temporary files registered below (every AtomicFile registers its
//    own) and calls _exit(128 + signal).
// Either way no file that looks finished is left half-written, and the exit status is 128 + the signal number
// (130 for SIGINT), as a shell reports a process killed by it.
#pragma once
#include <filesystem>
#include <string>
#include <sys/types.h>

#include "pipeline/error.h"

namespace floesim {

// Thrown by check_interrupt(): the process was asked to stop. Stage mains turn it into a message and exit code
// 128 + signal.
class Interrupted : public Error {
 public:
  // `detail` follows the signal in what(): e.g. where the simulation's checkpoint is.
  explicit Interrupted(int signal, const std::string& detail = "");
  int signal() const { return signal_; }

 private:
  int signal_;
};

// Installs the handlers for SIGINT, SIGTERM and SIGHUP (idempotent). Without SA_RESTART: a blocking call
// (waitpid, flock) returns EINTR, so that a waiting process sees the flag at once.
void install_interrupt_handlers();

// The first stop signal received (0: none).
int interrupt_signal();
// "SIGINT", "SIGTERM", "SIGHUP" or "signal N".
std::string signal_name(int signal);

// Throws Interrupted if a stop signal has arrived. Cheap (one atomic load): call it once per step or frame.
void check_interrupt();

// While one of these lives, a first stop signal only sets the flag (the code polls check_interrupt()) and is passed
// on to the registered children (the runner's ninja, which passes it on to the stages); a second one still stops
// the process at once.
class InterruptPolling {
 public:
  InterruptPolling();
  ~InterruptPolling();
  InterruptPolling(const InterruptPolling&) = delete;
  InterruptPolling& operator=(const InterruptPolling&) = delete;
};

// Temporary files the handler unlinks when it stops the process at once (AtomicFile registers its own). Up to 256
// at a time; paths longer than PATH_MAX are not registered (the runner removes such leftovers on its next run).
void register_temporary(const std::filesystem::path& p);
void unregister_temporary(const std::filesystem::path& p);

// Child processes the handler kills (SIGKILL) and reaps before it stops the process at once: their output files
// are among the temporary files, and must not be recreated after the unlink.
void register_child(pid_t pid);
void unregister_child(pid_t pid);

// Removes the temporary files an interrupted writer may have left in `dir` (not recursive): AtomicFile's
// ".tmp-<pid>-<name>" files. Only safe when no writer is at work in `dir` (the runner holds the run's lock).
// Returns how many were removed.
int remove_stale_temporaries(const std::filesystem::path& dir);

// True if `name` is an AtomicFile temporary name (".tmp-<pid>-<name>").
bool is_temporary_name(const std::string& name);

}  // namespace floesim
