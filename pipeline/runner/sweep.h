// Sweeps: one command runs a grid of variants of a case (axes: any case key path and its values) times an
// ensemble of starts, on this machine through one Ninja file or on a SLURM cluster through sbatch job arrays.
//
// cases/<name>/sweep.json:
//   {"description": "...",
//    "base": "../default",                       base case folder (relative to the sweep's folder)
//    "axes": [{"key": "simulate.vessel.propulsion.speed_mps", "values": [1, 2, 3]}, ...],
//                                                "keys": [...] instead of "key" sets several paths to each value
//    "combine": "grid",                          or "zip" (axes of equal length, taken together)
//    "ensemble": {"size": 3, "vary": ["field_seed", "start"], "start_step_m": 0.001},
//    "set": {"simulate.duration_s": 100},        key paths set in every member
//    "render": false,                            render each member's video (off: sweeps want numbers)
//    "slurm": {"partition": "", "time": "01:00:00", "mem": "4G", "cpus_per_task": 1, "account": ""}}
//
// Every stage instance lives in RUN/stages/<stage>-<content key>/: members that need the same stage with the same
// settings and inputs share it (members differing only in speed share image, floes and hull). Each member is a run
// folder RUN/members/<id>/ (its case.json and links to its stages' folders); RUN/plan.json lists members and stages
// for floesim-gather, which writes RUN/sweep.csv, RUN/sweep.json and the plots.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace floesim::runner {

struct SweepOptions {
  std::filesystem::path sweep_dir;  // folder holding sweep.json
  std::filesystem::path run_dir;    // default runs/<sweep folder name>
  std::filesystem::path bin_dir;    // stage executables (default: beside the runner)
  int jobs = 0;                     // stages run in parallel (ninja -j; 0 = ninja's default)
  bool dry_run = false;             // plan, validate and show what would run; run nothing
  bool yes = false;                 // allow more than kMaxMembersUnasked members
  bool slurm = false;               // submit to SLURM (sbatch job arrays) instead of running here
  bool wait = false;                // with slurm: block until the gather job has finished
  bool resume = false;              // members' simulations continue from their checkpoints (FLOESIM_RESUME)
};

// Sweeps larger than this need --yes (a typo in an axis can ask for thousands of runs).
constexpr int kMaxMembersUnasked = 64;

// An axis sets one key path ("key") or several to the same value ("keys": e.g. the target speed and the initial
// speed); it is named by its first key path.
struct SweepAxis {
  std::string key;
  std::vector<std::string> paths;
  std::vector<nlohmann::json> values;
};

struct SlurmSettings {
  std::string partition, account;   // empty: the cluster's default
  std::string time = "01:00:00";    // per stage instance (--time)
  std::string mem = "4G";           // per stage instance (--mem)
  int cpus_per_task = 1;
};

struct Sweep {
  std::filesystem::path file, base_dir;
  std::string name, description;
  std::vector<SweepAxis> axes;
  bool zip = false;
  int ensemble_size = 1;
  bool vary_field_seed = false, vary_start = false;
  double start_step_m = 0.001;
  nlohmann::json set = nlohmann::json::object();
  bool render = false;
  SlurmSettings slurm;
};

// Reads and validates SWEEP_DIR/sweep.json (unknown keys, empty axes, zip lengths...): errors name the file and key.
Sweep read_sweep(const std::filesystem::path& sweep_dir);

struct Member {
  std::string id;                  // g<grid point>-e<ensemble index>
  int grid_point = 0, ensemble_index = 0;
  nlohmann::json axes = nlohmann::json::object();   // axis key -> value
  nlohmann::json seeds = nlohmann::json::object();  // what the ensemble set: key path -> value
  nlohmann::json case_json;        // the base case with set, axes and seeds applied
};

// Sets a dotted key path ("simulate.vessel.y_m") in a case, making intermediate objects; `where` names the setting
// in errors.
void set_key_path(nlohmann::json& c, const std::string& path, const nlohmann::json& value, const std::string& where);

// The members: grid points (grid or zip of the axes) x ensemble, in that order.
std::vector<Member> expand_members(const Sweep& s, const nlohmann::json& base_case);

// Plans, validates every member's stage settings with the stages themselves, writes RUN/ and runs (or submits) it.
// Returns 0 when every member finished.
int run_sweep(const SweepOptions& o);

}  // namespace floesim::runner
