// Checkpoints and --resume of the simulate stage (issue #13): a 40 s transit of the kill-test case that breaks floes (a
// gcc build four, at 9.45, 17.69, 39.09 and 39.95 s), checkpointed every 2 s, stopped by SIGINT or SIGKILL and resumed,
// must give results.h5 and summary.json byte-identical to the run never stopped; a checkpoint of other inputs or a
// damaged one is refused with a message saying why.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "pipeline/options.h"
#include "pipeline/results_io.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;
using floesim::tests::read_text;
using namespace floesim;

namespace {

const fs::path kBin = FLOESIM_BIN_DIR;

// A checkpoint's time as the stage prints it: step x time step, in the stream's default format.
std::string time_text(long step) {
  std::ostringstream os;
  os << static_cast<double>(step) * 0.01;
  return os.str();
}

int system_code(const std::string& cmd) {
  const int s = std::system(cmd.c_str());
  return WIFEXITED(s) ? WEXITSTATUS(s) : 128;
}

struct Outcome {
  int code = -1;
  std::string text;
};

class Resume : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("floesim_resume_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    // The kill-test case's floes and hull, made by the stages themselves.
    std::ofstream(root_ / "synth.json") << R"({"width_px": 200, "height_px": 140, "concentration": 0.5,
      "max_diameter_m": 40.0, "seed": 3, "metres_per_pixel": 1.1794})";
    std::ofstream(root_ / "hull.json") << R"({"sections": 20})";
    std::ofstream(root_ / "digitise.json") << "{}";
    ASSERT_EQ(system_code("'" + (kBin / "floesim-synth").string() + "' --config '" + (root_ / "synth.json").string() +
                          "' --out '" + (root_ / "image").string() + "' > /dev/null"), 0);
    ASSERT_EQ(system_code("'" + (kBin / "floesim-digitise").string() + "' '" + (root_ / "image/image.png").string() +
                          "' --metres-per-pixel 1.1794 --config '" + (root_ / "digitise.json").string() +
                          "' --out '" + (root_ / "floes").string() + "' > /dev/null"), 0);
    ASSERT_EQ(system_code("'" + (kBin / "floesim-hull").string() + "' --config '" + (root_ / "hull.json").string() +
                          "' --out '" + (root_ / "hull/hull.obj").string() + "' > /dev/null"), 0);
    write_config(root_ / "sim.json", base_config());
    reference_ = simulate_to_end(root_ / "sim.json", root_ / "reference");
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  static Json base_config() {
    return Json::parse(R"({"duration_s": 40.0, "output_interval_s": 0.5, "steady_start_s": 10.0,
      "checkpoint_interval_s": 2.0,
      "vessel": {"x_m": 10.0, "y_m": 82.0, "heading_deg": 0.0, "initial_speed_mps": 2.0}})");
  }
  static void write_config(const fs::path& f, const Json& j) { std::ofstream(f) << j.dump(2); }

  static std::vector<std::string> simulate_args(const fs::path& config, const fs::path& out, bool resume) {
    std::vector<std::string> a = {(kBin / "floesim-simulate").string(), "--floes",
                                  (root_ / "floes/floes.geojson").string(), "--hull", (root_ / "hull/hull.obj").string(),
                                  "--config", config.string(), "--out", out.string()};
    if (resume) a.push_back("--resume");
    return a;
  }

  // Starts floesim-simulate with its output into `log`.
  static pid_t start(const std::vector<std::string>& args, const fs::path& log) {
    std::vector<std::string> a = args;
    std::vector<char*> argv;
    for (auto& s : a) argv.push_back(s.data());
    argv.push_back(nullptr);
    const pid_t pid = fork();
    if (pid == 0) {
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(fd, 1);
      dup2(fd, 2);
      execv(argv[0], argv.data());
      _exit(127);
    }
    return pid;
  }
  static int wait_code(pid_t pid) {
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }

  static Outcome simulate_to_end(const fs::path& config, const fs::path& out, bool resume = false) {
    const fs::path log = out.string() + ".log";
    const int code = wait_code(start(simulate_args(config, out, resume), log));
    return {code, read_text(log)};
  }

  // Runs until its checkpoint has reached `step`, then sends `sig`; returns the exit code and the output.
  static Outcome stop_after(const fs::path& config, const fs::path& out, bool resume, long step, int sig) {
    const fs::path log = out.string() + ".log";
    const pid_t pid = start(simulate_args(config, out, resume), log);
    const fs::path info = out / "checkpoint" / "checkpoint.json";
    // At most ten minutes: an instrumented build (tests/sanitize/sanitize) on a loaded machine takes several to reach a
    // late checkpoint, and signalling before it would stop the run too early for the test's assertions.
    for (int i = 0; i < 60000; ++i) {
      if (fs::exists(info)) {
        try {
          if (load_json_file(info)["step"].get<long>() >= step) break;
        } catch (const std::exception&) {
        }
      }
      if (waitpid(pid, nullptr, WNOHANG) == pid) return {-1, read_text(log)};  // ended before the stop
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    kill(pid, sig);
    const int code = wait_code(pid);
    return {code, read_text(log)};
  }

  static long checkpoint_step(const fs::path& out) {
    return load_json_file(out / "checkpoint" / "checkpoint.json")["step"].get<long>();
  }

  static void expect_identical_to_reference(const fs::path& out) {
    ASSERT_EQ(reference_.code, 0) << reference_.text;
    for (const char* f : {"results.h5", "summary.json"}) {
      ASSERT_TRUE(fs::exists(out / f)) << f;
      EXPECT_TRUE(read_text(out / f) == read_text(root_ / "reference" / f))
          << f << " differs from the run that was never stopped";
    }
    EXPECT_FALSE(fs::exists(out / "checkpoint")) << "the checkpoint outlived the finished results";
  }

  // Bit for bit (NaN, the value of a series not measured, equals itself here).
  template <class T>
  static bool same(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
  }
  // Every dataset of two results files equal, value for value (files whose provenance differs).
  static void expect_same_datasets(const Results& a, const Results& b) {
    ASSERT_EQ(a.series.size(), b.series.size());
    for (const auto& [name, v] : a.series) EXPECT_TRUE(same(v, b.series.at(name))) << "series " << name;
    EXPECT_TRUE(same(a.frame_time_s, b.frame_time_s)) << "frame_time_s";
    EXPECT_TRUE(same(a.frame_offset, b.frame_offset)) << "frame_offset";
    EXPECT_TRUE(same(a.state_body_id, b.state_body_id)) << "state_body_id";
    EXPECT_TRUE(same(a.state_position_m, b.state_position_m)) << "state_position_m";
    EXPECT_TRUE(same(a.state_quaternion, b.state_quaternion)) << "state_quaternion";
    EXPECT_TRUE(same(a.state_in_contact, b.state_in_contact)) << "state_in_contact";
    EXPECT_TRUE(same(a.floe_id, b.floe_id)) << "floe_id";
    EXPECT_TRUE(same(a.floe_vertices_m, b.floe_vertices_m)) << "floe_vertices_m";
    EXPECT_TRUE(same(a.floe_parent_id, b.floe_parent_id)) << "floe_parent_id";
    EXPECT_TRUE(same(a.floe_ended_s, b.floe_ended_s)) << "floe_ended_s";
    EXPECT_TRUE(same(a.fracture_time_s, b.fracture_time_s)) << "fracture_time_s";
    EXPECT_TRUE(same(a.fracture_force_n, b.fracture_force_n)) << "fracture_force_n";
    EXPECT_TRUE(same(a.fracture_child_id, b.fracture_child_id)) << "fracture_child_id";
  }

  static fs::path root_;
  static Outcome reference_;
};
fs::path Resume::root_;
Outcome Resume::reference_;

}  // namespace

// The case breaks floes before the checkpoints resumed from below, so a restored world carries fracture pieces.
TEST_F(Resume, TheCaseBreaksFloes) {
  ASSERT_EQ(reference_.code, 0) << reference_.text;
  const Results r = read_results(root_ / "reference" / "results.h5");
  // At least one before the second SIGINT stop below (step 3400): the world restored there carries pieces. Which
  // floes break when depends on the compiler: fracture is a threshold on chaotic contact loads, and round-off
  // differs between builds (gcc, Release: 9.45, 17.69, 39.09 and 39.95 s; clang with the sanitizers,
  // tests/sanitize/sanitize: 26.92 and 38.70 s). Each build is compared with its own uninterrupted run.
  ASSERT_GE(r.fracture_time_s.size(), 1u);
  EXPECT_LT(r.fracture_time_s[0], 34.0);
}

// Stopped twice by SIGINT (at steps 1200 and 3400; a gcc build has broken one floe by the first, two by the second),
// resumed twice: byte-identical.
TEST_F(Resume, SigintTwiceThenResumeEqualsTheUninterruptedRunByteForByte) {
  const fs::path out = root_ / "sigint";
  const Outcome first = stop_after(root_ / "sim.json", out, false, 1200, SIGINT);
  ASSERT_EQ(first.code, 130) << first.text;
  EXPECT_NE(first.text.find("interrupted by SIGINT; checkpoint at t = "), std::string::npos) << first.text;
  EXPECT_FALSE(fs::exists(out / "results.h5"));
  const long s1 = checkpoint_step(out);
  EXPECT_GE(s1, 1200);  // SIGINT checkpoints the step reached, between two regular checkpoints
  const Outcome second = stop_after(root_ / "sim.json", out, true, 3400, SIGINT);
  ASSERT_EQ(second.code, 130) << second.text;
  EXPECT_NE(second.text.find("--resume: continuing from the checkpoint at t = " + time_text(s1) + " s"),
            std::string::npos)
      << second.text;
  const long s2 = checkpoint_step(out);
  EXPECT_GE(s2, 3400);  // the world restored below holds fracture pieces (TheCaseBreaksFloes)
  const Outcome last = simulate_to_end(root_ / "sim.json", out, true);
  ASSERT_EQ(last.code, 0) << last.text;
  EXPECT_NE(last.text.find("continuing from the checkpoint at t = " + time_text(s2) + " s"),
            std::string::npos)
      << last.text;
  expect_identical_to_reference(out);
}

// SIGKILL gives no chance to write anything: the resume starts from the last regular checkpoint (every 200 steps).
TEST_F(Resume, SigkillThenResumeFromTheLastRegularCheckpoint) {
  const fs::path out = root_ / "sigkill";
  const Outcome killed = stop_after(root_ / "sim.json", out, false, 2000, SIGKILL);
  ASSERT_EQ(killed.code, 128 + SIGKILL) << killed.text;
  const long s = checkpoint_step(out);
  EXPECT_EQ(s % 200, 0);
  const Outcome last = simulate_to_end(root_ / "sim.json", out, true);
  ASSERT_EQ(last.code, 0) << last.text;
  EXPECT_NE(last.text.find("continuing from the checkpoint at t = " + time_text(s) + " s"),
            std::string::npos)
      << last.text;
  expect_identical_to_reference(out);
}

// Writing checkpoints does not touch the physics: the datasets equal those of a run without checkpoints. With
// checkpoints the series before the last one are read back from its chunks (sim/simulate/checkpoint.h CheckpointSeries),
// without them they are all in memory: the results and the summary are the same either way.
TEST_F(Resume, CheckpointsDoNotChangeTheResults) {
  Json c = base_config();
  c["checkpoint_interval_s"] = 0.0;
  write_config(root_ / "no_checkpoints.json", c);
  const Outcome run = simulate_to_end(root_ / "no_checkpoints.json", root_ / "no_checkpoints");
  ASSERT_EQ(run.code, 0) << run.text;
  expect_same_datasets(read_results(root_ / "no_checkpoints" / "results.h5"),
                       read_results(root_ / "reference" / "results.h5"));
  Json a = load_json_file(root_ / "no_checkpoints" / "summary.json"), b = load_json_file(root_ / "reference" / "summary.json");
  for (Json* j : {&a, &b}) {  // the settings (checkpoint_interval_s) and their provenance differ, by design
    j->erase("settings");
    j->erase("provenance");
  }
  EXPECT_EQ(a.dump(), b.dump());
}

// A checkpoint of other settings is refused, naming what differs, and left in place; threads and the checkpoint
// interval change no result, so a resume with other values of them is accepted.
TEST_F(Resume, ACheckpointOfOtherSettingsIsRefusedOtherThreadCountsAreNot) {
  const fs::path out = root_ / "other";
  ASSERT_EQ(stop_after(root_ / "sim.json", out, false, 1000, SIGINT).code, 130);
  Json c = base_config();
  c["ice"] = {{"density_kg_m3", 910.0}};
  write_config(root_ / "denser.json", c);
  const Outcome refused = simulate_to_end(root_ / "denser.json", out, true);
  EXPECT_EQ(refused.code, 1) << refused.text;
  EXPECT_NE(refused.text.find("other inputs or settings"), std::string::npos) << refused.text;
  EXPECT_NE(refused.text.find("config.ice.density_kg_m3: 900.0 -> 910.0"), std::string::npos) << refused.text;
  EXPECT_NE(refused.text.find("without --resume"), std::string::npos) << refused.text;
  EXPECT_TRUE(fs::exists(out / "checkpoint" / "checkpoint.bin")) << "a refused checkpoint must stay";
  EXPECT_FALSE(fs::exists(out / "results.h5"));

  Json t = base_config();
  t["threads"] = 2;
  t["checkpoint_interval_s"] = 4.0;
  write_config(root_ / "two_threads.json", t);
  const Outcome resumed = simulate_to_end(root_ / "two_threads.json", out, true);
  ASSERT_EQ(resumed.code, 0) << resumed.text;
  EXPECT_NE(resumed.text.find("continuing from the checkpoint"), std::string::npos) << resumed.text;
  expect_same_datasets(read_results(out / "results.h5"), read_results(root_ / "reference" / "results.h5"));
}

TEST_F(Resume, ADamagedCheckpointIsAnError) {
  const fs::path out = root_ / "damaged";
  ASSERT_EQ(stop_after(root_ / "sim.json", out, false, 600, SIGINT).code, 130);
  {
    std::fstream f(out / "checkpoint" / "checkpoint.bin", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(200);
    f.put('\x5a');
  }
  const Outcome r = simulate_to_end(root_ / "sim.json", out, true);
  EXPECT_EQ(r.code, 1) << r.text;
  EXPECT_NE(r.text.find("checkpoint.bin: damaged"), std::string::npos) << r.text;
}

TEST_F(Resume, ResumeWithoutACheckpointStartsFromTheBeginning) {
  const fs::path out = root_ / "nothing";
  const Outcome r = simulate_to_end(root_ / "sim.json", out, true);
  ASSERT_EQ(r.code, 0) << r.text;
  EXPECT_NE(r.text.find("no checkpoint in"), std::string::npos) << r.text;
  expect_identical_to_reference(out);
}

TEST_F(Resume, TheIntervalMustBeAWholeNumberOfSteps) {
  Json c = base_config();
  c["checkpoint_interval_s"] = 0.015;
  write_config(root_ / "bad.json", c);
  const fs::path log = root_ / "bad.log";
  EXPECT_EQ(system_code("'" + (kBin / "floesim-simulate").string() + "' --check-config --config '" +
                        (root_ / "bad.json").string() + "' > '" + log.string() + "' 2>&1"), 1);
  EXPECT_NE(read_text(log).find("checkpoint_interval_s"), std::string::npos) << read_text(log);
  EXPECT_NE(read_text(log).find("whole number of time steps"), std::string::npos) << read_text(log);
}
