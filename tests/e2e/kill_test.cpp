// The kill test (issue #13, "interrupted runs"): `floesim run` is stopped at random moments of every stage, by
// SIGINT, by SIGKILL of the runner alone, and by SIGKILL of every process of the run at once (a crash: nothing can
// clean up), and then run again, half of the time with --resume. After every kill, every artefact present must be
// whole: byte-identical to the same artefact of an uninterrupted run (the stages are deterministic, so a present
// file that differs is half-written or wrong) and readable by an independent reader (JSON parser, HDF5 results
// reader, PNG decoder, ffprobe for the video); after SIGINT the runner must say which stage it stopped and leave no
// temporary file. The next run must finish, and its artefacts must be byte-identical to the uninterrupted run's.
//
//   kill_test [--kills N] [--seed S] [--case DIR] [--work DIR] [--bin DIR]
//
// N kills (default 50) round-robin over the stages and the three ways to kill; prints the figures; exit status 0
// only if nothing was found half-written, every recovery finished and matched. tests/e2e/kill-test runs it with 50
// kills, ctest (kill_test_short) with 6.
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pipeline/results_io.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;
using floesim::tests::read_text;
using Clock = std::chrono::steady_clock;

namespace {

const std::vector<std::string> kStages = {"synth", "digitise", "hull", "simulate", "render", "plot", "report"};
// The main artefact of each stage, as named in the run's .ninja_log (for the reference's stage durations).
const std::map<std::string, std::string> kMainOutput = {
    {"synth", "image/image.png"},   {"digitise", "floes/floes.geojson"}, {"hull", "hull/hull.obj"},
    {"simulate", "sim/results.h5"}, {"render", "video/transit.mp4"},   {"plot", "plots/surge_ice_load.png"},
    {"report", "report/report.html"}};

enum class Kill { sigint, sigkill_runner, sigkill_all };
const char* kill_name(Kill k) {
  switch (k) {
    case Kill::sigint: return "SIGINT to the runner";
    case Kill::sigkill_runner: return "SIGKILL to the runner alone";
    default: return "SIGKILL to every process of the run";
  }
}

// Starts `args` in a new session (so that every process of the run can be found), output into `log`.
pid_t spawn(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> a = args;
  std::vector<char*> argv;
  for (auto& s : a) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::cout.flush();
  const pid_t pid = fork();
  if (pid == 0) {
    setsid();
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    close(fd);
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

// Waits for a child; its exit code (128 + signal if killed), or -1 after `timeout_s`.
int wait_for(pid_t pid, double timeout_s) {
  const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    int status = 0;
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (r < 0) return -1;
    if (Clock::now() > end) return -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

struct Proc {
  pid_t pid;
  std::string cmdline;
};

// The processes of session `sid` (/proc/PID/stat: pid (comm) state ppid pgrp session ...).
std::vector<Proc> session(pid_t sid) {
  std::vector<Proc> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string stat = read_text(e.path() / "stat");
    const size_t close = stat.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream is(stat.substr(close + 1));
    char state = 0;
    long ppid = 0, pgrp = 0, sess = 0;
    if (!(is >> state >> ppid >> pgrp >> sess) || sess != sid || state == 'Z') continue;
    std::string cmd = read_text(e.path() / "cmdline");
    for (char& c : cmd)
      if (c == '\0') c = ' ';
    out.push_back({static_cast<pid_t>(std::stol(name)), cmd});
  }
  return out;
}

// The descendants of `pid` from /proc/PID/task/*/children (a few small reads: cheap enough to poll).
std::vector<pid_t> descendants(pid_t pid) {
  std::vector<pid_t> out, todo = {pid};
  while (!todo.empty()) {
    const pid_t p = todo.back();
    todo.pop_back();
    std::error_code ec;
    for (const auto& t : fs::directory_iterator("/proc/" + std::to_string(p) + "/task", ec)) {
      std::ifstream in(t.path() / "children");
      for (long c; in >> c;) {
        out.push_back(static_cast<pid_t>(c));
        todo.push_back(static_cast<pid_t>(c));
      }
    }
  }
  return out;
}

// The stages whose executables run under the runner `pid` (none: the runner between stages, or nothing).
std::vector<std::string> running_stages(pid_t pid, const fs::path& bin) {
  std::vector<std::string> out;
  for (pid_t d : descendants(pid)) {
    std::string cmd = read_text("/proc/" + std::to_string(d) + "/cmdline");
    for (char& c : cmd)
      if (c == '\0') c = ' ';
    for (const std::string& s : kStages)
      if (cmd.rfind((bin / ("floesim-" + s)).string() + " ", 0) == 0) out.push_back(s);
  }
  return out;
}
bool runs(const std::vector<std::string>& stages, const std::string& s) {
  return std::find(stages.begin(), stages.end(), s) != stages.end();
}

// Waits until no process holds the run's lock (the runner, ninja and the stages all hold it); false on timeout.
bool wait_lock_free(const fs::path& run, double timeout_s) {
  const fs::path lock = run / ".floesim.lock";
  if (!fs::exists(lock)) return true;
  const int fd = open(lock.c_str(), O_RDWR);
  if (fd < 0) return true;
  const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  bool ok = false;
  while (Clock::now() < end) {
    if (flock(fd, LOCK_EX | LOCK_NB) == 0) {
      flock(fd, LOCK_UN);
      ok = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  close(fd);
  return ok;
}

bool is_temporary(const fs::path& p) { return p.filename().string().rfind(".tmp-", 0) == 0; }
// The runner's bookkeeping (ninja's log, the lock): not artefacts.
bool is_bookkeeping(const fs::path& rel) {
  const std::string n = rel.filename().string();
  return n == ".ninja_log" || n == ".ninja_deps" || n == ".floesim.lock";
}
bool in_checkpoint(const fs::path& rel) { return rel.string().find("checkpoint/") != std::string::npos; }

// Files of a run folder, relative to it.
std::vector<fs::path> files(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); it != fs::recursive_directory_iterator(); ++it)
    if (it->is_regular_file()) out.push_back(fs::relative(it->path(), dir));
  return out;
}

// An independent reader's verdict on a file ("" = whole).
std::string read_problem(const fs::path& p, const std::string& expected_frames) {
  const std::string ext = p.extension().string();
  try {
    if (ext == ".json" || ext == ".geojson") {
      const nlohmann::json j = nlohmann::json::parse(read_text(p));
      (void)j;
    } else if (ext == ".h5") {
      floesim::read_results(p);
    } else if (ext == ".png") {
      if (cv::imread(p.string(), cv::IMREAD_UNCHANGED).empty()) return "does not decode as PNG";
    } else if (ext == ".mp4") {
      const std::string cmd = "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
                              "stream=nb_read_frames -of csv=p=0 '" + p.string() + "' 2>&1";
      FILE* f = popen(cmd.c_str(), "r");
      std::string out;
      char buf[256];
      while (f && std::fgets(buf, sizeof buf, f)) out += buf;
      const int rc = f ? pclose(f) : -1;
      while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
      if (rc != 0 || out != expected_frames) return "ffprobe: '" + out + "', expected " + expected_frames + " frames";
    } else if (ext == ".svg" || ext == ".html") {
      const std::string t = read_text(p);
      const std::string end = ext == ".svg" ? "</svg>" : "</html>";
      if (t.find(end) == std::string::npos) return "has no " + end;
    }
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

struct Figures {
  std::map<std::string, int> per_stage;  // stage running at the kill ("between stages" if none)
  std::map<Kill, int> per_kill;
  int kills = 0, missed = 0;            // missed: the run had ended before the kill
  int sigint_messages_ok = 0;
  int recoveries = 0, with_resume = 0, resumed_from_checkpoint = 0, recovery_failed = 0;
  int incomplete = 0;                    // artefacts found half-written or wrong after a kill
  int temporaries_clean_kill = 0;        // temporary files left after SIGINT or SIGKILL of the runner alone
  int temporaries_crash = 0;             // ... after SIGKILL of every process (a crash): removed by the next run
  int mismatches = 0;                    // artefacts of a recovery differing from the uninterrupted run
  std::vector<std::string> problems;
};

struct Test {
  fs::path bin, case_dir, work, run, ref;
  std::map<std::string, double> stage_s;  // the reference's stage durations
  double total_s = 0;
  std::string video_frames;
  std::mt19937 rng;
  Figures f;
  std::string last_kill_;  // the last kill, for the message of a recovery that fails

  std::vector<std::string> run_args(bool resume) const {
    std::vector<std::string> a = {(bin / "floesim").string(), "run", case_dir.string(), "--out", run.string()};
    if (resume) a.push_back("--resume");
    return a;
  }

  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }

  void reference() {
    fs::remove_all(run);
    const auto t0 = Clock::now();
    const pid_t pid = spawn(run_args(false), work / "reference.log");
    const int rc = wait_for(pid, 600);
    total_s = std::chrono::duration<double>(Clock::now() - t0).count();
    if (rc != 0) throw std::runtime_error("the uninterrupted reference run failed:\n" + read_text(work / "reference.log"));
    fs::remove_all(ref);
    fs::create_directories(ref);
    for (const fs::path& rel : files(run)) {
      if (is_bookkeeping(rel)) continue;
      fs::create_directories((ref / rel).parent_path());
      fs::copy_file(run / rel, ref / rel);
    }
    // Stage durations from ninja's log: "start_ms end_ms mtime path hash".
    std::istringstream log(read_text(run / ".ninja_log"));
    for (std::string line; std::getline(log, line);) {
      std::istringstream is(line);
      long start = 0, end = 0, mt = 0;
      std::string path;
      if (!(is >> start >> end >> mt >> path)) continue;
      for (const auto& [stage, out] : kMainOutput)
        if (path == (run / out).string()) stage_s[stage] = (end - start) / 1000.0;
    }
    const std::string probe = read_problem(ref / "video/transit.mp4", "?");
    const size_t at = probe.find("'");
    video_frames = probe.substr(at + 1, probe.find("'", at + 1) - at - 1);
  }

  // Starts a run and stops it: at a random moment of stage `target` (or, if empty, at a random moment of the
  // whole run) with `how`. Then checks what it left.
  void kill_run(bool resume, const std::string& target, Kill how) {
    const pid_t pid = spawn(run_args(resume), work / "killed.log");
    std::string at;
    bool ended = false;
    if (!target.empty()) {
      // Wait for the stage to start, then a random part of its reference duration.
      const auto end = Clock::now() + std::chrono::seconds(120);
      while (!runs(running_stages(pid, bin), target) && Clock::now() < end) {
        if (waitpid(pid, nullptr, WNOHANG) == pid) {
          ended = true;
          break;
        }
        std::this_thread::sleep_for(std::chrono::microseconds(300));
      }
      if (!ended) std::this_thread::sleep_for(std::chrono::duration<double>(uniform(0, stage_s[target])));
    } else {
      std::this_thread::sleep_for(std::chrono::duration<double>(uniform(0, total_s)));
    }
    std::vector<std::string> now;  // the stages running at the kill (synth, digitise and hull, or render and plot,
                                   // run side by side)
    if (!ended) {
      now = running_stages(pid, bin);
      at = now.empty() ? "" : runs(now, target) ? target : now.front();
    }
    if (ended || waitpid(pid, nullptr, WNOHANG) == pid) {
      ++f.missed;  // the run ended first: nothing to kill
      return;
    }
    ++f.kills;
    ++f.per_kill[how];
    last_kill_ = std::string(kill_name(how)) + " during " + (at.empty() ? "no stage" : at);
    ++f.per_stage[at.empty() ? "between stages" : at];
    if (how == Kill::sigint) {
      kill(pid, SIGINT);
      const int rc = wait_for(pid, 120);
      const std::string log = read_text(work / "killed.log");
      // The message is checked only when the stage was seen running at the kill (the runner may see it end first).
      std::string line;
      for (std::istringstream ls(log); std::getline(ls, line);)
        if (line.find("interrupted by SIGINT") != std::string::npos && line.rfind("floesim:", 0) == 0) break;
      // It must name a stage that ran at the kill (any of them), or say "between stages" when the stages it saw
      // had ended by the time it looked.
      bool names = now.empty() || line.find("between stages") != std::string::npos;
      for (const std::string& st : now)
        names = names || (line.find("during stage") != std::string::npos && line.find(st) != std::string::npos);
      if (rc == 130 && names && log.find("interrupted by SIGINT") != std::string::npos &&
          log.find("nothing half-written left") != std::string::npos)
        ++f.sigint_messages_ok;
      else
        f.problems.push_back("SIGINT during " + at + ": exit " + std::to_string(rc) + ", output:\n" + log);
    } else if (how == Kill::sigkill_runner) {
      kill(pid, SIGKILL);
      wait_for(pid, 60);
    } else {
      // Every process of the session, until none is left (ninja may start one between two looks).
      for (int round = 0; round < 200; ++round) {
        const std::vector<Proc> ps = session(pid);
        if (ps.empty()) break;
        for (const Proc& p : ps) kill(p.pid, SIGKILL);
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
      wait_for(pid, 60);
    }
    // The remains of a killed runner stop (its ninja gets SIGTERM): wait until they have let go of the run.
    if (!wait_lock_free(run, 120)) f.problems.push_back("after " + std::string(kill_name(how)) + " during " + at +
                                                        ": processes of the run still hold its lock after 120 s");
    check_after_kill(how, at);
  }

  void check_after_kill(Kill how, const std::string& at) {
    for (const fs::path& rel : files(run)) {
      const fs::path p = run / rel;
      if (is_temporary(rel)) {
        if (how == Kill::sigkill_all) {
          ++f.temporaries_crash;
        } else {
          ++f.temporaries_clean_kill;
          f.problems.push_back(std::string(kill_name(how)) + " during " + at + " left a temporary file " + rel.string());
        }
        continue;
      }
      if (is_bookkeeping(rel)) continue;
      std::string problem;
      if (in_checkpoint(rel)) {
        if (rel.extension() == ".json") problem = read_problem(p, video_frames);  // the .bin files carry a SHA-256
      } else if (!fs::exists(ref / rel)) {
        problem = "is not an artefact of the uninterrupted run";
      } else if (read_text(p) != read_text(ref / rel)) {
        problem = "differs from the uninterrupted run's (half-written?)";
      } else {
        problem = read_problem(p, video_frames);
      }
      if (!problem.empty()) {
        ++f.incomplete;
        f.problems.push_back("after " + std::string(kill_name(how)) + " during " + at + ": " + rel.string() + " " +
                             problem);
      }
    }
  }

  // Runs to the end and compares every artefact with the uninterrupted run's.
  void recover(bool resume) {
    ++f.recoveries;
    f.with_resume += resume;
    const pid_t pid = spawn(run_args(resume), work / "recovery.log");
    const int rc = wait_for(pid, 600);
    const std::string log = read_text(work / "recovery.log");
    if (rc != 0) {
      ++f.recovery_failed;
      // What else ran then (to look into it): the processes of floesim's stages and ninja on this machine.
      std::string ps;
      if (FILE* p = popen("ps -eo pid,ppid,pgid,sid,etimes,args | grep -E 'floesim|ninja' | grep -v grep", "r")) {
        char buf[512];
        while (std::fgets(buf, sizeof buf, p)) ps += buf;
        pclose(p);
      }
      f.problems.push_back("the run after a kill (" + last_kill_ + ") failed (exit " + std::to_string(rc) + "):\n" +
                           log + "processes:\n" + ps);
      return;
    }
    if (log.find("--resume: continuing from the checkpoint") != std::string::npos) ++f.resumed_from_checkpoint;
    std::set<fs::path> seen;
    for (const fs::path& rel : files(run)) {
      if (is_bookkeeping(rel)) continue;
      seen.insert(rel);
      if (!fs::exists(ref / rel) || read_text(run / rel) != read_text(ref / rel)) {
        ++f.mismatches;
        f.problems.push_back("after the recovery run " + rel.string() +
                             (fs::exists(ref / rel) ? " differs from the uninterrupted run's"
                                                    : " is not in the uninterrupted run (a leftover)"));
      }
    }
    for (const fs::path& rel : files(ref))
      if (!seen.count(rel)) {
        ++f.mismatches;
        f.problems.push_back("after the recovery run " + rel.string() + " is missing");
      }
  }

  void iteration(int i) {
    fs::remove_all(run);  // a fresh run folder, at the reference's path (artefacts name their folder)
    std::string target = kStages[static_cast<size_t>(i) % kStages.size()];
    Kill how = static_cast<Kill>(i % 3);
    if (const char* only = std::getenv("KILL_TEST_ONLY")) {  // STAGE:MODE (0 SIGINT, 1 SIGKILL runner, 2 all): a
      const std::string o = only;                             // scenario repeated, to look into a failure
      target = o.substr(0, o.find(':'));
      how = static_cast<Kill>(std::stoi(o.substr(o.find(':') + 1)));
    }
    kill_run(false, target, how);
    if (std::getenv("KILL_TEST_VERBOSE")) std::cout << "    target " << target << ", " << kill_name(how) << "\n";
    // Now and then the recovery itself is stopped too (at a random moment of the whole run), then run again.
    if (std::bernoulli_distribution(0.25)(rng)) {
      const Kill again = static_cast<Kill>(std::uniform_int_distribution<int>(0, 2)(rng));
      kill_run(std::bernoulli_distribution(0.5)(rng), "", again);
    }
    recover(std::bernoulli_distribution(0.5)(rng));
  }

  void print(std::ostream& os, int iterations, unsigned seed) const {
    os << "\nkill test: " << f.kills << " kills in " << iterations << " runs started (seed " << seed << ", case "
       << case_dir.string() << "; uninterrupted run " << std::fixed;
    os.precision(2);
    os << total_s << " s: ";
    for (const std::string& s : kStages) os << s << " " << stage_s.at(s) << " s" << (s == "report" ? "" : ", ");
    os << ")\n  kills per stage:";
    for (const auto& [s, n] : f.per_stage) os << " " << s << " " << n << ";";
    os << "\n  kills per signal:";
    for (Kill k : {Kill::sigint, Kill::sigkill_runner, Kill::sigkill_all})
      os << " " << kill_name(k) << " " << (f.per_kill.count(k) ? f.per_kill.at(k) : 0) << ";";
    os << "\n  runs that ended before the kill came: " << f.missed
       << "\n  SIGINT: runner exited 130 with the message naming the stage: " << f.sigint_messages_ok << " of "
       << (f.per_kill.count(Kill::sigint) ? f.per_kill.at(Kill::sigint) : 0)
       << "\n  artefacts found half-written or wrong after a kill: " << f.incomplete
       << "\n  temporary files left after SIGINT or SIGKILL of the runner: " << f.temporaries_clean_kill
       << "\n  temporary files left after SIGKILL of every process (removed by the next run): " << f.temporaries_crash
       << "\n  recovery runs: " << f.recoveries << " (" << f.with_resume << " with --resume, "
       << f.resumed_from_checkpoint << " of them continued from a checkpoint), failed: " << f.recovery_failed
       << "\n  artefacts of a recovery differing from the uninterrupted run: " << f.mismatches << "\n";
  }
};

}  // namespace

int main(int argc, char** argv) {
  int kills = 50;
  unsigned seed = 13;
  fs::path case_dir = fs::path(FLOESIM_SOURCE_DIR) / "tests" / "e2e" / "kill";
  fs::path bin = FLOESIM_BIN_DIR;
  fs::path work = fs::temp_directory_path() / ("floesim_kill_" + std::to_string(getpid()));
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--kills") kills = std::stoi(v);
    else if (a == "--seed") seed = static_cast<unsigned>(std::stoul(v));
    else if (a == "--case") case_dir = fs::absolute(v);
    else if (a == "--work") work = fs::absolute(v);
    else if (a == "--bin") bin = fs::absolute(v);
    else {
      std::cerr << "usage: kill_test [--kills N] [--seed S] [--case DIR] [--work DIR] [--bin DIR]\n";
      return 2;
    }
  }
  Test t;
  t.bin = bin;
  t.case_dir = case_dir;
  t.work = work;
  t.run = work / "run";
  t.ref = work / "reference";
  t.rng.seed(seed);
  fs::create_directories(work);
  try {
    t.reference();
    std::cout << "kill test: reference run in " << t.total_s << " s; " << kills << " kills follow\n" << std::flush;
    int i = 0;
    for (; t.f.kills < kills && i < 3 * kills; ++i) {
      t.iteration(i);
      std::cout << "  run " << i + 1 << ": " << t.f.kills << " kills so far, " << t.f.problems.size()
                << " problems\n" << std::flush;
    }
    t.print(std::cout, i, seed);
  } catch (const std::exception& e) {
    std::cerr << "kill test: " << e.what() << "\n";
    return 1;
  }
  for (const std::string& p : t.f.problems) std::cout << "PROBLEM: " << p << "\n";
  const bool ok = t.f.problems.empty() && t.f.incomplete == 0 && t.f.mismatches == 0 && t.f.recovery_failed == 0 &&
                  t.f.temporaries_clean_kill == 0 && t.f.kills >= kills;
  std::cout << (ok ? "kill test passed\n" : "kill test FAILED\n");
  if (ok) fs::remove_all(work);
  return ok ? 0 : 1;
}
