// A case planned as stages: which executable reads which files and writes which, with what settings. `floesim run`
// places the stages in the fixed folders of one run; `floesim sweep` places each in a folder named by its content
// key, so that members of a sweep that need the same stage with the same settings and inputs share one instance.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace floesim::runner {

struct Artefact {
  std::string stage, file, content;
};

struct PlannedStage {
  std::string name, description;
  std::string section;                  // the key path of its settings in the case file ("simulate", "hull.generate";
                                        // "" when they are not the case's)
  // Content key: a digest of the stage's name, its settings and the keys (or, for the case's own files, the
  // contents) of everything it reads. Equal keys mean equal outputs: the stages are deterministic.
  std::string key;
  std::filesystem::path dir;            // its outputs' folder
  std::filesystem::path config;         // its settings file
  std::string config_text;              // ... and what goes in it
  std::vector<std::filesystem::path> inputs;   // files it reads, its settings file included
  std::vector<std::filesystem::path> outputs;  // files it writes (the first is its main artefact)
  std::filesystem::path exe;
  std::vector<std::string> args;        // command-line arguments (unquoted)
  // The stage continues from its checkpoint when the runner is asked to (`floesim run --resume`): its command
  // passes --resume when FLOESIM_RESUME is set in the environment. Through the environment, not the command text,
  // so that ninja (which reruns a stage whose command changed) sees the same command with and without --resume.
  bool resumable = false;
};

// Where a stage's outputs and settings file go, from its name and content key.
struct StageLayout {
  std::function<std::filesystem::path(const std::string& stage, const std::string& key)> dir, config;
};

struct CasePlan {
  std::vector<PlannedStage> stages;  // in an order in which every stage comes after the stages it reads from
  std::vector<Artefact> artefacts;   // for the closing table of `floesim run` (paths relative to a run folder)
  std::filesystem::path results, summary;
};

// The stages a case runs; `render` false leaves out the video, `report` false the HTML report (which reads a run
// folder's layout: `floesim run` only). Validates the case's top level and its own files
// (relative names resolve against case_dir); errors begin with `where` (the case file, or a sweep's member). Stage
// settings are checked by the stages themselves (`--check-config`), not here.
CasePlan plan_case(const nlohmann::json& c, const std::string& where,
                   const std::filesystem::path& case_dir, const std::filesystem::path& bin,
                   const StageLayout& layout, bool render = true, bool report = false);

// POSIX shell quoting of one word.
std::string shell_quote(const std::string& s);
// A stage's command line for a POSIX shell.
std::string shell_command(const PlannedStage& s);

// How each stage's command is wrapped in the Ninja file (and in cluster job scripts).
enum class StageOutput {
  console,  // the stage writes to the terminal (floesim run)
  logged,   // to DIR/log.txt, its wall time in milliseconds to DIR/wall_ms, the log's tail on failure (sweeps)
};

// The shell command that runs stage k of `stages`: first removes its outputs and those of every stage downstream
// of them (a failed stage then leaves nothing that looks complete) and the temporary files a killed run of it left
// in its folder (pipeline/atomic_file.h; one stage instance runs at a time in a folder), then runs it. `logged` keeps that list in
// DIR/downstream.txt (written here), out of the command: a sweep's shared stage keeps its command, and so is not
// rerun, when members are added downstream of it.
std::string stage_script(const std::vector<PlannedStage>& stages, size_t k, StageOutput output);

// Writes a Ninja file with one edge per stage (outputs <- inputs | executable) and the given description per stage;
// the file is rewritten only when its content changes.
void write_ninja(const std::filesystem::path& file, const std::string& header,
                 const std::vector<PlannedStage>& stages, const std::vector<std::string>& descriptions,
                 StageOutput output);

// The folder of a stage's outputs in a run folder: image, floes, hull, sim, video, plots, report.
std::string run_folder(const std::string& stage);

// The case's own files (image.file, floes.file, hull.file, simulate.vessel.propulsion.thrust_file) made absolute
// against case_dir, so that the case can be run from another folder.
void absolute_case_files(nlohmann::json& c, const std::filesystem::path& case_dir);

// Writes text only if the file's content differs, so that its modification time marks real changes only.
void write_if_changed(const std::filesystem::path& file, const std::string& text);

// Folder of the running executable (the stage executables are installed beside it).
std::filesystem::path self_dir();

}  // namespace floesim::runner
