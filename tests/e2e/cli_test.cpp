// The command line as a newcomer meets it: `floesim --help` names every stage executable that is built, `floesim
// run CASE --check` checks every section of a case with its stage and names each problem by its key in case.json
// (with the key it most likely meant), a run with a bad setting writes nothing, and every JSON example of the
// README is a valid case fragment (merged into the default case and checked as `floesim run --check` would).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <unistd.h>

#include "pipeline/options.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;
using namespace floesim;
using floesim::tests::read_text;

namespace {

const fs::path kBin = FLOESIM_BIN_DIR;
const fs::path kSource = FLOESIM_SOURCE_DIR;

using RunOutput = floesim::tests::CommandOutput;

// floesim with `args` (shell words), its output into `log`.
RunOutput run(const std::string& args, const fs::path& log) {
  return floesim::tests::run_logged("'" + (kBin / "floesim").string() + "' " + args, log);
}

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("floesim_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A copy of the default case (its case.json and the files it owns) in `dir`, with `edit` applied to its case.json.
void write_case(const fs::path& dir, const Json& c) {
  fs::create_directories(dir);
  for (const auto& e : fs::directory_iterator(kSource / "cases" / "default"))
    if (e.path().filename() != "case.json") fs::copy(e.path(), dir / e.path().filename());
  std::ofstream(dir / "case.json") << c.dump(2);
}

// `patch` merged into `base`, objects key by key (RFC 7386 without deletion).
void merge(Json& base, const Json& patch) {
  for (auto it = patch.begin(); it != patch.end(); ++it) {
    if (it->is_object() && base.contains(it.key()) && base[it.key()].is_object()) merge(base[it.key()], *it);
    else base[it.key()] = *it;
  }
}

// Relative "file" values of a README example are written from a case folder of the repository (cases/<name>/):
// made absolute from there, so that the example is checked against the files it names.
void absolute_files(Json& j) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it->is_object()) absolute_files(*it);
    else if ((it.key() == "file" || it.key() == "thrust_file") && it->is_string() &&
             fs::path(it->get<std::string>()).is_relative())
      *it = (kSource / "cases" / "example" / it->get<std::string>()).lexically_normal().string();
  }
}

}  // namespace

// Every floesim-* executable of the build (but the benchmark) has its line in the runner's help.
TEST(Cli, HelpNamesEveryStageExecutable) {
  const fs::path d = scratch("help");
  const RunOutput out = run("--help", d / "help.txt");
  ASSERT_EQ(out.code, 0) << out.text;
  int stages = 0;
  for (const auto& e : fs::directory_iterator(kBin)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("floesim-", 0) != 0 || name == "floesim-bench") continue;
    ++stages;
    EXPECT_NE(out.text.find("  " + name + " "), std::string::npos) << name << " is missing from floesim --help:\n"
                                                                      << out.text;
  }
  EXPECT_GE(stages, 12);
  fs::remove_all(d);
}

// Typos in two sections: both reported at once as case.json key paths with the key they meant, exit 1, and the
// run folder never made; the same case checked clean once corrected.
TEST(Cli, CheckNamesEveryProblemByItsCaseKeyAndWritesNothing) {
  const fs::path d = scratch("check");
  Json c = load_json_file(kSource / "cases" / "default" / "case.json");
  c["simulate"]["duraton_s"] = 10;
  c["hull"]["generate"]["lenght_m"] = 100;
  write_case(d / "case", c);
  const RunOutput bad = run("run '" + (d / "case").string() + "' --check --out '" + (d / "run").string() + "'",
                            d / "check.txt");
  EXPECT_EQ(bad.code, 1) << bad.text;
  EXPECT_NE(bad.text.find("simulate.duraton_s is not a known key; did you mean duration_s?"), std::string::npos)
      << bad.text;
  EXPECT_NE(bad.text.find("hull.generate.lenght_m is not a known key; did you mean length_m?"), std::string::npos)
      << bad.text;
  EXPECT_EQ(bad.text.find("ninja"), std::string::npos) << bad.text;
  EXPECT_FALSE(fs::exists(d / "run"));

  // A run (not only --check) refuses the same case before it writes anything.
  const RunOutput refused = run("run '" + (d / "case").string() + "' --out '" + (d / "run").string() + "'",
                                d / "run.txt");
  EXPECT_EQ(refused.code, 1) << refused.text;
  EXPECT_NE(refused.text.find("simulate.duraton_s"), std::string::npos) << refused.text;
  EXPECT_FALSE(fs::exists(d / "run" / "build.ninja"));
  EXPECT_FALSE(fs::exists(d / "run" / "config"));

  c["simulate"].erase("duraton_s");
  c["hull"]["generate"].erase("lenght_m");
  std::ofstream(d / "case" / "case.json") << c.dump(2);
  const RunOutput good = run("run '" + (d / "case").string() + "' --check", d / "good.txt");
  EXPECT_EQ(good.code, 0) << good.text;
  EXPECT_NE(good.text.find("are valid"), std::string::npos) << good.text;
  fs::remove_all(d);
}

// Every ```json block of README.md is a fragment of a case: merged into the default case, `floesim run --check`
// accepts it (each stage checks its own section, strictly). A README example that a stage refuses fails here.
TEST(Cli, EveryReadmeJsonExampleIsAValidCase) {
  const std::string readme = read_text(kSource / "README.md");
  const std::regex block("```json\\n([\\s\\S]*?)```");
  const fs::path d = scratch("readme");
  int checked = 0;
  for (std::sregex_iterator it(readme.begin(), readme.end(), block), end; it != end; ++it) {
    const std::string text = (*it)[1].str();
    Json snippet;
    ASSERT_NO_THROW(snippet = Json::parse(text, nullptr, true, /*ignore_comments=*/true)) << text;
    ASSERT_TRUE(snippet.is_object()) << text;
    Json c = load_json_file(kSource / "cases" / "default" / "case.json");
    // An example that brings its own floes or image replaces the default's source of floes.
    if (snippet.contains("floes")) c.erase("image"), c.erase("digitise");
    if (snippet.contains("image")) c.erase("image");
    if (snippet.contains("hull")) c.erase("hull");
    merge(c, snippet);
    absolute_files(c);
    const fs::path dir = d / ("example" + std::to_string(checked++));
    write_case(dir, c);
    const RunOutput out = run("run '" + dir.string() + "' --check", dir.string() + ".txt");
    EXPECT_EQ(out.code, 0) << "README example:\n" << text << "\n" << out.text;
  }
  EXPECT_GE(checked, 3) << "the README's examples were not found (```json blocks)";
  fs::remove_all(d);
}
