#include "pipeline/interrupt.h"

#include <limits.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <mutex>

namespace floesim {

namespace {

std::atomic<int> g_signal{0};    // the first stop signal
std::atomic<int> g_count{0};     // stop signals received
std::atomic<int> g_polling{0};   // live InterruptPolling scopes

// Registries read by the handler. A slot is claimed (0 -> 2) by compare-exchange, filled, then published (2 -> 1);
// the handler reads published slots only. Lock-free atomics are async-signal-safe.
constexpr int kTempSlots = 256, kChildSlots = 16;
struct TempSlot {
  std::atomic<int> state{0};  // 0 free, 1 published, 2 being filled
  char path[PATH_MAX];
};
TempSlot g_temps[kTempSlots];
std::atomic<pid_t> g_children[kChildSlots];

static_assert(std::atomic<int>::is_always_lock_free && std::atomic<pid_t>::is_always_lock_free,
              "the signal handler needs lock-free atomics");

// Async-signal-safe only: kill, waitpid, unlink, _exit.
void stop_now(int sig) {
  for (auto& c : g_children) {
    const pid_t pid = c.load();
    if (pid > 0) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
  }
  for (auto& t : g_temps)
    if (t.state.load() == 1) ::unlink(t.path);
  ::_exit(128 + sig);
}

void on_stop_signal(int sig) {
  int expected = 0;
  g_signal.compare_exchange_strong(expected, sig);
  const int n = ++g_count;
  if (g_polling.load() > 0 && n == 1) {
    // The polling loop stops at its next check; children (the runner's ninja) are asked to stop as well.
    for (auto& c : g_children) {
      const pid_t pid = c.load();
      if (pid > 0) ::kill(pid, sig);
    }
    return;
  }
  stop_now(g_signal.load());
}

}  // namespace

Interrupted::Interrupted(int signal, const std::string& detail)
    : Error("interrupted by " + signal_name(signal) + (detail.empty() ? "" : "; " + detail)), signal_(signal) {}

void install_interrupt_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction sa;
    std::memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;  // no SA_RESTART: waitpid and flock return EINTR and the waiter looks at the flag
    for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaction(s, &sa, nullptr);
  });
}

int interrupt_signal() { return g_signal.load(); }

std::string signal_name(int signal) {
  switch (signal) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    case SIGKILL: return "SIGKILL";
    default: return "signal " + std::to_string(signal);
  }
}

void check_interrupt() {
  const int s = g_signal.load(std::memory_order_relaxed);
  if (s != 0) throw Interrupted(s);
}

InterruptPolling::InterruptPolling() { ++g_polling; }
InterruptPolling::~InterruptPolling() { --g_polling; }

void register_temporary(const std::filesystem::path& p) {
  const std::string s = p.string();
  if (s.size() >= PATH_MAX) return;
  for (auto& t : g_temps) {
    int expected = 0;
    if (!t.state.compare_exchange_strong(expected, 2)) continue;
    std::memcpy(t.path, s.c_str(), s.size() + 1);
    t.state.store(1);
    return;
  }
  // All slots taken: the file is still removed by its AtomicFile on any exception, and by the runner's next run
  // after a hard stop.
}

void unregister_temporary(const std::filesystem::path& p) {
  const std::string s = p.string();
  for (auto& t : g_temps)
    if (t.state.load() == 1 && s == t.path) {
      t.state.store(0);
      return;
    }
}

void register_child(pid_t pid) {
  for (auto& c : g_children) {
    pid_t expected = 0;
    if (c.compare_exchange_strong(expected, pid)) return;
  }
}

void unregister_child(pid_t pid) {
  for (auto& c : g_children) {
    pid_t expected = pid;
    if (c.compare_exchange_strong(expected, 0)) return;
  }
}

bool is_temporary_name(const std::string& name) {
  // ".tmp-" digits "-" rest
  if (name.rfind(".tmp-", 0) != 0) return false;
  size_t i = 5;
  while (i < name.size() && name[i] >= '0' && name[i] <= '9') ++i;
  return i > 5 && i < name.size() && name[i] == '-';
}

int remove_stale_temporaries(const std::filesystem::path& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return 0;
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    if (!is_temporary_name(e.path().filename().string())) continue;
    std::error_code rm;
    if (std::filesystem::remove(e.path(), rm)) ++n;
  }
  return n;
}

}  // namespace floesim
