#include <gtest/gtest.h>

#include <hdf5.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>

#include "pipeline/error.h"
#include "pipeline/provenance.h"
#include "pipeline/results_io.h"
#include "pipeline/options.h"
#include "tests/test_util.h"

using namespace floesim;
namespace fs = std::filesystem;

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

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
  r.state_in_contact = {0, 1, 0, 0};  // floe 1 pressed against the vessel in the first frame
  r.floe_id = {1};
  r.floe_thickness_m = {1.0};
  r.floe_vertex_offset = {0, 3};
  r.floe_vertices_m = {0, 0, 1, 0, 0, 1};
  r.floe_parent_id = {-1};
  r.floe_generation = {0};
  r.floe_origin_mode = {kFractureNone};
  r.floe_created_s = {0.0};
  r.floe_ended_s = {kInf};
  r.hull_vertices_m = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  r.hull_triangles = {0, 1, 2};
  r.attributes = {{"time_step_s", 0.01}};
  return r;
}

// Two input floes (1, 2). Event 0 at 0.15 s: floe 1 splits at the vessel into pieces 3 and 4. Event 1 at 0.2 s:
// piece 3 loses a bending wedge, piece 5, at a floe-floe contact (the rest of it went to brash). Three pieces.
Results fractured_results() {
  Results r = small_results(7);
  r.floe_id = {1, 2, 3, 4, 5};
  r.floe_thickness_m = {1.0, 1.5, 1.0, 1.0, 1.0};
  r.floe_vertex_offset = {0, 3, 6, 9, 12, 15};
  r.floe_vertices_m.clear();
  for (int k = 0; k < 5; ++k) r.floe_vertices_m.insert(r.floe_vertices_m.end(), {0, 0, 1.0 + k, 0, 0, 1.0 + k});
  r.floe_parent_id = {-1, -1, 1, 1, 3};
  r.floe_generation = {0, 0, 1, 1, 2};
  r.floe_origin_mode = {kFractureNone, kFractureNone, kFractureSplitting, kFractureSplitting, kFractureBending};
  r.floe_created_s = {0, 0, 0.15, 0.15, 0.2};
  r.floe_ended_s = {0.15, kInf, 0.2, kInf, kInf};
  r.fracture_time_s = {0.15, 0.2};
  r.fracture_parent_id = {1, 3};
  r.fracture_mode = {kFractureSplitting, kFractureBending};
  r.fracture_at_structure = {1, 0};
  r.fracture_force_n = {-2.5e6, 1e5, 0, 3e4, -2e4, -6e5};
  r.fracture_threshold_n = {2.4e6, 5.5e5};
  r.fracture_point_m = {10, 0.5, -0.2, 14, 3, 0.4};
  r.fracture_width_m = {1.2, 2.5};
  r.fracture_theta_rad = {0, 1.0471975511965976};
  r.fracture_brash_mass_kg = {0, 1234.5};
  r.fracture_child_offset = {0, 2, 3};
  r.fracture_child_id = {3, 4, 5};
  return r;
}

template <class T>
hid_t native();
template <>
hid_t native<double>() { return H5T_NATIVE_DOUBLE; }
template <>
hid_t native<int32_t>() { return H5T_NATIVE_INT32; }
template <>
hid_t native<int64_t>() { return H5T_NATIVE_INT64; }

// Edits a written file behind the writer's back (its checks would refuse the content), as a damaged or foreign
// file would come.
template <class T>
void replace_dataset(const fs::path& file, const std::string& name, const std::vector<T>& v, size_t cols) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0) << file;
  ASSERT_GE(H5Ldelete(f, name.c_str(), H5P_DEFAULT), 0) << name;
  const hsize_t dims[2] = {v.size() / cols, cols};
  const hid_t sp = H5Screate_simple(cols == 1 ? 1 : 2, dims, nullptr);
  const hid_t ds = H5Dcreate2(f, name.c_str(), native<T>(), sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(ds, 0) << name;
  if (!v.empty()) {
    EXPECT_GE(H5Dwrite(ds, native<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0) << name;
  }
  H5Dclose(ds);
  H5Sclose(sp);
  H5Fclose(f);
}

// Writes dataset `name` of the file from the same field of `r`.
void replace_from(const fs::path& file, const std::string& name, const Results& r) {
  if (name == "/geometry/floe_parent_id") return replace_dataset(file, name, r.floe_parent_id, 1);
  if (name == "/geometry/floe_generation") return replace_dataset(file, name, r.floe_generation, 1);
  if (name == "/geometry/floe_origin_mode") return replace_dataset(file, name, r.floe_origin_mode, 1);
  if (name == "/geometry/floe_created_s") return replace_dataset(file, name, r.floe_created_s, 1);
  if (name == "/geometry/floe_ended_s") return replace_dataset(file, name, r.floe_ended_s, 1);
  if (name == "/fracture/time_s") return replace_dataset(file, name, r.fracture_time_s, 1);
  if (name == "/fracture/parent_id") return replace_dataset(file, name, r.fracture_parent_id, 1);
  if (name == "/fracture/mode") return replace_dataset(file, name, r.fracture_mode, 1);
  if (name == "/fracture/force_n") return replace_dataset(file, name, r.fracture_force_n, 3);
  if (name == "/fracture/child_offset") return replace_dataset(file, name, r.fracture_child_offset, 1);
  if (name == "/fracture/child_id") return replace_dataset(file, name, r.fracture_child_id, 1);
  FAIL() << "the test cannot replace " << name;
}

// Replaces the root's "floesim" attribute (layout version and run settings).
void replace_attributes(const fs::path& file, const nlohmann::json& attrs) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0) << file;
  ASSERT_GE(H5Adelete(f, "floesim"), 0);
  const std::string text = attrs.dump();
  const hid_t st = H5Tcopy(H5T_C_S1);
  H5Tset_size(st, text.size() + 1);
  const hid_t sp = H5Screate(H5S_SCALAR);
  const hid_t at = H5Acreate2(f, "floesim", st, sp, H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(H5Awrite(at, st, text.c_str()), 0);
  H5Aclose(at);
  H5Sclose(sp);
  H5Tclose(st);
  H5Fclose(f);
}

using floesim::tests::error_of;

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
  EXPECT_EQ(back.state_in_contact, r.state_in_contact);
  EXPECT_EQ(back.attributes["time_step_s"], 0.01);
  fs::remove(a);
  fs::remove(b);
}

TEST(ResultsIo, OnlySeriesReadsThoseAndTimeAsTheWholeReadDoes) {
  const fs::path a = fs::temp_directory_path() / "floesim_results_only.h5";
  write_results(a, small_results(7));
  const Results all = read_results(a);
  const Results some = read_results(a, true, {"ice_load"});
  EXPECT_EQ(some.series.size(), 2u);  // ice_load and time_s
  EXPECT_EQ(some.get("ice_load"), all.get("ice_load"));
  EXPECT_EQ(some.get("time_s"), all.get("time_s"));
  EXPECT_THROW(some.get("hydro_load"), Error);
  EXPECT_EQ(some.state_body_id, all.state_body_id);
  fs::remove(a);
}

TEST(ResultsIo, FrameReplayRefusesOffsetsThatRunPastTheStates) {
  // Three frames over two state rows, the middle offset past the end: refused before any row is read.
  Results r = small_results(3);
  r.frame_time_s = {0.1, 0.2, 0.3};
  r.frame_offset = {0, 100, 1, 2};
  r.state_body_id = {0, 0};
  r.state_position_m.assign(6, 0.0);
  r.state_quaternion = {1, 0, 0, 0, 1, 0, 0, 0};
  r.state_in_contact = {0, 0};
  EXPECT_THROW(FrameReplay(r, "test"), Error);
  r.frame_offset = {0, 1, 1, 2};  // frame 1 stores nothing, not even the vessel
  EXPECT_THROW(FrameReplay(r, "test"), Error);
  r.frame_offset = {0, 1, 2, 2};
  r.state_body_id = {0, 0};
  EXPECT_THROW(FrameReplay(r, "test"), Error);  // frame 2 lacks the vessel
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

TEST(ResultsIo, FractureEventsAndLineageRoundTrip) {
  const fs::path p = fs::temp_directory_path() / "floesim_results_fracture.h5";
  const Results r = fractured_results();
  write_results(p, r);
  const Results b = read_results(p);
  EXPECT_EQ(b.attributes["layout"], "floesim-results/12");
  EXPECT_EQ(b.floe_id, r.floe_id);
  EXPECT_EQ(b.floe_vertices_m, r.floe_vertices_m);
  EXPECT_EQ(b.floe_parent_id, r.floe_parent_id);
  EXPECT_EQ(b.floe_generation, r.floe_generation);
  EXPECT_EQ(b.floe_origin_mode, r.floe_origin_mode);
  EXPECT_EQ(b.floe_created_s, r.floe_created_s);
  EXPECT_EQ(b.floe_ended_s, r.floe_ended_s) << "+inf (the floe lasted) must survive the file";
  EXPECT_EQ(b.fracture_time_s, r.fracture_time_s);
  EXPECT_EQ(b.fracture_parent_id, r.fracture_parent_id);
  EXPECT_EQ(b.fracture_mode, r.fracture_mode);
  EXPECT_EQ(b.fracture_at_structure, r.fracture_at_structure);
  EXPECT_EQ(b.fracture_force_n, r.fracture_force_n);
  EXPECT_EQ(b.fracture_threshold_n, r.fracture_threshold_n);
  EXPECT_EQ(b.fracture_point_m, r.fracture_point_m);
  EXPECT_EQ(b.fracture_width_m, r.fracture_width_m);
  EXPECT_EQ(b.fracture_theta_rad, r.fracture_theta_rad);
  EXPECT_EQ(b.fracture_brash_mass_kg, r.fracture_brash_mass_kg);
  EXPECT_EQ(b.fracture_child_offset, r.fracture_child_offset);
  EXPECT_EQ(b.fracture_child_id, r.fracture_child_id);
  EXPECT_EQ(b.get("fracture_events"), r.get("fracture_events"));
  EXPECT_EQ(b.get("floe_bodies"), r.get("floe_bodies"));
  // The plot reads without states; the fracture tables come all the same.
  EXPECT_EQ(read_results(p, /*with_states=*/false).fracture_child_id, r.fracture_child_id);
  EXPECT_STREQ(fracture_mode_name(b.fracture_mode[0]), "splitting");
  EXPECT_STREQ(fracture_mode_name(b.fracture_mode[1]), "bending");
  EXPECT_STREQ(fracture_mode_name(kFractureRadial), "radial");
  EXPECT_STREQ(fracture_mode_name(b.floe_origin_mode[0]), "input");
  EXPECT_THROW(fracture_mode_name(7), Error);
  fs::remove(p);
}

TEST(ResultsIo, InconsistentFractureTablesAreRefusedOnWriteAndOnReadNamingTheDataset) {
  struct Case {
    const char* dataset;  // named by the error
    const char* needle;   // what the error says about it
    std::function<void(Results&)> apply;
  };
  const std::vector<Case> cases = {
      {"/geometry/floe_parent_id", "expected 5", [](Results& r) { r.floe_parent_id.pop_back(); }},
      {"/geometry/floe_generation", "expected 5", [](Results& r) { r.floe_generation.push_back(1); }},
      {"/geometry/floe_origin_mode", "expected 5", [](Results& r) { r.floe_origin_mode.pop_back(); }},
      {"/geometry/floe_created_s", "expected 5", [](Results& r) { r.floe_created_s.pop_back(); }},
      {"/geometry/floe_ended_s", "expected 5", [](Results& r) { r.floe_ended_s.clear(); }},
      {"/fracture/parent_id", "expected 2", [](Results& r) { r.fracture_parent_id.pop_back(); }},
      {"/fracture/mode", "expected 2", [](Results& r) { r.fracture_mode.push_back(1); }},
      {"/fracture/force_n", "expected 2 x 3", [](Results& r) { r.fracture_force_n.resize(3); }},
      {"/fracture/child_offset", "expected 3", [](Results& r) { r.fracture_child_offset.pop_back(); }},
      {"/fracture/child_offset", "starts at 1", [](Results& r) { r.fracture_child_offset = {1, 2, 3}; }},
      {"/fracture/child_offset", "decreases", [](Results& r) { r.fracture_child_offset = {0, 3, 2}; }},
      {"/fracture/child_offset", "ends at 2", [](Results& r) { r.fracture_child_offset = {0, 1, 2}; }},
      {"/fracture/mode", "is 5", [](Results& r) { r.fracture_mode[1] = 5; }},
      {"/fracture/mode", "is 0", [](Results& r) { r.fracture_mode[0] = 0; }},
      {"/fracture/child_id", "99", [](Results& r) { r.fracture_child_id[2] = 99; }},
      {"/fracture/parent_id", "42", [](Results& r) { r.fracture_parent_id[0] = 42; }},
      {"/geometry/floe_parent_id", "77", [](Results& r) { r.floe_parent_id[4] = 77; }},
      {"/fracture/time_s", "decreases", [](Results& r) { r.fracture_time_s = {0.2, 0.15}; }},
  };
  const fs::path good = fs::temp_directory_path() / "floesim_results_fracture_good.h5";
  const fs::path bad = fs::temp_directory_path() / "floesim_results_fracture_bad.h5";
  fs::remove(bad);  // what a failed run of this test may have left
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.dataset) + ": " + c.needle);
    Results r = fractured_results();
    c.apply(r);
    // Write: an internal error of the simulator; no file appears.
    const std::string w = error_of([&] { write_results(bad, r); });
    EXPECT_NE(w.find(c.dataset), std::string::npos) << w;
    EXPECT_NE(w.find(c.needle), std::string::npos) << w;
    EXPECT_NE(w.find("internal"), std::string::npos) << w;
    EXPECT_FALSE(fs::exists(bad));
    // Read: the same inconsistency in a file (edited behind the writer's back) names the file and the dataset.
    write_results(good, fractured_results());
    replace_from(good, c.dataset, r);
    const std::string e = error_of([&] { read_results(good); });
    EXPECT_NE(e.find(good.string()), std::string::npos) << e;
    EXPECT_NE(e.find(c.dataset), std::string::npos) << e;
    EXPECT_NE(e.find(c.needle), std::string::npos) << e;
  }
  fs::remove(good);
}

TEST(ResultsIo, LayoutTwoFilesReadWithTheSolverSeriesNotRecorded) {
  // A floesim-results/2 file: today's writer, then the series /3 added removed and the layout set back. What it did
  // not record reads as NaN (unknown), never as a made-up zero; the rest is read as written.
  const fs::path p = fs::temp_directory_path() / "floesim_results_layout2.h5";
  const Results w = small_results(4);
  write_results(p, w);
  std::vector<std::string> added;
  for (const auto& f : series_fields())
    if (f.since == 3) added.push_back(f.name);
  ASSERT_FALSE(added.empty());
  {
    const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    for (const std::string& name : added) ASSERT_GE(H5Ldelete(f, ("/series/" + name).c_str(), H5P_DEFAULT), 0) << name;
    ASSERT_GE(H5Ldelete(f, "/states/in_contact", H5P_DEFAULT), 0);
    H5Fclose(f);
  }
  replace_attributes(p, {{"layout", "floesim-results/2"}, {"time_step_s", 0.01}});
  const Results r = read_results(p);
  for (const std::string& name : added) {
    ASSERT_EQ(r.get(name).size(), 4u) << name;
    for (double x : r.get(name)) EXPECT_TRUE(std::isnan(x)) << name;
  }
  EXPECT_EQ(r.get("solver_iterations"), w.get("solver_iterations"));
  EXPECT_EQ(r.get("fracture_events"), w.get("fracture_events"));
  fs::remove(p);
}

TEST(ResultsIo, LayoutThreeFilesReadWithNoFloeInContact) {
  // A floesim-results/3 file: today's writer, then /states/in_contact removed and the layout set back. Contact was
  // not recorded: every state reads as not in contact; the states themselves read as written.
  const fs::path p = fs::temp_directory_path() / "floesim_results_layout3.h5";
  const Results w = small_results(4);
  write_results(p, w);
  {
    const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    ASSERT_GE(H5Ldelete(f, "/states/in_contact", H5P_DEFAULT), 0);
    H5Fclose(f);
  }
  replace_attributes(p, {{"layout", "floesim-results/3"}, {"time_step_s", 0.01}});
  const Results r = read_results(p);
  EXPECT_EQ(r.state_body_id, w.state_body_id);
  EXPECT_EQ(r.state_in_contact, std::vector<int8_t>(4, 0));
  // A /4 file without the dataset is damaged: the error names it.
  replace_attributes(p, {{"layout", "floesim-results/4"}, {"time_step_s", 0.01}});
  const std::string e = error_of([&] { read_results(p); });
  EXPECT_NE(e.find("/states/in_contact"), std::string::npos) << e;
  fs::remove(p);
}

TEST(ResultsIo, LevelIceFlagRoundTripsAndLayoutFourFilesHaveNone) {
  // Layout /5 records which floes are level ice tiles; a /4 file (today's writer, the dataset removed, the layout
  // set back) has none; a /5 file without it is damaged and the error names it.
  const fs::path p = fs::temp_directory_path() / "floesim_results_layout4.h5";
  Results w = small_results(4);
  w.floe_level_ice = {1};
  write_results(p, w);
  EXPECT_EQ(read_results(p).floe_level_ice, std::vector<int8_t>{1});
  {
    const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    ASSERT_GE(H5Ldelete(f, "/geometry/floe_level_ice", H5P_DEFAULT), 0);
    H5Fclose(f);
  }
  replace_attributes(p, {{"layout", "floesim-results/4"}, {"time_step_s", 0.01}});
  EXPECT_EQ(read_results(p).floe_level_ice, std::vector<int8_t>{0});
  replace_attributes(p, {{"layout", "floesim-results/5"}, {"time_step_s", 0.01}});
  const std::string e = error_of([&] { read_results(p); });
  EXPECT_NE(e.find("/geometry/floe_level_ice"), std::string::npos) << e;
  // Written with a flag per floe or none (all 0), never with a wrong count.
  w.floe_level_ice = {1, 0};
  EXPECT_THROW(write_results(p, w), Error);
  fs::remove(p);
}

TEST(ResultsIo, LayoutOneFilesFromBeforeFractureReadWithDefaults) {
  // A floesim-results/1 file: today's writer, then what /1 did not have removed and the layout set back.
  const fs::path p = fs::temp_directory_path() / "floesim_results_layout1.h5";
  write_results(p, small_results(4));
  {
    const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    for (const char* name : {"/fracture", "/geometry/floe_parent_id", "/geometry/floe_generation",
                             "/geometry/floe_origin_mode", "/geometry/floe_created_s", "/geometry/floe_ended_s",
                             "/series/fracture_events", "/series/floe_bodies", "/states/in_contact"})
      ASSERT_GE(H5Ldelete(f, name, H5P_DEFAULT), 0) << name;
    H5Fclose(f);
  }
  replace_attributes(p, {{"layout", "floesim-results/1"}, {"time_step_s", 0.01}});
  const Results r = read_results(p);
  EXPECT_EQ(r.attributes["layout"], "floesim-results/1");
  EXPECT_EQ(r.floe_id, std::vector<int32_t>{1});
  EXPECT_EQ(r.floe_parent_id, std::vector<int32_t>{-1});
  EXPECT_EQ(r.floe_generation, std::vector<int32_t>{0});
  EXPECT_EQ(r.floe_origin_mode, std::vector<int32_t>{kFractureNone});
  EXPECT_EQ(r.floe_created_s, std::vector<double>{0.0});
  EXPECT_EQ(r.floe_ended_s, std::vector<double>{kInf});
  EXPECT_TRUE(r.fracture_time_s.empty());
  EXPECT_TRUE(r.fracture_child_id.empty());
  EXPECT_EQ(r.fracture_child_offset, std::vector<int64_t>{0});
  EXPECT_EQ(r.get("fracture_events"), std::vector<double>(4, 0.0));
  EXPECT_EQ(r.get("floe_bodies"), std::vector<double>(4, 1.0)) << "every floe was a body for the whole run";
  EXPECT_EQ(r.get("ice_load").size(), 4u * 6u);
  // Rewritten, it becomes a file of the current layout with the same content.
  const fs::path q = fs::temp_directory_path() / "floesim_results_layout1_rewritten.h5";
  write_results(q, r);
  EXPECT_EQ(read_results(q).attributes["layout"], "floesim-results/12");
  fs::remove(q);

  // A layout from the future is refused, naming it.
  write_results(p, small_results(2));
  replace_attributes(p, {{"layout", "floesim-results/13"}});
  const std::string e = error_of([&] { read_results(p); });
  EXPECT_NE(e.find("floesim-results/13"), std::string::npos) << e;
  fs::remove(p);
}

// Damaged files the reader once mis-read (found while fuzzing it, tests/fuzz/fuzz_results): each is a clear Error
// naming the dataset, never an overrun buffer, a huge allocation or a nlohmann exception.
TEST(ResultsIo, DamagedShapesAttributesAndOffsetsAreClearErrors) {
  const fs::path p = fs::temp_directory_path() / "floesim_results_damaged.h5";
  auto fresh = [&] { write_results(p, small_results(3)); };
  auto expect_error = [&](const std::string& what) {
    const std::string e = error_of([&] { read_results(p); });
    EXPECT_NE(e.find(what), std::string::npos) << "expected '" << what << "', got: " << e;
  };
  // A dataset of rank 3 (its dimensions used to be read into an array of two).
  fresh();
  {
    const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(H5Ldelete(f, "/frames/time_s", H5P_DEFAULT), 0);
    const hsize_t dims[3] = {2, 1, 1};
    const hid_t sp = H5Screate_simple(3, dims, nullptr);
    const hid_t ds = H5Dcreate2(f, "/frames/time_s", H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dclose(ds);
    H5Sclose(sp);
    H5Fclose(f);
  }
  expect_error("dataset /frames/time_s has rank 3");
  // A dataset that claims far more rows than the file holds (chunked, nothing written: only fill values).
  fresh();
  {
    const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(H5Ldelete(f, "/states/body_id", H5P_DEFAULT), 0);
    const hsize_t dims[1] = {hsize_t(1) << 40}, chunk[1] = {1024};
    const hid_t sp = H5Screate_simple(1, dims, nullptr);
    const hid_t pl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(pl, 1, chunk);
    const hid_t ds = H5Dcreate2(f, "/states/body_id", H5T_NATIVE_INT32, sp, H5P_DEFAULT, pl, H5P_DEFAULT);
    ASSERT_GE(ds, 0);
    H5Dclose(ds);
    H5Pclose(pl);
    H5Sclose(sp);
    H5Fclose(f);
  }
  expect_error("dataset /states/body_id claims 1099511627776 rows");
  // The attribute: not an object, a layout that is not a string, an array of strings.
  fresh();
  replace_attributes(p, 5);
  expect_error("the 'floesim' attribute is not a JSON object");
  fresh();
  replace_attributes(p, {{"layout", 3}});
  expect_error("layout ? is not supported");
  fresh();
  {
    const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(H5Adelete(f, "floesim"), 0);
    const hid_t st = H5Tcopy(H5T_C_S1);
    H5Tset_size(st, 4);
    const hsize_t n[1] = {3};
    const hid_t sp = H5Screate_simple(1, n, nullptr);
    const hid_t at = H5Acreate2(f, "floesim", st, sp, H5P_DEFAULT, H5P_DEFAULT);
    EXPECT_GE(H5Awrite(at, st, "{}\0\0{}\0\0{}\0\0"), 0);
    H5Aclose(at);
    H5Sclose(sp);
    H5Tclose(st);
    H5Fclose(f);
  }
  expect_error("the 'floesim' attribute is not one JSON string");
  // Offsets and indices that point outside their arrays (a reader of the frames would have run past them).
  fresh();
  replace_dataset<int64_t>(p, "/frames/offset", {0, 3, 2}, 1);
  expect_error("/frames/offset decreases at row 2");
  fresh();
  replace_dataset<int64_t>(p, "/geometry/floe_vertex_offset", {0, 7}, 1);
  expect_error("/geometry/floe_vertex_offset ends at 7, but /geometry/floe_vertices_m has 3 rows");
  fresh();
  replace_dataset<int32_t>(p, "/geometry/hull_triangles", {0, 1, 9}, 3);
  expect_error("/geometry/hull_triangles names vertex 9");
  fresh();
  replace_dataset<double>(p, "/states/quaternion_wxyz", {1, 0, 0, 0}, 4);
  expect_error("/states arrays have different lengths");
  fs::remove(p);
}

namespace {

// A string attribute of an HDF5 object as its strings (one for a scalar), read with the C API alone.
std::vector<std::string> string_attribute(hid_t obj, const char* key) {
  if (H5Aexists(obj, key) <= 0) return {};
  const hid_t at = H5Aopen(obj, key, H5P_DEFAULT), type = H5Aget_type(at), space = H5Aget_space(at);
  const size_t size = H5Tget_size(type), n = static_cast<size_t>(H5Sget_simple_extent_npoints(space));
  std::string buf(size * n, '\0');
  const hid_t mem = H5Tcopy(H5T_C_S1);
  H5Tset_size(mem, size);
  H5Tset_strpad(mem, H5T_STR_NULLPAD);
  H5Aread(at, mem, buf.data());
  std::vector<std::string> out;
  for (size_t k = 0; k < n; ++k) {
    std::string v = buf.substr(k * size, size);
    out.push_back(v.substr(0, v.find('\0')));
  }
  H5Tclose(mem), H5Sclose(space), H5Tclose(type), H5Aclose(at);
  return out;
}

struct DatasetSeen {
  std::string path;
  size_t cols;
  std::vector<std::string> unit, columns, column_units, doc;
};

herr_t visit_dataset(hid_t obj, const char* name, const H5O_info_t* info, void* data) {
  if (info->type != H5O_TYPE_DATASET) return 0;
  const hid_t ds = H5Dopen2(obj, name, H5P_DEFAULT), space = H5Dget_space(ds);
  hsize_t dims[2] = {0, 1};
  H5Sget_simple_extent_dims(space, dims, nullptr);
  const size_t cols = H5Sget_simple_extent_ndims(space) == 2 ? dims[1] : 1;
  static_cast<std::vector<DatasetSeen>*>(data)->push_back(
      {std::string("/") + name, cols, string_attribute(ds, "unit"), string_attribute(ds, "columns"),
       string_attribute(ds, "column_units"), string_attribute(ds, "doc")});
  H5Sclose(space), H5Dclose(ds);
  return 0;
}

}  // namespace

// Layout /11: every dataset the file holds, whatever writes it, names its columns and units, one per column of its
// own shape; the loads' six columns are three forces in N and three moments in N m.
TEST(ResultsLayout, EveryDatasetCarriesItsUnitAndColumnNames) {
  Results r = small_results(3);
  r.attributes["structures"] = {{{"name", "buoy"}, {"columns", {{"line_tension_n", 2}, {"part_force_n", 6}}}}};
  r.structure_series["buoy/line_tension_n"] = std::vector<double>(3 * 2, 1.0);
  r.structure_series["buoy/part_force_n"] = std::vector<double>(3 * 6, 2.0);
  r.structure_hull_vertices_m["buoy"] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  r.structure_hull_triangles["buoy"] = {0, 1, 2};
  const fs::path p = fs::temp_directory_path() / "floesim_results_attributes.h5";
  write_results(p, r);
  std::vector<DatasetSeen> seen;
  const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  H5Ovisit2(f, H5_INDEX_NAME, H5_ITER_NATIVE, visit_dataset, &seen, H5O_INFO_BASIC);
  H5Fclose(f);
  fs::remove(p);
  ASSERT_GT(seen.size(), series_fields().size() + 30);
  std::map<std::string, DatasetSeen> by_path;
  for (const DatasetSeen& d : seen) {
    by_path[d.path] = d;
    EXPECT_EQ(d.unit.size(), 1u) << d.path;
    EXPECT_EQ(d.doc.size(), 1u) << d.path;
    EXPECT_FALSE(d.doc.empty() || d.doc[0].empty()) << d.path;
    EXPECT_EQ(d.columns.size(), d.cols) << d.path << ": one name per column";
    EXPECT_EQ(d.column_units.size(), d.cols) << d.path << ": one unit per column";
    for (const std::string& c : d.columns) EXPECT_FALSE(c.empty() || c.find(' ') != std::string::npos) << d.path;
  }
  EXPECT_EQ(by_path["/series/ice_load"].columns, (std::vector<std::string>{"Fx", "Fy", "Fz", "Mx", "My", "Mz"}));
  EXPECT_EQ(by_path["/series/ice_load"].column_units, (std::vector<std::string>{"N", "N", "N", "N m", "N m", "N m"}));
  EXPECT_EQ(by_path["/series/station_offset"].column_units, (std::vector<std::string>{"m", "m", "rad"}));
  EXPECT_EQ(by_path["/states/quaternion_wxyz"].columns, (std::vector<std::string>{"w", "x", "y", "z"}));
  EXPECT_EQ(by_path["/frames/time_s"].unit, std::vector<std::string>{"s"});
  EXPECT_EQ(by_path["/structures/buoy/line_tension_n"].columns, (std::vector<std::string>{"line1", "line2"}));
  EXPECT_EQ(by_path["/structures/buoy/part_force_n"].columns,
            (std::vector<std::string>{"part1.x", "part1.y", "part1.z", "part2.x", "part2.y", "part2.z"}));
  // Every dataset of the file is in the layout's table, and every one of the table in the file.
  for (const DatasetSpec& d : results_datasets()) {
    std::string path = d.path;
    if (path.rfind("/structures/NAME/", 0) == 0) {
      if (path.find("line_tension") == std::string::npos && path.find("part_force") == std::string::npos &&
          path.find("hull_") == std::string::npos)
        continue;  // this structure records only those two fields
      path.replace(12, 4, "buoy");
    }
    EXPECT_TRUE(by_path.count(path)) << path << " is in the table but not in the file";
  }
}

// pipeline/results-layout.md is the code's table: regenerate it when the layout changes.
TEST(ResultsLayout, TheGuideIsTheCodesTable) {
  const fs::path guide = fs::path(FLOESIM_SOURCE_DIR) / "pipeline" / "results-layout.md";
  EXPECT_EQ(floesim::tests::read_text(guide), results_layout_markdown())
      << guide << " is stale: rewrite it with `build/bin/floesim-simulate --results-layout > pipeline/results-layout.md`";
}
