// A case file through the runner's planning (pipeline/runner/plan.h plan_case): the top level, the case's own files
// (relative names resolve against an empty temporary case folder), the stages and their settings files' text.
#include <filesystem>

#include "fuzz_util.h"
#include "pipeline/options.h"
#include "pipeline/runner/plan.h"

namespace fs = std::filesystem;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const auto file = floesim::fuzz::temp_file(".case.json");
  static const fs::path case_dir = [] {
    fs::path d = floesim::fuzz::temp_file(".case");
    fs::create_directories(d);
    return d;
  }();
  floesim::fuzz::write_input(file, data, size);
  floesim::fuzz::expect_ok_or_error([&] {
    floesim::Json c = floesim::load_json_file(file);
    floesim::runner::StageLayout layout;
    layout.dir = [](const std::string& stage, const std::string&) {
      return fs::path("/nonexistent/run") / floesim::runner::run_folder(stage);
    };
    layout.config = [](const std::string& stage, const std::string&) {
      return fs::path("/nonexistent/run/config") / (stage + ".json");
    };
    const auto plan = floesim::runner::plan_case(c, file.string(), case_dir, "/nonexistent/bin", layout,
                                                 /*render=*/true, /*report=*/true);
    for (const auto& s : plan.stages) (void)floesim::runner::shell_command(s);
    floesim::runner::absolute_case_files(c, case_dir);
  });
  return 0;
}
