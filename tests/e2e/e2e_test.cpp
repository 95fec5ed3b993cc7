// The runner on a tiny case: every artefact exists, reads back and agrees with the others; a rerun does
// nothing; a changed parameter reruns exactly the stages downstream of it; a failed stage leaves nothing that
// looks complete.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "pipeline/floes_io.h"
#include "pipeline/options.h"
#include "pipeline/results_io.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;
using namespace floesim;

namespace {

const fs::path kBin = FLOESIM_BIN_DIR;
const fs::path kSource = FLOESIM_SOURCE_DIR;

using RunOutput = floesim::tests::CommandOutput;

RunOutput run_case(const fs::path& case_dir, const fs::path& run_dir) {
  return floesim::tests::run_logged(
      "'" + (kBin / "floesim").string() + "' run '" + case_dir.string() + "' --out '" + run_dir.string() + "'",
      run_dir.string() + ".log");
}

fs::file_time_type mtime(const fs::path& p) { return fs::last_write_time(p); }

// One fixture run shared by the tests: the tiny case copied to a temporary folder (so tests may edit it).
class TinyCase : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("floesim_e2e_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    case_ = root_ / "tiny";
    fs::copy(kSource / "tests" / "e2e" / "tiny", case_, fs::copy_options::recursive);
    run_ = root_ / "run";
    first_ = run_case(case_, run_);
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }
  static Json case_json() { return load_json_file(case_ / "case.json"); }
  static void write_case(const Json& j) { std::ofstream(case_ / "case.json") << j.dump(2); }

  static fs::path root_, case_, run_;
  static RunOutput first_;
};
fs::path TinyCase::root_, TinyCase::case_, TinyCase::run_;
RunOutput TinyCase::first_;

}  // namespace

TEST_F(TinyCase, FirstRunProducesEveryArtefact) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  for (const char* f : {"image/image.png", "image/truth.geojson", "floes/floes.geojson", "floes/labels.png",
                        "floes/overlay.png", "floes/stats.json", "hull/hull.obj", "sim/results.h5",
                        "sim/summary.json", "video/transit.mp4", "plots/surge_ice_load.png",
                        "plots/surge_ice_load.svg"})
    EXPECT_TRUE(fs::exists(run_ / f)) << f << " is missing\n" << first_.text;
}

TEST_F(TinyCase, FloeCountAgreesBetweenGeoJsonAndLabelImage) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  const FloeField floes = read_floes(run_ / "floes" / "floes.geojson");
  const cv::Mat labels = cv::imread((run_ / "floes" / "labels.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(labels.type(), CV_16UC1);
  const cv::Mat image = cv::imread((run_ / "image" / "image.png").string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(labels.size(), image.size()) << "labels must be on the input's pixel grid";
  std::set<int> ids;
  for (int r = 0; r < labels.rows; ++r)
    for (int c = 0; c < labels.cols; ++c)
      if (labels.at<uint16_t>(r, c)) ids.insert(labels.at<uint16_t>(r, c));
  ASSERT_GT(floes.floes.size(), 3u) << "the tiny case should digitise several floes";
  EXPECT_EQ(ids.size(), floes.floes.size());
  for (const Floe& f : floes.floes) EXPECT_TRUE(ids.count(f.id)) << "floe " << f.id << " has no label pixels";
  const Json stats = load_json_file(run_ / "floes" / "stats.json");
  EXPECT_EQ(stats["floe_count"].get<size_t>(), floes.floes.size());
  // Concentration from the label image must equal the floe-pixel fraction of the valid (non-black) pixels.
  int valid = 0, ice = 0;
  for (int r = 0; r < labels.rows; ++r)
    for (int c = 0; c < labels.cols; ++c) {
      valid += image.at<uint8_t>(r, c) != 0;
      ice += labels.at<uint16_t>(r, c) != 0;
    }
  EXPECT_NEAR(stats["ice_concentration"].get<double>(), double(ice) / valid, 1e-9);
}

TEST_F(TinyCase, SeriesFramesAndVideoAgreeWithTheSettings) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  const Json sim = case_json()["simulate"];
  const double duration = sim["duration_s"], dt = sim.value("time_step_s", 0.01), out = sim["output_interval_s"];
  const Results r = read_results(run_ / "sim" / "results.h5");
  EXPECT_EQ(r.steps(), static_cast<size_t>(std::llround(duration / dt)));
  EXPECT_EQ(r.frames(), static_cast<size_t>(std::llround(duration / out)));
  EXPECT_NEAR(r.frame_time_s.back(), duration, 1e-9);

  cv::VideoCapture video((run_ / "video" / "transit.mp4").string());
  ASSERT_TRUE(video.isOpened());
  int frames = 0;
  cv::Mat frame;
  while (video.read(frame)) ++frames;
  EXPECT_EQ(frames, static_cast<int>(r.frames())) << "one video frame per stored results frame";

  const Json summary = load_json_file(run_ / "sim" / "summary.json");
  ASSERT_TRUE(summary.contains("mean_surge_ice_load_N"));
  EXPECT_TRUE(std::isfinite(summary["mean_surge_ice_load_N"].get<double>()));
}

// Runs a command line (already quoted) with its output into `log`; returns the exit code and the output.
RunOutput run_logged(const std::string& cmd, const fs::path& log) {
  const int status = std::system((cmd + " > '" + log.string() + "' 2>&1").c_str());
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 1, ss.str()};
}

// The sweep gather on a real transit as a one-member plan: its row is the run's summary, and the series it takes
// the standard error from (the plot stage's steady part) has the summary's mean, to round-off. The tiny case's
// own transit meets no ice in its 6 s, so this one runs 40 s through the same floes (about 2 s of simulation).
TEST_F(TinyCase, GatherOfARealTransitAgreesWithItsSummary) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  const fs::path dir = root_ / "gather";
  fs::create_directories(dir);
  std::ofstream(dir / "simulate.json") << R"({"duration_s": 40.0, "output_interval_s": 1.0, "steady_start_s": 10.0,
    "vessel": {"heading_deg": 0.0, "initial_speed_mps": 2.0, "x_m": 10.0, "y_m": 82.0}})";
  const RunOutput sim = run_logged("'" + (kBin / "floesim-simulate").string() + "' --floes '" +
                                       (run_ / "floes" / "floes.geojson").string() + "' --hull '" +
                                       (run_ / "hull" / "hull.obj").string() + "' --config '" +
                                       (dir / "simulate.json").string() + "' --out '" + (dir / "sim").string() + "'",
                                   dir / "simulate.log");
  ASSERT_EQ(sim.code, 0) << sim.text;

  const fs::path summary_file = dir / "sim" / "summary.json", results_file = dir / "sim" / "results.h5";
  const Json stage = {{"name", "simulate"},
                      {"outputs", {results_file.string(), summary_file.string()}},
                      {"log", (dir / "simulate.log").string()}};
  const Json plan = {{"format", "floesim-sweep-plan/1"},
                     {"name", "tiny-40s"},
                     {"axes", Json::array()},
                     {"grid_points", Json::array({{{"index", 0}, {"axes", Json::object()}}})},
                     {"members", Json::array({{{"id", "transit"},
                                               {"grid_point", 0},
                                               {"ensemble_index", 0},
                                               {"axes", Json::object()},
                                               {"summary", summary_file.string()},
                                               {"results", results_file.string()},
                                               {"stages", Json::array({stage})}}})}};
  std::ofstream(dir / "plan.json") << plan.dump(2);
  const RunOutput gather = run_logged("'" + (kBin / "floesim-gather").string() + "' --plan '" +
                                          (dir / "plan.json").string() + "' --out '" + dir.string() + "'",
                                      dir / "gather.log");
  ASSERT_EQ(gather.code, 0) << gather.text;

  const Json summary = load_json_file(summary_file);
  const Json gathered = load_json_file(dir / "sweep.json");
  const Json& row = gathered["members"][0];
  ASSERT_EQ(row["status"], "ok") << row.dump(2);
  const double mean_kN = summary["mean_surge_ice_resistance_N"].get<double>() / 1000.0;
  ASSERT_GT(mean_kN, 10.0) << "the transit should meet ice";
  EXPECT_EQ(row["mean_surge_ice_resistance_kN"].get<double>(), mean_kN);
  EXPECT_EQ(row["mean_speed_mps"].get<double>(), summary["mean_vessel_speed_mps"].get<double>());
  for (const char* mode : {"bending", "radial", "splitting"})
    EXPECT_EQ(row[std::string("fracture_") + mode], summary["fracture"]["events"][mode]) << mode;
  // The same samples: the summary's steady part (t >= steady_start_s) is the gather's.
  EXPECT_EQ(row["steady_series"]["samples"], summary["steady_part"]["samples"]);
  // Summed in another order and unit (N against kN): equal to round-off, against the size of the signal.
  const double spread_kN = summary["std_surge_ice_load_N"].get<double>() / 1000.0;
  EXPECT_NEAR(row["steady_series"]["mean_kN"].get<double>(), mean_kN, 1e-12 * (std::abs(mean_kN) + spread_kN));
  // A correlated signal: the batch-means SE is positive and well below the spread of the signal itself.
  const double se = row["batch_means_se_kN"].get<double>();
  EXPECT_GT(se, 0.0);
  EXPECT_LT(se, spread_kN);
  // The 0.5 s peak: the summary's 0.5 s window is a 50-sample boxcar, the gather's the centred 51-tap average with
  // half-weighted ends (signal.h); the same span, so nearly the same peak.
  const double summary_peak_kN = summary["moving_average_surge_ice_load"][0]["max_resistance_N"].get<double>() / 1e3;
  ASSERT_EQ(summary["moving_average_surge_ice_load"][0]["window_s"].get<double>(), 0.5);
  EXPECT_NEAR(row["peak_0.5s_resistance_kN"].get<double>(), summary_peak_kN, 0.02 * summary_peak_kN);
  // The CSV carries the speed exactly as summary.json writes it.
  std::ifstream csv_in(dir / "sweep.csv");
  std::string header, line;
  std::getline(csv_in, header);
  std::getline(csv_in, line);
  EXPECT_NE(line.find("," + summary["mean_vessel_speed_mps"].dump() + ","), std::string::npos) << line;
  for (const char* f : {"ensemble.png", "ensemble.svg", "running_mean.png", "running_mean.svg"})
    EXPECT_GT(fs::file_size(dir / f), 0u) << f;
}

TEST_F(TinyCase, RerunWithNothingChangedDoesNothing) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  const auto t_results = mtime(run_ / "sim" / "results.h5");
  const auto t_video = mtime(run_ / "video" / "transit.mp4");
  const RunOutput again = run_case(case_, run_);
  ASSERT_EQ(again.code, 0) << again.text;
  EXPECT_NE(again.text.find("no work to do"), std::string::npos) << again.text;
  EXPECT_EQ(mtime(run_ / "sim" / "results.h5"), t_results);
  EXPECT_EQ(mtime(run_ / "video" / "transit.mp4"), t_video);
}

TEST_F(TinyCase, ChangedRenderParameterRerunsOnlyRender) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  const auto t_floes = mtime(run_ / "floes" / "floes.geojson");
  const auto t_results = mtime(run_ / "sim" / "results.h5");
  const auto t_plot = mtime(run_ / "plots" / "surge_ice_load.png");
  const auto t_video = mtime(run_ / "video" / "transit.mp4");
  Json c = case_json();
  c["render"]["width_px"] = c["render"].value("width_px", 320) + 32;
  write_case(c);
  const RunOutput again = run_case(case_, run_);
  ASSERT_EQ(again.code, 0) << again.text;
  EXPECT_EQ(mtime(run_ / "floes" / "floes.geojson"), t_floes);
  EXPECT_EQ(mtime(run_ / "sim" / "results.h5"), t_results);
  EXPECT_EQ(mtime(run_ / "plots" / "surge_ice_load.png"), t_plot);
  EXPECT_NE(mtime(run_ / "video" / "transit.mp4"), t_video);
}

TEST_F(TinyCase, ChangedSimulateParameterRerunsSimulateAndEverythingDownstream) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  const auto t_image = mtime(run_ / "image" / "image.png");
  const auto t_floes = mtime(run_ / "floes" / "floes.geojson");
  const auto t_hull = mtime(run_ / "hull" / "hull.obj");
  const auto t_results = mtime(run_ / "sim" / "results.h5");
  const auto t_plot = mtime(run_ / "plots" / "surge_ice_load.png");
  const auto t_video = mtime(run_ / "video" / "transit.mp4");
  Json c = case_json();
  c["simulate"]["steady_start_s"] = c["simulate"]["steady_start_s"].get<double>() + 0.5;
  write_case(c);
  const RunOutput again = run_case(case_, run_);
  ASSERT_EQ(again.code, 0) << again.text;
  EXPECT_EQ(mtime(run_ / "image" / "image.png"), t_image);
  EXPECT_EQ(mtime(run_ / "floes" / "floes.geojson"), t_floes);
  EXPECT_EQ(mtime(run_ / "hull" / "hull.obj"), t_hull);
  EXPECT_NE(mtime(run_ / "sim" / "results.h5"), t_results);
  EXPECT_NE(mtime(run_ / "plots" / "surge_ice_load.png"), t_plot);
  EXPECT_NE(mtime(run_ / "video" / "transit.mp4"), t_video);
}

// A stage that fails while it runs (settings it accepts, a run it cannot finish: here a health limit below the
// vessel's own speed) stops the run and leaves nothing downstream that looks complete.
TEST_F(TinyCase, FailedStageStopsAndLeavesNothingThatLooksComplete) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  Json c = case_json();
  const Json good = c;
  c["simulate"]["health"]["max_speed_mps"] = 0.01;
  write_case(c);
  const RunOutput bad = run_case(case_, run_);
  write_case(good);
  EXPECT_NE(bad.code, 0) << bad.text;
  EXPECT_NE(bad.text.find("max_speed_mps"), std::string::npos) << "the message names the key\n" << bad.text;
  EXPECT_TRUE(fs::exists(run_ / "floes" / "floes.geojson")) << "upstream artefacts stay";
  for (const char* f : {"sim/results.h5", "sim/summary.json", "video/transit.mp4", "plots/surge_ice_load.png"})
    EXPECT_FALSE(fs::exists(run_ / f)) << f << " survived a failed simulate stage";
  for (auto& e : fs::recursive_directory_iterator(run_))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path() << " left behind";
}

// A setting a stage refuses stops the run before anything is written: the message names the key by its path in
// case.json, and the run folder keeps what it held (the last good run's artefacts, untouched).
TEST_F(TinyCase, RefusedSettingStopsTheRunBeforeItWritesAnything) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  ASSERT_EQ(run_case(case_, run_).code, 0);  // complete again (a test before may have removed artefacts)
  const auto t_results = mtime(run_ / "sim" / "results.h5"), t_config = mtime(run_ / "config" / "simulate.json");
  Json c = case_json();
  const Json good = c;
  c["simulate"]["duration_s"] = -1.0;
  write_case(c);
  const RunOutput bad = run_case(case_, run_);
  write_case(good);
  EXPECT_NE(bad.code, 0) << bad.text;
  EXPECT_NE(bad.text.find("simulate.duration_s must be"), std::string::npos) << bad.text;
  EXPECT_EQ(mtime(run_ / "sim" / "results.h5"), t_results);
  EXPECT_EQ(mtime(run_ / "config" / "simulate.json"), t_config) << "the refused settings were written";
}

// The round trip as stages of a run (case key "identify" without "measured"): the transit becomes the data the
// ship would record, identify finds the ice load from them with the simulated ship's model, and the plot and the
// report show it against the simulated load. The identified mean must match the simulation's own mean
// (summary.json, every step) within the issue's 2 %; changing the sensor noise reruns the round trip, not the
// simulation. The tiny field over 40 s, so that the hull meets ice.
TEST_F(TinyCase, RoundTripStagesIdentifyTheSimulatedLoad) {
  ASSERT_EQ(first_.code, 0) << first_.text;
  const fs::path case_dir = root_ / "round-trip", run = root_ / "round-trip-run";
  fs::create_directories(case_dir);
  Json c = case_json();
  c["simulate"]["duration_s"] = 40.0;
  c["simulate"]["output_interval_s"] = 2.0;
  c["simulate"]["steady_start_s"] = 10.0;
  c["identify"] = {{"shipdata", Json::object()}};
  std::ofstream(case_dir / "case.json") << c.dump(2);
  const RunOutput out = run_case(case_dir, run);
  ASSERT_EQ(out.code, 0) << out.text;
  const Json summary = load_json_file(run / "sim" / "summary.json");
  const Json id = load_json_file(run / "identify" / "identified.json");
  const double sim_kN = summary["mean_surge_ice_resistance_N"].get<double>() / 1e3;
  ASSERT_GT(sim_kN, 10.0) << "the transit should meet ice";
  EXPECT_NEAR(id["mean_surge_ice_resistance_n"].get<double>() / 1e3, sim_kN, 0.02 * sim_kN);
  // The comparison identify made against the data's known load is the summary's mean over the same steps.
  EXPECT_NEAR(id["known_load"]["mean_surge_ice_resistance_n"].get<double>() / 1e3, sim_kN, 1e-9 * sim_kN);
  for (const char* f : {"shipdata/measured.csv", "shipdata/measured.json", "identify/identified.csv",
                        "plots/identified_load.png", "report/report.html"})
    EXPECT_TRUE(fs::exists(run / f)) << f << " is missing\n" << out.text;
  std::ifstream page(run / "report" / "report.html");
  std::stringstream html;
  html << page.rdbuf();
  EXPECT_NE(html.str().find("id=\"identified-kN\""), std::string::npos);
  EXPECT_EQ(html.str().find("id=\"missing\""), std::string::npos) << "the report lists something missing";

  // Sensor noise changed: the round trip reruns, the simulation does not.
  const auto t_results = mtime(run / "sim" / "results.h5"), t_measured = mtime(run / "shipdata" / "measured.csv");
  c["identify"]["shipdata"] = {{"noise", {{"surge_sd_mps2", 0.001}}}, {"seed", 3}};
  std::ofstream(case_dir / "case.json") << c.dump(2);
  const RunOutput again = run_case(case_dir, run);
  ASSERT_EQ(again.code, 0) << again.text;
  EXPECT_EQ(mtime(run / "sim" / "results.h5"), t_results);
  EXPECT_NE(mtime(run / "shipdata" / "measured.csv"), t_measured);

  // A ship's identify config without a ship's data is refused, naming the key, before anything runs.
  c["identify"] = {{"config", Json::object()}};
  std::ofstream(case_dir / "case.json") << c.dump(2);
  const RunOutput bad = run_case(case_dir, run);
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.text.find("identify.config"), std::string::npos) << bad.text;
}

// Two runs into one folder at once: the second waits for the first (the run folder's lock), saying so, and then
// finds everything up to date; neither leaves a temporary file.
TEST_F(TinyCase, ASecondRunIntoTheSameFolderWaitsForTheFirst) {
  const fs::path run = root_ / "twice";
  const std::string cmd = "'" + (kBin / "floesim").string() + "' run '" + case_.string() + "' --out '" + run.string() +
                          "' > '" + (root_ / "first-of-two.log").string() + "' 2>&1";
  const pid_t pid = fork();
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), nullptr);
    _exit(127);
  }
  // The second starts once the first holds the lock (its lock file exists and a stage has started).
  for (int i = 0; i < 3000 && !fs::exists(run / "config" / "simulate.json"); ++i) usleep(1000);
  const RunOutput second = run_case(case_, run);
  int status = 0;
  waitpid(pid, &status, 0);
  std::ifstream in(root_ / "first-of-two.log");
  std::stringstream first;
  first << in.rdbuf();
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << first.str();
  ASSERT_EQ(second.code, 0) << second.text;
  EXPECT_NE(second.text.find("waiting for " + run.string() + ": another floesim run is writing there"),
            std::string::npos)
      << second.text;
  EXPECT_NE(second.text.find("up to date"), std::string::npos) << second.text;
  for (const auto& e : fs::recursive_directory_iterator(run))
    EXPECT_NE(e.path().filename().string().rfind(".tmp-", 0), 0u) << e.path();
}
