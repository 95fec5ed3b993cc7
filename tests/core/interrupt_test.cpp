// Stopping on a signal without leaving a half-written file (pipeline/interrupt.h), and the checked writes of
// pipeline/atomic_file.h. The signal tests run in a forked child, whose exit status and leftovers the parent reads.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/interrupt.h"
#include "pipeline/runner/plan.h"
#include "tests/test_util.h"

using namespace floesim;
namespace fs = std::filesystem;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("floesim_interrupt_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::set<std::string> names(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

int exit_code(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

using floesim::tests::error_of;

}  // namespace

TEST(Interrupt, TemporaryNamesAreAtomicFilesOnly) {
  EXPECT_TRUE(is_temporary_name(".tmp-123-results.h5"));
  EXPECT_TRUE(is_temporary_name(".tmp-0-wall_ms"));
  EXPECT_FALSE(is_temporary_name(".tmp--results.h5"));
  EXPECT_FALSE(is_temporary_name(".tmp-12x-a"));
  EXPECT_FALSE(is_temporary_name(".tmp-12"));
  EXPECT_FALSE(is_temporary_name("results.h5"));
  EXPECT_FALSE(is_temporary_name("a.tmp-1-b"));
}

TEST(Interrupt, StaleTemporariesAreRemovedAndNothingElse) {
  const fs::path d = fresh_dir("stale");
  for (const char* f : {".tmp-17-a.png", ".tmp-4242-results.h5", "results.h5", "floes.tmp-link", ".tmp-x"})
    std::ofstream(d / f) << "x";
  EXPECT_EQ(remove_stale_temporaries(d), 2);
  EXPECT_EQ(names(d), (std::set<std::string>{"results.h5", "floes.tmp-link", ".tmp-x"}));
  EXPECT_EQ(remove_stale_temporaries(d / "absent"), 0);
  fs::remove_all(d);
}

// Outside a polling loop, SIGINT ends the process at once: exit 130, the unfinished AtomicFile's temporary removed,
// the registered child killed, the finished files kept.
TEST(Interrupt, OutsideAPollingLoopSigintRemovesTemporariesKillsChildrenAndExits130) {
  const fs::path d = fresh_dir("hard");
  int pipefd[2];
  ASSERT_EQ(pipe(pipefd), 0);
  const pid_t pid = fork();
  if (pid == 0) {
    install_interrupt_handlers();
    write_text_atomic(d / "done.json", "{}\n");
    AtomicFile f(d / "half.h5");
    std::ofstream(f.tmp()) << "half of it";
    const pid_t sleeper = fork();
    if (sleeper == 0) {
      execlp("sleep", "sleep", "60", nullptr);
      _exit(127);
    }
    register_child(sleeper);
    (void)!write(pipefd[1], &sleeper, sizeof sleeper);
    raise(SIGINT);
    _exit(0);  // not reached
  }
  close(pipefd[1]);
  pid_t sleeper = 0;
  ASSERT_EQ(read(pipefd[0], &sleeper, sizeof sleeper), static_cast<ssize_t>(sizeof sleeper));
  close(pipefd[0]);
  EXPECT_EQ(exit_code(pid), 130);
  EXPECT_EQ(names(d), std::set<std::string>{"done.json"});
  EXPECT_NE(kill(sleeper, 0), 0) << "the registered child outlived the stop";
  fs::remove_all(d);
}

// In a polling loop the first SIGINT is a flag (the loop throws Interrupted at its next check and unwinds); a second
// one stops the process at once.
TEST(Interrupt, InAPollingLoopTheFirstSigintIsAFlagTheSecondStopsAtOnce) {
  const fs::path d = fresh_dir("poll");
  int pipefd[2];
  ASSERT_EQ(pipe(pipefd), 0);
  const pid_t pid = fork();
  if (pid == 0) {
    install_interrupt_handlers();
    InterruptPolling polling;
    AtomicFile f(d / "video.mp4");
    std::ofstream(f.tmp()) << "frames";
    raise(SIGINT);
    char seen = '0';
    try {
      check_interrupt();
    } catch (const Interrupted& e) {
      seen = e.signal() == SIGINT && interrupt_signal() == SIGINT && fs::exists(f.tmp()) ? '1' : '2';
    }
    (void)!write(pipefd[1], &seen, 1);
    raise(SIGINT);
    _exit(0);  // not reached
  }
  close(pipefd[1]);
  char seen = 0;
  ASSERT_EQ(read(pipefd[0], &seen, 1), 1);
  close(pipefd[0]);
  EXPECT_EQ(seen, '1') << "the first SIGINT must be seen by check_interrupt, with the temporary still there";
  EXPECT_EQ(exit_code(pid), 130);
  EXPECT_TRUE(names(d).empty());
  fs::remove_all(d);
}

// /dev/full answers every write with ENOSPC: the error names the file, the reason and the fix.
TEST(AtomicFile, AFullDiskIsAnErrorNamingTheFileAndTheFix) {
  const std::string e = error_of([] { write_file_checked("/dev/full", std::string(100000, 'x'), "run/sim/summary.json"); });
  EXPECT_NE(e.find("run/sim/summary.json: writing failed: No space left on device (the disk is full"),
            std::string::npos)
      << e;
}

TEST(AtomicFile, AnOutputFolderThroughAFileIsAnError) {
  const fs::path d = fresh_dir("through");
  std::ofstream(d / "a-file") << "x";
  const std::string e = error_of([&] { ensure_directory(d / "a-file" / "run"); });
  EXPECT_NE(e.find("cannot create the output directory: Not a directory (a file stands where"), std::string::npos) << e;
  fs::remove_all(d);
}

TEST(AtomicFile, CommitPublishesWholeFilesAndNothingElse) {
  const fs::path d = fresh_dir("commit");
  {
    AtomicFile f(d / "a.json");
    write_file_checked(f.tmp(), "{\"a\": 1}\n", f.path());
    EXPECT_FALSE(fs::exists(d / "a.json"));
    f.commit();
  }
  { AtomicFile g(d / "b.json"); std::ofstream(g.tmp()) << "{\"b\""; }  // never committed: removed
  EXPECT_EQ(names(d), std::set<std::string>{"a.json"});
  std::ifstream in(d / "a.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "{\"a\": 1}\n");
  fs::remove_all(d);
}

// The runner's stage commands: each removes the temporaries a killed run of it left in its folder, and the simulate
// stage takes --resume from the environment, so that the command (ninja's record of it) is the same either way.
TEST(Plan, StageCommandsRemoveStaleTemporariesAndSimulateResumesFromTheEnvironment) {
  const fs::path dir = fresh_dir("plan");
  std::ofstream(dir / "floes.geojson") << "{}";
  std::ofstream(dir / "hull.obj") << "";
  runner::StageLayout layout;
  layout.dir = [](const std::string& s, const std::string&) { return fs::path("/run") / s; };
  layout.config = [](const std::string& s, const std::string&) { return fs::path("/run/config") / (s + ".json"); };
  const runner::CasePlan plan = runner::plan_case(
      {{"floes", {{"file", "floes.geojson"}}}, {"hull", {{"file", "hull.obj"}}}}, "case.json", dir, "/bin", layout);
  for (size_t k = 0; k < plan.stages.size(); ++k) {
    const runner::PlannedStage& s = plan.stages[k];
    const std::string script = runner::stage_script(plan.stages, k, runner::StageOutput::console);
    EXPECT_NE(script.find("'" + s.dir.string() + "'/.tmp-*"), std::string::npos) << s.name << ": " << script;
    const bool resumes = script.find("${FLOESIM_RESUME:+--resume}") != std::string::npos;
    EXPECT_EQ(resumes, s.name == "simulate") << s.name << ": " << script;
  }
  fs::remove_all(dir);
}
