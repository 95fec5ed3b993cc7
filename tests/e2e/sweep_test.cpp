// floesim sweep on the tiny case: shared stages run once, a member's gathered row equals the summary of the same
// case run alone, a rerun does nothing, a changed axis value reruns exactly the members it touches, a failed member
// does not stop the others, bad sweeps are refused before anything runs, and the same sweep through a one-node
// SLURM cluster on loopback gives byte-identical results.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "pipeline/options.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;
using floesim::tests::read_text;
using namespace floesim;

namespace {

const fs::path kBin = FLOESIM_BIN_DIR;
const fs::path kSource = FLOESIM_SOURCE_DIR;

using RunOutput = floesim::tests::CommandOutput;

RunOutput shell(const std::string& cmd, const fs::path& log) { return floesim::tests::run_logged(cmd, log); }

RunOutput floesim(const std::string& args, const fs::path& log) {
  return shell("'" + (kBin / "floesim").string() + "' " + args, log);
}

// sweep.csv as rows of column -> text.
std::vector<std::map<std::string, std::string>> read_csv(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  std::vector<std::string> head;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](const std::string& l) {
    std::vector<std::string> out;
    std::string cur;
    bool q = false;
    for (size_t i = 0; i < l.size(); ++i) {
      const char c = l[i];
      if (q) {
        if (c == '"' && i + 1 < l.size() && l[i + 1] == '"') cur += '"', ++i;
        else if (c == '"') q = false;
        else cur += c;
      } else if (c == '"') q = true;
      else if (c == ',') out.push_back(cur), cur.clear();
      else cur += c;
    }
    out.push_back(cur);
    return out;
  };
  if (std::getline(in, line)) head = split(line);
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const auto v = split(line);
    std::map<std::string, std::string> r;
    for (size_t i = 0; i < head.size() && i < v.size(); ++i) r[head[i]] = v[i];
    rows.push_back(r);
  }
  return rows;
}

// Files under a run folder's stages/ with their modification times.
std::map<fs::path, fs::file_time_type> stage_files(const fs::path& run) {
  std::map<fs::path, fs::file_time_type> out;
  for (const auto& e : fs::recursive_directory_iterator(run / "stages"))
    if (e.is_regular_file() && e.path().filename() != "log.txt" && e.path().filename() != "wall_ms" &&
        e.path().filename() != "downstream.txt")  // the runner's list of what lies downstream, not a result
      out[e.path()] = fs::last_write_time(e.path());
  return out;
}

int count_dirs(const fs::path& run, const std::string& prefix) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(run / "stages"))
    n += e.path().filename().string().rfind(prefix + "-", 0) == 0;
  return n;
}

// The tiny case (copied), a good and a malformed thrust series, and a sweep over them: axis initial speed (two
// values) x two starts 1 mm apart = 4 members.
class TinySweep : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("floesim_sweep_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    base_ = root_ / "tiny";
    fs::copy(kSource / "tests" / "e2e" / "tiny", base_, fs::copy_options::recursive);
    sweep_ = root_ / "sweep";
    fs::create_directories(sweep_);
    write_sweep("[1.5, 2.0]");
    run_ = root_ / "run";
    first_ = floesim("sweep '" + sweep_.string() + "' --out '" + run_.string() + "' -j 2", root_ / "first.log");
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }
  static void write_sweep(const std::string& speeds) {
    std::ofstream(sweep_ / "sweep.json")
        << R"({"base": "../tiny",
               "axes": [{"key": "simulate.vessel.initial_speed_mps", "values": )"
        << speeds << R"(}],
               "ensemble": {"size": 2, "vary": ["start"]}})";
  }
  static fs::path root_, base_, sweep_, run_;
  static RunOutput first_;
};
fs::path TinySweep::root_, TinySweep::base_, TinySweep::sweep_, TinySweep::run_;
RunOutput TinySweep::first_;

TEST_F(TinySweep, SharedStagesRunOnceAndEveryMemberIsGathered) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  // Members differ in the vessel only: one image, one digitisation and one hull for all four.
  EXPECT_EQ(count_dirs(run_, "synth"), 1);
  EXPECT_EQ(count_dirs(run_, "digitise"), 1);
  EXPECT_EQ(count_dirs(run_, "hull"), 1);
  EXPECT_EQ(count_dirs(run_, "simulate"), 4);
  EXPECT_EQ(count_dirs(run_, "plot"), 4);
  EXPECT_EQ(count_dirs(run_, "render"), 0);  // sweeps do not render unless asked
  const auto rows = read_csv(run_ / "sweep.csv");
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& r : rows) EXPECT_EQ(r.at("status"), "ok") << r.at("member");
  EXPECT_EQ(rows[3].at("member"), "g001-e01");
  EXPECT_EQ(std::stod(rows[3].at("simulate.vessel.initial_speed_mps")), 2.0);
  EXPECT_NEAR(std::stod(rows[3].at("simulate.vessel.y_m")), 82.001, 1e-12);
  EXPECT_TRUE(fs::exists(run_ / "sweep.json"));
  EXPECT_TRUE(fs::exists(run_ / "members" / "g001-e01" / "sim" / "summary.json"));  // a member is a run folder
  // The axis by its option's own description (floesim-simulate --help-config: vessel.initial_speed_mps, m/s,
  // "initial forward speed"), in sweep.json and on the report, not by its key.
  const nlohmann::json sw = nlohmann::json::parse(read_text(run_ / "sweep.json"));
  EXPECT_EQ(sw["axes"][0]["label"], "vessel: initial forward speed (m/s)");
  EXPECT_EQ(sw["axes"][0]["unit"], "m/s");
  // The sweep's report: every grid point and member on one page, the gathered plot embedded, nothing missing.
  const std::string html = read_text(run_ / "report.html");
  EXPECT_NE(html.find("id=\"grid-points\""), std::string::npos);
  for (const char* m : {">g000-e00<", ">g000-e01<", ">g001-e00<", ">g001-e01<"})
    EXPECT_NE(html.find(m), std::string::npos) << m;
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
  EXPECT_EQ(html.find("id=\"missing\""), std::string::npos);
  EXPECT_EQ(html.find("id=\"failed-members\""), std::string::npos);
  EXPECT_NE(html.find(">vessel: initial forward speed (m/s)</th>"), std::string::npos);
  EXPECT_EQ(html.find(">simulate.vessel.initial_speed_mps<"), std::string::npos);  // no key as a visible cell
}

// The member's case.json run alone with floesim run gives the summary the sweep gathered, number for number.
TEST_F(TinySweep, GatheredRowEqualsTheSameCaseRunAlone) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  const fs::path alone = root_ / "alone_case";
  fs::create_directories(alone);
  fs::copy_file(run_ / "members" / "g001-e01" / "case.json", alone / "case.json");
  const RunOutput r = floesim("run '" + alone.string() + "' --out '" + (root_ / "alone_run").string() + "'",
                              root_ / "alone.log");
  ASSERT_EQ(r.code, 0) << r.text;
  const Json s = load_json_file(root_ / "alone_run" / "sim" / "summary.json");
  const auto rows = read_csv(run_ / "sweep.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(std::stod(rows[3].at("mean_surge_ice_resistance_kN")),
            s["mean_surge_ice_resistance_N"].get<double>() / 1000);
  EXPECT_EQ(std::stod(rows[3].at("mean_speed_mps")), s["mean_vessel_speed_mps"].get<double>());
  // The simulation itself is the same: the results' series are byte-identical (the file's provenance names its
  // own config path, which differs).
  const Json s_sweep = load_json_file(run_ / "members" / "g001-e01" / "sim" / "summary.json");
  EXPECT_EQ(s_sweep["mean_surge_ice_resistance_N"], s["mean_surge_ice_resistance_N"]);
  EXPECT_EQ(s_sweep["steps"], s["steps"]);
  EXPECT_EQ(s_sweep["moving_average_surge_ice_load"], s["moving_average_surge_ice_load"]);
}

TEST_F(TinySweep, RerunDoesNothingAndAChangedValueRerunsOnlyItsMembers) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  const auto before = stage_files(run_);
  const RunOutput again = floesim("sweep '" + sweep_.string() + "' --out '" + run_.string() + "'", root_ / "again.log");
  ASSERT_EQ(again.code, 0) << again.text;
  EXPECT_EQ(stage_files(run_), before) << again.text;

  // 2.0 -> 2.5: the two members at 1.5 m/s keep their results; two new simulations, nothing upstream reruns.
  write_sweep("[1.5, 2.5]");
  const RunOutput changed =
      floesim("sweep '" + sweep_.string() + "' --out '" + run_.string() + "'", root_ / "changed.log");
  ASSERT_EQ(changed.code, 0) << changed.text;
  const auto after = stage_files(run_);
  int kept = 0, rewritten = 0;
  for (const auto& [p, t] : before) {
    auto it = after.find(p);
    ASSERT_NE(it, after.end()) << p;
    (it->second == t ? kept : rewritten) += 1;
  }
  EXPECT_EQ(rewritten, 0);  // old stage folders are a cache: untouched
  EXPECT_EQ(count_dirs(run_, "simulate"), 6);
  EXPECT_EQ(count_dirs(run_, "synth"), 1);
  const auto rows = read_csv(run_ / "sweep.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(std::stod(rows[2].at("simulate.vessel.initial_speed_mps")), 2.5);
  write_sweep("[1.5, 2.0]");
}

// A member whose simulation fails (a malformed thrust series) is listed with its error; the others finish.
TEST_F(TinySweep, FailedMemberDoesNotStopTheOthers) {
  const fs::path sw = root_ / "sweep_fail";
  fs::create_directories(sw);
  std::ofstream(base_ / "good.csv") << "time_s,thrust_N\n0,400000\n100,400000\n";
  std::ofstream(base_ / "bad.csv") << "time_s,thrust_N\n0,lots\n";
  std::ofstream(sw / "sweep.json") << R"({"base": "../tiny",
      "set": {"simulate.vessel.propulsion.mode": "thrust_series"},
      "axes": [{"key": "simulate.vessel.propulsion.thrust_file", "values": ["bad.csv", "good.csv"]}]})";
  const fs::path run = root_ / "run_fail";
  const RunOutput r = floesim("sweep '" + sw.string() + "' --out '" + run.string() + "'", root_ / "fail.log");
  EXPECT_NE(r.code, 0) << r.text;
  EXPECT_NE(r.text.find("FAILED member g000-e00"), std::string::npos) << r.text;
  const auto rows = read_csv(run / "sweep.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("status"), "failed");
  EXPECT_NE(rows[0].at("error").find("bad.csv"), std::string::npos) << rows[0].at("error");
  EXPECT_EQ(rows[1].at("status"), "ok");
  // The report names the failed member and its error.
  const std::string html = read_text(run / "report.html");
  const size_t box = html.find("id=\"failed-members\"");
  ASSERT_NE(box, std::string::npos);
  EXPECT_NE(html.find("g000-e00", box), std::string::npos);
  EXPECT_NE(html.find("bad.csv", box), std::string::npos);
  fs::remove(base_ / "good.csv");
  fs::remove(base_ / "bad.csv");
}

// Bad sweeps: refused with the file and key named, before anything is written.
TEST_F(TinySweep, BadSweepsAreRefusedBeforeAnythingRuns) {
  auto refused = [&](const std::string& json, const std::string& piece, const std::string& extra = "") {
    const fs::path sw = root_ / "bad_sweep";
    fs::remove_all(sw);
    fs::create_directories(sw);
    std::ofstream(sw / "sweep.json") << json;
    const fs::path run = root_ / "bad_run";
    fs::remove_all(run);
    const RunOutput r = floesim("sweep '" + sw.string() + "' --out '" + run.string() + "' " + extra, root_ / "bad.log");
    EXPECT_NE(r.code, 0) << json;
    EXPECT_NE(r.text.find(piece), std::string::npos) << "missing '" << piece << "' in: " << r.text;
    EXPECT_NE(r.text.find("sweep.json"), std::string::npos) << r.text;
    EXPECT_FALSE(fs::exists(run)) << json;
  };
  refused(R"({"base": "../tiny", "axes": [{"key": "simulate.vessel.initial_sped_mps", "values": [1]}]})",
          "initial_sped_mps is not a known key");
  refused(R"({"base": "../tiny", "axes": [{"key": "simulat.duration_s", "values": [1]}]})",
          "unknown case section \"simulat\"");
  refused(R"({"base": "../tiny", "axes": [{"key": "simulate.duration_s", "values": []}]})", "has no values");
  refused(R"({"base": "../tiny", "axes": [{"key": "simulate.duration_s", "values": [5, -1]}]})",
          "duration_s must be > 0");
  refused(R"({"base": "../tiny", "ensemble": {"size": 2, "vary": ["weather"]}})", "unknown \"weather\"");
  refused(R"({"base": "../tiny", "axez": []})", "unknown key axez");
  refused(R"({"base": "../tiny", "axes": [{"key": "simulate.duration_s", "values": [2, 3, 4, 5, 6, 7, 8, 9]}],
              "ensemble": {"size": 9, "vary": ["start"]}})",
          "pass --yes");
}

// The same sweep through a one-node SLURM cluster on loopback (tests/slurm/slurm-cluster): every stage output
// byte-identical to the local run's, in the same folder (results name their inputs' paths).
TEST_F(TinySweep, SlurmRunIsByteIdenticalToTheLocalRun) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  const fs::path cluster = root_ / "cluster";
  const fs::path script = kSource / "tests" / "slurm" / "slurm-cluster";
  const RunOutput start = shell("'" + script.string() + "' start '" + cluster.string() + "'", root_ / "cluster.log");
  // Skipped where SLURM is not installed, but never in CI (.ci/run sets FLOESIM_REQUIRE_SLURM and installs it).
  if (start.code == 77 && !std::getenv("FLOESIM_REQUIRE_SLURM"))
    GTEST_SKIP() << "no SLURM on this machine: " << start.text;
  ASSERT_EQ(start.code, 0) << start.text;
  const std::string conf = (cluster / "slurm.conf").string();

  // A local run of the sweep in a folder of its own, its outputs kept aside; then the same folder emptied of them
  // and run on the cluster.
  const fs::path run = root_ / "run_slurm";
  const RunOutput here = floesim("sweep '" + sweep_.string() + "' --out '" + run.string() + "'", root_ / "here.log");
  ASSERT_EQ(here.code, 0) << here.text;
  const fs::path local = root_ / "local_copy";
  fs::copy(run / "stages", local, fs::copy_options::recursive);
  fs::copy_file(run / "sweep.csv", root_ / "local_sweep.csv");
  for (const auto& e : fs::directory_iterator(run / "stages"))
    for (const auto& f : fs::directory_iterator(e.path()))
      if (f.path().filename() != "config.json") fs::remove(f.path());
  fs::remove(run / "sweep.csv");
  fs::remove(run / "report.html");
  const RunOutput r = shell("SLURM_CONF='" + conf + "' '" + (kBin / "floesim").string() + "' sweep '" +
                                sweep_.string() + "' --out '" + run.string() + "' --slurm --wait",
                            root_ / "slurm_sweep.log");
  shell("'" + script.string() + "' stop '" + cluster.string() + "'", root_ / "cluster_stop.log");
  ASSERT_EQ(r.code, 0) << r.text;
  int compared = 0;
  for (const auto& e : fs::recursive_directory_iterator(local)) {
    if (!e.is_regular_file()) continue;
    const std::string name = e.path().filename().string();
    if (name == "log.txt" || name == "wall_ms") continue;  // what the stage printed and how long it took
    const fs::path there = run / "stages" / fs::relative(e.path(), local);
    ASSERT_TRUE(fs::exists(there)) << there;
    EXPECT_EQ(read_text(there), read_text(e.path())) << there;
    ++compared;
  }
  EXPECT_GE(compared, 20);
  // The gathered table too, but for the wall times.
  auto without_wall = [](const std::vector<std::map<std::string, std::string>>& rows) {
    auto out = rows;
    for (auto& r : out) r.erase("wall_s");
    return out;
  };
  EXPECT_EQ(without_wall(read_csv(run / "sweep.csv")), without_wall(read_csv(root_ / "local_sweep.csv")));
  EXPECT_TRUE(fs::exists(run / "report.html")) << "the cluster's gather job writes the report too";
}

}  // namespace

// A local sweep stopped by SIGINT during its simulations: it passes the signal on, gathers nothing, says where it
// stopped, and leaves nothing half-written; `floesim sweep --resume` then finishes, the stopped simulation continuing
// from its checkpoint, and every member's results are byte-identical to those of a sweep never stopped.
TEST(SweepInterrupt, SigintStopsTheSweepCleanlyAndResumeFinishesItByteForByte) {
  const fs::path root = fs::temp_directory_path() / ("floesim_sweep_int_" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root / "sweep");
  fs::copy(kSource / "tests" / "e2e" / "kill", root / "kill", fs::copy_options::recursive);
  std::ofstream(root / "sweep" / "sweep.json") << R"({"base": "../kill",
    "axes": [{"key": "simulate.vessel.initial_speed_mps", "values": [1.8, 2.0]}]})";
  const fs::path sweep = root / "sweep", run = root / "run", reference = root / "reference";
  const auto runner = [](const std::string& args, const fs::path& log) {
    return shell("'" + (kBin / "floesim").string() + "' " + args, log);
  };
  const RunOutput full = runner("sweep '" + sweep.string() + "' --out '" + reference.string() + "'", root / "ref.log");
  ASSERT_EQ(full.code, 0) << full.text;

  // Started in the background; SIGINT once a simulation has written a checkpoint.
  const std::string cmd = "'" + (kBin / "floesim").string() + "' sweep '" + sweep.string() + "' --out '" +
                          run.string() + "' -j 1 > '" + (root / "stopped.log").string() + "' 2>&1";
  const pid_t pid = fork();
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), nullptr);
    _exit(127);
  }
  bool checkpointed = false;
  for (int i = 0; i < 6000 && !checkpointed; ++i) {
    std::error_code ec;
    if (fs::exists(run / "stages", ec))
      for (const auto& e : fs::directory_iterator(run / "stages", ec))
        checkpointed = checkpointed || fs::exists(e.path() / "checkpoint" / "checkpoint.json");
    if (!checkpointed) usleep(10000);
  }
  ASSERT_TRUE(checkpointed) << read_text(root / "stopped.log");
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  const std::string stopped = read_text(root / "stopped.log");
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 130) << stopped;
  EXPECT_NE(stopped.find("floesim: interrupted by SIGINT during stage simulate-"), std::string::npos) << stopped;
  EXPECT_NE(stopped.find("nothing half-written left; nothing gathered"), std::string::npos) << stopped;
  EXPECT_FALSE(fs::exists(run / "sweep.csv"));
  for (const auto& e : fs::recursive_directory_iterator(run))
    EXPECT_NE(e.path().filename().string().rfind(".tmp-", 0), 0u) << "temporary file left: " << e.path();

  const RunOutput resumed = runner("sweep '" + sweep.string() + "' --out '" + run.string() + "' --resume",
                                    root / "resumed.log");
  ASSERT_EQ(resumed.code, 0) << resumed.text;
  int continued = 0, compared = 0;
  for (const auto& e : fs::directory_iterator(run / "stages")) {
    const std::string name = e.path().filename().string();
    if (name.rfind("simulate-", 0) != 0) continue;
    continued += read_text(e.path() / "log.txt").find("continuing from the checkpoint") != std::string::npos;
    for (const char* f : {"results.h5", "summary.json"}) {
      EXPECT_TRUE(read_text(e.path() / f) == read_text(reference / "stages" / name / f)) << name << "/" << f;
      ++compared;
    }
  }
  EXPECT_EQ(continued, 1) << "the stopped simulation should have continued from its checkpoint";
  EXPECT_EQ(compared, 4);
  const auto rows = read_csv(run / "sweep.csv");  // (its wall times differ from run to run)
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& r : rows) EXPECT_EQ(r.at("status"), "ok") << r.at("member");
  fs::remove_all(root);
}
