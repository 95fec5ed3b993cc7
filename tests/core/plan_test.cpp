#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pipeline/error.h"
#include "pipeline/runner/plan.h"

using namespace floesim;
namespace fs = std::filesystem;

namespace {
std::string plan_error(const nlohmann::json& c, const fs::path& dir) {
  runner::StageLayout layout;
  layout.dir = [](const std::string& s, const std::string&) { return fs::path("/run") / s; };
  layout.config = [](const std::string& s, const std::string&) { return fs::path("/run/config") / (s + ".json"); };
  try {
    runner::plan_case(c, "case.json", dir, "/bin", layout);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

// A case's own file must be a file: a folder was hashed as if it were empty and a device (/dev/zero) read forever
// (tests/fuzz/fuzz_case).
TEST(Plan, CaseFilesMustBeRegularFiles) {
  const fs::path dir = fs::temp_directory_path() / "floesim_plan_test";
  fs::create_directories(dir);
  for (const char* name : {".", "", "/dev/zero"}) {
    const std::string e = plan_error({{"floes", {{"file", name}}}}, dir);
    EXPECT_NE(e.find("floes.file names"), std::string::npos) << name << ": " << e;
    EXPECT_NE(e.find("which is not a file"), std::string::npos) << name << ": " << e;
  }
  std::ofstream(dir / "floes.geojson") << "{}";
  std::ofstream(dir / "hull.obj") << "";
  EXPECT_EQ(plan_error({{"floes", {{"file", "floes.geojson"}}}, {"hull", {{"file", "hull.obj"}}}}, dir), "");
  fs::remove_all(dir);
}
