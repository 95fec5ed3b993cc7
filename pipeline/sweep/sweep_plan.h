// The sweep plan (RUN/plan.json), its one home: `floesim sweep` writes it (pipeline/runner/sweep.cpp) and the
// gather reads it (pipeline/sweep/gather.h). It names the sweep's axes, its grid points and every member: its axis
// values and seeds, its summary and results, and its stages with their outputs, logs and wall times.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/options.h"

namespace floesim::sweep {

inline constexpr const char* kSweepPlanFormat = "floesim-sweep-plan/1";

struct PlanAxis {
  std::string key;                 // a case key path, e.g. "simulate.vessel.propulsion.speed_mps"
  std::vector<std::string> paths;  // every case key path the axis sets (the key and those it drives together)
  std::vector<Json> values;        // numbers, strings or booleans, in sweep order
  // A reader's name for it, from the option's own description (axis_label): "level ice: thickness of the sheet (m)";
  // its unit ("-": none) and the option's meaning as the stage documents it. Empty in a plan that does not give them.
  std::string label, unit, doc;
};

// The name a reader sees for an axis: label if the plan gives one, else the key.
inline const std::string& axis_title(const PlanAxis& a) { return a.label.empty() ? a.key : a.label; }

// A reader's name for the option at `field` (its key path inside its stage's settings: "level_ice.thickness_m",
// "ridges.0.keel_depth_m") from its unit and meaning: the meaning's head (up to its first ": ", " (", "; " or ", ";
// after a first "name: " that only restates the key) after the sections it is in, with the unit: "level ice:
// thickness of the sheet (m)", "ridge 1: keel draft (m)", "vessel propulsion: prescribed forward speed through the
// water (m/s)".
// Without a meaning, the field's own name in words ("initial speed (m/s)").
std::string axis_label(const std::string& field, const std::string& unit, const std::string& doc);

// A key path with list indices as the options' description names a list item's fields: "ridges.0.keel_depth_m" ->
// "ridges[].keel_depth_m".
std::string list_item_path(const std::string& field);

struct PlanStage {
  std::string name;                             // "synth", "digitise", ... (the member's stages are in run order)
  std::filesystem::path dir;                    // its folder (informational)
  std::vector<std::filesystem::path> outputs;   // the artefacts it makes
  std::filesystem::path log;                    // its stdout and stderr ("" if the plan gives none)
  std::filesystem::path wall_ms;                // one integer: milliseconds it took ("" if the plan gives none)
};

struct PlanMember {
  std::string id;               // e.g. "g000-e00"
  size_t grid_point = 0;        // index into SweepPlan::grid_points
  size_t ensemble_index = 0;
  Json axes = Json::object();   // axis key -> value (those of its grid point)
  Json seeds = Json::object();  // key the ensemble set -> value (may be empty)
  std::filesystem::path dir, summary, results;
  std::vector<PlanStage> stages;
};

struct PlanGridPoint {
  size_t index = 0;
  Json axes = Json::object();  // axis key -> value
};

struct SweepPlan {
  std::string name;
  std::string sweep_file;      // informational ("" if absent)
  std::string base_case;       // informational: the base case's folder
  std::string combine;         // informational: "grid" or "zip"
  std::vector<PlanAxis> axes;  // empty: a pure ensemble
  Json ensemble = nullptr;     // informational, copied into sweep.json
  std::vector<PlanGridPoint> grid_points;
  std::vector<PlanMember> members;
};

// The plan as plan.json holds it (format kSweepPlanFormat), paths as they are.
Json sweep_plan_json(const SweepPlan& plan);

// Reads a plan: format "floesim-sweep-plan/1" (any other is an error), then every problem at once, each naming the
// file and the key path ("plan.json: members[2].summary is missing"). Keys the reader does not know are ignored:
// the plan is written by a program, not by hand, and an incompatible change bumps the format. Relative paths are
// taken from the plan's folder.
SweepPlan read_sweep_plan(const std::filesystem::path& file);

// A value as text: strings as they are, numbers and booleans as JSON writes them.
std::string value_text(const Json& v);

}  // namespace floesim::sweep
