#include "pipeline/runner/process.h"

#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <iostream>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/interrupt.h"

namespace fs = std::filesystem;

namespace floesim::runner {

Child spawn_piped(const std::vector<std::string>& args, const std::vector<std::pair<std::string, std::string>>& env) {
  int fd[2];
  FLOESIM_REQUIRE(pipe(fd) == 0, "cannot create a pipe to run ", args[0]);
  std::vector<std::string> a = args;
  std::vector<char*> argv;
  for (auto& s : a) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::cout.flush();
  const pid_t parent = getpid();
  const pid_t pid = fork();
  FLOESIM_REQUIRE(pid >= 0, "cannot start ", args[0], ": fork failed");
  if (pid == 0) {
    // If the runner is killed outright, the child is told to stop (ninja passes it on to the stages).
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(128 + SIGTERM);
    dup2(fd[1], 1);
    dup2(fd[1], 2);
    close(fd[0]);
    close(fd[1]);
    for (const auto& [k, v] : env) setenv(k.c_str(), v.c_str(), 1);
    execvp(argv[0], argv.data());
    std::fprintf(stderr, "floesim: cannot execute %s (is it installed?)\n", argv[0]);
    _exit(127);
  }
  close(fd[1]);
  register_child(pid);  // a stop signal is passed on to it (pipeline/interrupt.h)
  return {pid, fdopen(fd[0], "r")};
}

// Closes the pipe and waits: the exit status (128 + the signal if killed).
int wait_child(Child& c) {
  std::fclose(c.out);
  int status = 0;
  while (waitpid(c.pid, &status, 0) < 0 && errno == EINTR) {
  }
  unregister_child(c.pid);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

// One line from a child's pipe; false at its end. A stop signal (EINTR) does not end it: the child is told too,
// and its last lines still come; `on_signal` (if any) runs at once, while the child's children are still stopping.
bool read_line(FILE* in, char* line, int size, const std::function<void()>& on_signal) {
  for (;;) {
    if (std::fgets(line, size, in)) return true;
    if (!std::ferror(in) || errno != EINTR) return false;
    std::clearerr(in);
    if (on_signal) on_signal();
  }
}

// Runs a program and collects its output.
Output run_capture(const std::vector<std::string>& args) {
  Child c = spawn_piped(args);
  Output out;
  char buf[4096];
  while (read_line(c.out, buf, sizeof buf)) out.text += buf;
  out.code = wait_child(c);
  return out;
}

namespace {

// One stage's check (see stage_settings_problems), its copy written into `tmp_dir`.
std::string settings_problems(const PlannedStage& st, const fs::path& tmp_dir) {
  const fs::path cfg = tmp_dir / (st.name + "-" + st.key + ".json");
  write_text_atomic(cfg, st.config_text);
  const Output r = run_capture({st.exe.string(), "--check-config", "--config", cfg.string()});
  if (r.code == 0) return "";
  std::string msg = r.text;
  while (!msg.empty() && msg.back() == '\n') msg.pop_back();
  // The stage's own prefix ("floesim-simulate: error: ") and the copy's name give way to the case's.
  const std::string prefix = st.exe.filename().string() + ": error: ";
  if (msg.rfind(prefix, 0) == 0) msg.erase(0, prefix.size());
  const std::string copy = cfg.string() + ": ";
  for (size_t at; (at = msg.find(copy)) != std::string::npos;) msg.erase(at, copy.size());
  // Each listed problem ("\n  - key ...") names its key from the stage's settings: prefixed with their section.
  if (!st.section.empty()) {
    const std::string item = "\n  - ";
    for (size_t at = msg.find(item); at != std::string::npos; at = msg.find(item, at + item.size()))
      msg.insert(at + item.size(), st.section + ".");
  }
  return msg;
}

}  // namespace

std::vector<std::string> stage_settings_problems(const std::vector<PlannedStage>& stages) {
  const fs::path tmp = fs::temp_directory_path() / ("floesim-check-" + std::to_string(getpid()));
  ensure_directory(tmp);
  std::vector<std::string> problems;
  try {
    for (const PlannedStage& st : stages) problems.push_back(settings_problems(st, tmp));
  } catch (...) {
    fs::remove_all(tmp);
    throw;
  }
  fs::remove_all(tmp);
  return problems;
}

}  // namespace floesim::runner
