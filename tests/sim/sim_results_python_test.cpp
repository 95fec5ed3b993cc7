// The pure-Python reader of results.h5 (pipeline/python/floesim_results.py, h5py and numpy) against the C++ reader
// on one file of a real run that breaks ice (pieces appear, floes end): every frame's replayed body states and the
// CSV export of the series, value for value (issue #37, part 4).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <sstream>

#include <Eigen/Geometry>

#include <nlohmann/json.hpp>

#include "pipeline/results_io.h"
#include "pipeline/vtk_series.h"
#include "sim/simulate/simulate.h"
#include "tests/sim/sim_fixtures.h"
#include "tests/sim/small_breaking_run.h"
#include "tests/test_util.h"

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;

// The Debian interpreter, whose python3-h5py and python3-numpy the reader needs (not a user's own python3).
constexpr const char* kPython = "/usr/bin/python3";

std::string reader() { return (fs::path(FLOESIM_SOURCE_DIR) / "pipeline/python/floesim_results.py").string(); }

class PythonReader : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // A folder per process: ctest runs the suite's tests as parallel processes, each making its own run.
    dir_ = new fs::path(testing::temp_dir("python_reader_" + std::to_string(::getpid())));
    RunStats stats;
    const Results r = simulate(testing::small_breaking_run_options(), testing::small_breaking_run(), stats);
    write_results(*dir_ / "results.h5", r);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static tests::CommandOutput python(const std::string& args) {
    return tests::run_logged(std::string(kPython) + " '" + reader() + "' '" + (*dir_ / "results.h5").string() + "' " +
                                 args,
                             *dir_ / "python.log");
  }
  static fs::path* dir_;
};
fs::path* PythonReader::dir_ = nullptr;

TEST_F(PythonReader, EveryFramesBodiesAreThoseOfFrameReplay) {
  const Results r = read_results(*dir_ / "results.h5");
  ASSERT_GT(r.fracture_time_s.size(), 0u) << "the run must break ice, so that pieces appear and floes end";
  FrameReplay replay(r, "results.h5");
  size_t compared = 0;
  for (size_t k = 0; k < r.frames(); ++k) {
    const tests::CommandOutput out = python("frame " + std::to_string(k));
    ASSERT_EQ(out.code, 0) << out.text;
    const nlohmann::json j = nlohmann::json::parse(out.text);
    replay.seek(k);
    EXPECT_EQ(j["time_s"].get<double>(), r.frame_time_s[k]);
    ASSERT_EQ(j["bodies"].size(), replay.rows().size()) << "frame " << k;
    for (size_t i = 0; i < replay.rows().size(); ++i) {
      const size_t row = static_cast<size_t>(replay.rows()[i]);
      const nlohmann::json& b = j["bodies"][i];
      EXPECT_EQ(b["id"].get<int>(), r.state_body_id[row]) << "frame " << k << " body " << i;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(b["position_m"][c].get<double>(), r.state_position_m[3 * row + c]);
      for (int c = 0; c < 4; ++c) EXPECT_EQ(b["quaternion_wxyz"][c].get<double>(), r.state_quaternion[4 * row + c]);
      EXPECT_EQ(b["in_contact"].get<int>(), r.state_in_contact[row]);
      ++compared;
    }
  }
  EXPECT_GT(compared, 8u);
}

TEST_F(PythonReader, TheCsvHoldsEverySeriesWithItsColumnsAndUnits) {
  const Results r = read_results(*dir_ / "results.h5");
  const fs::path csv = *dir_ / "series.csv";
  const tests::CommandOutput out = python("csv '" + csv.string() + "'");
  ASSERT_EQ(out.code, 0) << out.text;
  std::istringstream in(tests::read_text(csv));
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("time_s [s],", 0), 0u) << header;
  EXPECT_NE(header.find("ice_load.Fx [N]"), std::string::npos) << header;
  EXPECT_NE(header.find("ice_load.Mz [N m]"), std::string::npos) << header;
  // Column order: the header's names, each value read back equal to the C++ reader's.
  std::vector<std::pair<std::string, int>> columns;  // series, column
  {
    std::istringstream h(header);
    std::string cell;
    while (std::getline(h, cell, ',')) {
      const std::string name = cell.substr(0, cell.find(' '));
      const size_t dot = name.find('.');
      const std::string series = name.substr(0, dot);
      int col = 0;
      if (dot != std::string::npos) {
        const DatasetSpec& d = results_dataset("/series/" + series);
        const auto names = column_names(d, series_field(series).cols);
        col = static_cast<int>(std::find(names.begin(), names.end(), name.substr(dot + 1)) - names.begin());
      }
      columns.push_back({series, col});
    }
  }
  size_t cols_total = 0;
  for (const FieldSpec& f : series_fields()) cols_total += f.cols;
  ASSERT_EQ(columns.size(), cols_total) << "every column of every series";
  std::string line;
  size_t step = 0;
  while (std::getline(in, line)) {
    std::istringstream l(line);
    std::string cell;
    for (const auto& [series, col] : columns) {
      ASSERT_TRUE(std::getline(l, cell, ','));
      const double want = r.get(series)[step * series_field(series).cols + col];
      const double got = std::stod(cell);
      if (std::isnan(want)) EXPECT_TRUE(std::isnan(got)) << series << " step " << step;
      else EXPECT_EQ(got, want) << series << "[" << col << "] step " << step;
    }
    ++step;
  }
  EXPECT_EQ(step, r.steps());
}

TEST_F(PythonReader, AFrameOutOfRangeIsAClearErrorWithExitTwo) {
  const tests::CommandOutput out = python("frame 100000");
  EXPECT_EQ(out.code, 2);
  EXPECT_NE(out.text.find("results.h5"), std::string::npos) << out.text;
  EXPECT_EQ(out.text.find("Traceback"), std::string::npos) << out.text;
}

// The ParaView series read back by VTK's own reader: each frame at its time, one cell per floe alive in
// FrameReplay's frame (in its order) with that body's id and centre, the hull's triangles, and a floe's first
// vertex where its pose puts it (the points are float32: within a millimetre).
TEST_F(PythonReader, TheParaViewSeriesReadByVtkHoldsFrameReplaysBodies) {
  const Results r = read_results(*dir_ / "results.h5");
  write_vtk_series(r, *dir_ / "paraview", "results.h5");
  const tests::CommandOutput out = tests::run_logged(
      std::string(kPython) + " '" + (fs::path(FLOESIM_SOURCE_DIR) / "tests/sim/read_vtk_series.py").string() + "' '" +
          (*dir_ / "paraview/results.pvd").string() + "'",
      *dir_ / "vtk.log");
  ASSERT_EQ(out.code, 0) << out.text;
  const nlohmann::json frames = nlohmann::json::parse(out.text);
  ASSERT_EQ(frames.size(), r.frames());
  FrameReplay replay(r, "results.h5");
  const size_t hull_cells = r.hull_triangles.size() / 3;
  for (size_t k = 0; k < r.frames(); ++k) {
    replay.seek(k);
    const nlohmann::json& f = frames[k];
    EXPECT_EQ(f["timestep"].get<double>(), r.frame_time_s[k]);
    EXPECT_EQ(f["time_value"].get<double>(), r.frame_time_s[k]);
    const size_t step = static_cast<size_t>(std::llround(r.frame_time_s[k] / r.attributes["time_step_s"].get<double>())) - 1;
    EXPECT_EQ(f["surge_ice_load_n"].get<double>(), r.get("ice_load")[6 * step]);
    // The hull's triangles, and each floe as a prism: top, bottom and a quad per side of its outline.
    auto cells_of = [&](size_t i) {
      const int32_t g = replay.floes()[i];
      return g < 0 ? hull_cells
                   : static_cast<size_t>(r.floe_vertex_offset[g + 1] - r.floe_vertex_offset[g]) + 2;
    };
    size_t total = 0;
    for (size_t i = 0; i < replay.rows().size(); ++i) total += cells_of(i);
    ASSERT_EQ(f["body_id"].size(), total) << "frame " << k;
    size_t cell = 0;
    for (size_t i = 0; i < replay.rows().size(); ++i) {
      const size_t row = static_cast<size_t>(replay.rows()[i]);
      const size_t cells = cells_of(i);
      for (size_t c = 0; c < cells; ++c, ++cell) {
        EXPECT_EQ(f["body_id"][cell].get<int>(), r.state_body_id[row]) << "frame " << k << " cell " << cell;
        EXPECT_EQ(f["kind"][cell].get<int>(), replay.floes()[i] < 0 ? 3 : (r.floe_parent_id[replay.floes()[i]] >= 0 ? 2 : 0));
        for (int d = 0; d < 3; ++d) EXPECT_EQ(f["centre_m"][cell][d].get<double>(), r.state_position_m[3 * row + d]);
      }
      if (replay.floes()[i] < 0) continue;
      const size_t g = static_cast<size_t>(replay.floes()[i]);
      const double* q = &r.state_quaternion[4 * row];
      const Eigen::Vector3d v0(r.floe_vertices_m[2 * r.floe_vertex_offset[g]], r.floe_vertices_m[2 * r.floe_vertex_offset[g] + 1],
                               r.floe_thickness_m[g] / 2);
      const Eigen::Vector3d want = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized() * v0 +
                                   Eigen::Vector3d(r.state_position_m[3 * row], r.state_position_m[3 * row + 1],
                                                   r.state_position_m[3 * row + 2]);
      // The floe's first cell is its top face, from the outline's first vertex.
      for (int d = 0; d < 3; ++d) EXPECT_NEAR(f["first_point"][cell - cells][d].get<double>(), want[d], 1e-3);
    }
  }
}

}  // namespace
}  // namespace floesim::sim
