#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pipeline/error.h"
#include "pipeline/provenance.h"
#include "pipeline/results_io.h"
#include "pipeline/options.h"

using namespace floesim;
namespace fs = std::filesystem;

namespace {
Results small_results(int steps) {
  Results r;
  for (int k = 0; k < steps; ++k) {
    for (const auto& f : series_fields()) {
      std::vector<double> row(f.cols, 0.5 * k);
      auto& v = r.series[f.name];
      v.insert(v.end(), row.begin(), row.end());
    }
  }
  r.frame_time_s = {0.1, 0.2};
  r.frame_offset = {0, 2, 4};
  r.state_body_id = {0, 1, 0, 1};
  r.state_position_m = std::vector<double>(12, 1.0);
  r.state_quaternion = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  r.floe_id = {1};
  r.floe_thickness_m = {1.0};
  r.floe_vertex_offset = {0, 3};
  r.floe_vertices_m = {0, 0, 1, 0, 0, 1};
  r.hull_vertices_m = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  r.hull_triangles = {0, 1, 2};
  r.attributes = {{"time_step_s", 0.01}};
  return r;
}
}  // namespace

TEST(ResultsIo, RoundTripAndBitIdenticalRewrites) {
  const fs::path a = fs::temp_directory_path() / "floesim_results_a.h5";
  const fs::path b = fs::temp_directory_path() / "floesim_results_b.h5";
  Results r = small_results(7);
  write_results(a, r);
  write_results(b, r);
  EXPECT_EQ(sha256_file(a), sha256_file(b)) << "identical results must give identical bytes";
  Results back = read_results(a);
  EXPECT_EQ(back.steps(), 7u);
  EXPECT_EQ(back.frames(), 2u);
  EXPECT_EQ(back.get("ice_load").size(), 7u * 6u);
  EXPECT_DOUBLE_EQ(back.get("ice_load")[6 * 3], 1.5);
  EXPECT_EQ(back.state_body_id, r.state_body_id);
  EXPECT_EQ(back.attributes["time_step_s"], 0.01);
  fs::remove(a);
  fs::remove(b);
}

TEST(ResultsIo, RefusesInconsistentSeriesAndLeavesNoFile) {
  Results r = small_results(3);
  r.series["time_s"].push_back(9.0);
  const fs::path p = fs::temp_directory_path() / "floesim_results_bad.h5";
  EXPECT_THROW(write_results(p, r), Error);
  EXPECT_FALSE(fs::exists(p));
}

TEST(ResultsIo, ClearErrorsForMissingOrForeignFiles) {
  const fs::path p = fs::temp_directory_path() / "floesim_not_hdf5.h5";
  std::ofstream(p) << "plain text";
  try {
    read_results(p);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not an HDF5 file"), std::string::npos) << e.what();
  }
  fs::remove(p);
  EXPECT_THROW(read_results(fs::temp_directory_path() / "floesim_absent.h5"), Error);
}
