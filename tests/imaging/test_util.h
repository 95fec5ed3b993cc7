// Helpers shared by the imaging tests: a scratch directory per test and file listing.
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

namespace floesim::imaging::test {

// A fresh, empty directory named after the running test; removed when the object goes out of scope.
struct ScratchDir {
  std::filesystem::path path;
  ScratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = std::filesystem::temp_directory_path() / ("floesim_imaging_" + std::string(info->test_suite_name()) + "_" +
                                                     info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

inline std::vector<std::string> list_dir(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  if (!std::filesystem::exists(dir)) return names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

inline std::filesystem::path shared_data(const std::string& rel) {
  const std::filesystem::path p = std::filesystem::path(FLOESIM_SHARED_DATA_DIR) / rel;
  if (!std::filesystem::exists(p))
    ADD_FAILURE() << "test data missing: " << p
                  << " (FLOESIM_SHARED_DATA_DIR must point at ../shared/data; CI always has it)";
  return p;
}

}  // namespace floesim::imaging::test
