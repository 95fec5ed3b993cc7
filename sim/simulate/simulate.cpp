#include "sim/simulate/simulate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <sys/resource.h>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/floes_io.h"
#include "pipeline/interrupt.h"
#include "pipeline/progress.h"
#include "pipeline/provenance.h"
#include "pipeline/units.h"
#include "pipeline/vtk_series.h"
#include "sim/engine/ridge_build.h"
#include "sim/engine/world.h"
#include "sim/simulate/checkpoint.h"
#include "sim/simulate/recorder.h"
#include "sim/simulate/ridge_summary.h"

namespace floesim::sim {

namespace fs = std::filesystem;

namespace {

// Stops the run between two steps on SIGINT/SIGTERM (pipeline/interrupt.h): with checkpoints on, the step reached
// is checkpointed first, so that --resume loses nothing.
void stop_if_interrupted(const World& w, Checkpointer* cp, long checkpoint_every, Results& r, RecorderSums& sums,
                         double wall_s) {
  if (!interrupt_signal()) return;
  std::string where;
  if (cp && checkpoint_every > 0 && w.state().step > cp->last_step()) {
    sums.wall_s = wall_s;
    cp->save(w, r, sums);
  }
  if (cp && cp->last_step() > 0) {
    std::ostringstream os;
    os << "checkpoint at t = " << w.state().time_s << " s in " << cp->dir().string()
       << ": --resume continues from it";
    where = os.str();
  }
  throw Interrupted(interrupt_signal(), where);
}

// The run's statistics from the world's stage times and the recorder's sums.
void fill_run_stats(const World& w, const RecorderSums& sums, long steps, double wall_s, RunStats& stats) {
  stats.wall_s = wall_s;
  for (int i = 0; i < kStageCount; ++i) stats.stage_s[i] = w.stage_seconds()[i];
  stats.stage_s[kStageCount] = sums.record_s;
  stats.steps = steps;
  stats.mean_awake_floes = sums.awake / steps;
  stats.mean_awake_rubble = sums.awake_rubble / steps;
  stats.mean_contacts = sums.contacts / steps;
  stats.mean_iterations = sums.iterations / steps;
  stats.mean_pairs = sums.pairs / steps;
  stats.mean_touching = sums.touching / steps;
  stats.mean_edge_pairs = sums.edges / steps;
  stats.mean_crushing_pairs = sums.crushing / steps;
}

// What a reader of the run's loads must know of it, from its summary: a mean whose interval the run is too short
// for, floes the run left out.
std::vector<std::string> run_warnings(const nlohmann::json& summary) {
  std::vector<std::string> out;
  const nlohmann::json ci = summary.value("mean_surge_ice_load_interval", nlohmann::json::object());
  if (!ci.value("meaningful", true))
    out.push_back("the mean surge ice load's 95 % interval cannot be trusted: " + ci.value("note", std::string()));
  if (const size_t n = summary.value("removed_floes", size_t{0}); n > 0)
    out.push_back(std::to_string(n) + (n == 1 ? " floe was" : " floes were") +
                  " left out of the run: they overlapped the vessel's initial footprint");
  return out;
}

}  // namespace

Results simulate(const SimulateOptions& o, Model model, RunStats& stats, std::ostream* progress,
                 const CheckpointPlan* checkpoints, std::unique_ptr<World>* world_out) {
  FLOESIM_REQUIRE(model.vessel >= 0, "simulate: the model has no vessel");
  const long steps = o.steps(), checkpoint_every = o.checkpoint_every();
  const bool spill = checkpoints && checkpoints->spill_series && checkpoint_every > 0;
  Results r;
  Recorder recorder(o, model, r, spill ? std::min(steps, checkpoint_every) : steps);
  RecorderSums& sums = recorder.sums();

  // 1. The world: fresh, or continued from a checkpoint (sim/simulate/checkpoint.h) with the results recorded up
  // to it.
  std::unique_ptr<Checkpointer> cp;
  std::unique_ptr<World> world;
  if (checkpoints) {
    cp = std::make_unique<Checkpointer>(checkpoints->dir, checkpoints->provenance, spill);
    if (checkpoints->resume) world = cp->resume(o, model, r, sums, progress);
    else cp->start_fresh(r, progress);
  }
  if (!world) world = std::make_unique<World>(std::move(model));
  model = Model();  // the world holds the one model of the run (a resumed world rebuilt its own)
  if (cp) r.series_first_step = static_cast<size_t>(cp->series_steps_on_disk());
  recorder.attach(*world);
  const long first = world->state().step + 1;
  stats.resumed_at_step = first - 1;
  const auto t0 = std::chrono::steady_clock::now();
  auto wall_now = [&] { return sums.wall_s + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };

  // 2. The steps: step, record, checkpoint every checkpoint_interval_s (not after the last step: the results
  // follow), a progress line with the time left every 10 % (pipeline/progress.h).
  {
    InterruptPolling polling;
    ProgressLine line(progress, steps);
    for (long k = first; k <= steps; ++k) {
      stop_if_interrupted(*world, cp.get(), checkpoint_every, r, sums, wall_now());
      world->step();
      recorder.record_step(*world, k);
      if (cp && checkpoint_every > 0 && k % checkpoint_every == 0 && k < steps) {
        const double before = sums.wall_s;
        sums.wall_s = wall_now();
        const auto tc = std::chrono::steady_clock::now();
        cp->save(*world, r, sums);
        stats.checkpoint_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
        ++stats.checkpoints;
        sums.wall_s = before;
      }
      if (line.due(k)) {
        const StepReport& rep = world->report();
        char head[48];
        std::snprintf(head, sizeof head, "t = %.1f s", world->state().time_s);
        line.print(k, wall_now(), head,
                   ", awake floes " + std::to_string(rep.awake_floes) + ", contacts " + std::to_string(rep.contacts));
      }
    }
  }

  // 3. The geometry, the fracture table and the attributes; the run's statistics.
  recorder.finish(*world);
  fill_run_stats(*world, sums, steps, wall_now(), stats);
  if (world_out) *world_out = std::move(world);
  return r;
}

std::string run_simulate(const fs::path& floes_file, const fs::path& hull_file, const fs::path& config_file,
                         const fs::path& out_dir, bool resume) {
  // 1. Inputs: options (strict), thrust series path relative to the config file, floes, hull.
  const Json cfg = load_json_file(config_file);
  SimulateOptions o = read_options<SimulateOptions>(cfg, config_file.string());
  std::vector<NamedInput> inputs = {{"floes", floes_file}, {"hull", hull_file}, {"config", config_file}};
  if (o.vessel.propulsion.mode == "thrust_series") {
    fs::path tf = o.vessel.propulsion.thrust_file;
    if (tf.is_relative()) tf = config_file.parent_path() / tf;
    o.vessel.propulsion.thrust_file = tf.string();
    inputs.push_back({"thrust_series", tf});
  }
  const FloeField field = read_floes(floes_file);
  const HullModel hull = load_hull(hull_file, o.hull);
  try {  // the stage floats the hull as the file has it: one entirely above or below the water is a placement error
    require_floating(hull, hull_file.string());
  } catch (const Error& e) {
    throw Error(std::string(e.what()) + ". floesim-simulate takes the hull frame as the file has it (bow +x, "
                "waterline z = 0): place a CAD mesh with the hull options (case \"hull\": {\"file\", \"waterline_z_m\", "
                "\"up_direction\", \"bow_direction\", \"scale\"}, or floesim-hull) first");
  }
  // The structures beside it: meshes in their hull frames as the files have them, relative to the config file.
  std::vector<HullModel> structures;
  for (size_t k = 0; k < o.structures.size(); ++k) {
    fs::path f = o.structures[k].hull_file;
    if (f.is_relative()) f = config_file.parent_path() / f;
    o.structures[k].hull_file = f.string();
    inputs.push_back({"structure " + o.structures[k].name, f});
    const std::string key = config_file.string() + ": structures[" + std::to_string(k) + "].hull_file";
    FLOESIM_REQUIRE(fs::is_regular_file(f), key, ": ", f.string(), " does not exist");
    try {
      structures.push_back(load_hull(f, HullLoadOptions{}));
      require_floating(structures.back(), f.string());
    } catch (const Error& e) {
      throw Error(key + ": " + e.what());
    }
  }
  Model model = build_model(field, &hull, o, structures);
  // The ridges' rubble settled before the run (the same on a resumed run: deterministic).
  const RidgeSettling settled = settle_ridges(field, model, &std::cout);
  if (settled.blocks > 0)
    std::cout << "floesim-simulate: " << settled.blocks << " blocks of rubble settled in " << settled.time_s
              << " s (" << settled.steps << " steps, " << settled.wall_s << " s wall)\n";
  if (settled.bonds > 0)
    std::cout << "floesim-simulate: " << settled.bonds << " freeze bonds between the settled blocks\n";

  std::ostringstream out;
  out << "floesim-simulate: " << model.floe_count() << " floes in " << model.parts.size() << " convex parts ("
      << model.removed_floe_ids.size()
      << " removed: they overlapped the vessel's initial footprint";
  if (model.small_overlaps) out << "; " << model.small_overlaps << " small floe-floe overlaps left to the solver";
  out << "), vessel ";
  if (model.vessel_info.mass_kg < 1e4) out << std::lround(model.vessel_info.mass_kg) << " kg";  // a tank model
  else out << model.vessel_info.mass_kg / 1e3 << " t";
  out << ", L_wl " << model.vessel_info.length_wl_m
      << " m, GM_T " << model.vessel_info.gm_transverse_m << " m\n";
  std::cout << out.str() << std::flush;

  // 2. Simulate (throws on numerical failure: nothing is written), with checkpoints in out_dir/checkpoint. The
  // output folder is checked first: a run of hours must not end at a folder it cannot write.
  ensure_directory(out_dir);
  const Json prov = make_provenance("floesim-simulate", inputs, options_to_json(o));
  CheckpointPlan checkpoints;
  checkpoints.dir = out_dir / "checkpoint";
  checkpoints.provenance = prov;
  checkpoints.resume = resume;
  checkpoints.spill_series = true;
  RunStats stats;
  std::unique_ptr<World> world;
  Results results = simulate(o, std::move(model), stats, &std::cout, &checkpoints, &world);
  results.attributes["provenance"] = prov;
  // The series before the last checkpoint are read back from its chunks, one at a time.
  const CheckpointSeries series(checkpoints.dir, prov, static_cast<long>(results.series_first_step), results);
  nlohmann::json summary = summarize(o, world->model(), results, series);
  if (!world->model().settings.ridges.empty())
    summary["ridges"] = ridge_summary(o, world->model(), settled, series, world->state());
  // Every warning of the stages before (the floes' maker) and of this one, for the report.
  nlohmann::json warnings = nlohmann::json::array();
  for (const std::string& w : field.warnings) warnings.push_back("floes (" + floes_file.filename().string() + "): " + w);
  for (const std::string& w : run_warnings(summary)) warnings.push_back("simulate: " + w);
  summary["warnings"] = warnings;
  summary["settings"] = options_to_json(o);
  summary["provenance"] = prov;

  // 3. Artefacts, atomically; then the checkpoint has served.
  write_results(out_dir / "results.h5", results, series);
  if (o.paraview)  // from the file: it holds the series of a long run that left them on disk
    write_vtk_series(read_results(out_dir / "results.h5", true, {"ice_load"}), out_dir / "paraview",
                     (out_dir / "results.h5").string());
  write_text_atomic(out_dir / "summary.json", summary.dump(2) + "\n");
  remove_checkpoint(checkpoints.dir);

  // 4. The report (wall time lives here, not in the artefacts).
  std::ostringstream rep;
  const double ms = 1e3 * stats.wall_s / stats.steps;
  rep << std::fixed << std::setprecision(2);
  rep << "floes " << world->model().built_floe_count() << ", steps " << stats.steps << ", wall " << stats.wall_s << " s, "
      << ms << " ms/step, " << o.duration_s / stats.wall_s << " simulated s per wall s\n";
  if (stats.resumed_at_step > 0)
    rep << "resumed at step " << stats.resumed_at_step << " (t = " << stats.resumed_at_step * o.time_step_s
        << " s); the wall time includes the run before\n";
  if (stats.checkpoints > 0)
    rep << stats.checkpoints << " checkpoints written (every " << o.checkpoint_interval_s << " s of simulated time), "
        << 1e3 * stats.checkpoint_s / stats.checkpoints << " ms each on average\n";
  rep << "mean awake floes " << stats.mean_awake_floes;
  if (stats.mean_awake_rubble > 0) rep << " (of them, blocks of rubble " << stats.mean_awake_rubble << ")";
  rep << ", mean contacts " << stats.mean_contacts
      << ", mean solver sweeps " << stats.mean_iterations << "\n";
  rep << "mean part pairs per step: " << stats.mean_pairs << " from the broad phase, " << stats.mean_touching
      << " touching (" << stats.mean_edge_pairs << " edge-on-edge, single point; " << stats.mean_crushing_pairs
      << " crushing, two rows)\n";
  rep << "stage times (ms/step):";
  for (int i = 0; i <= kStageCount; ++i)
    rep << " " << (i < kStageCount ? stage_name(i) : "record") << " " << std::setprecision(3)
        << 1e3 * stats.stage_s[i] / stats.steps;
  rep << "\n" << std::setprecision(1);
  {  // in the unit that suits the loads' size: N for a tank model, kN for a ship
    const double load_n = summary["mean_surge_ice_load_N"].get<double>();
    const ForceUnit u = force_unit_for(load_n);
    rep << "mean surge ice load " << load_text(load_n, u) << " (resistance "
        << load_text(summary["mean_surge_ice_resistance_N"].get<double>(), u) << ")";
    const nlohmann::json ci = summary.value("mean_surge_ice_load_interval", nlohmann::json::object());
    if (ci["half_width_N"].is_number())
      rep << " ± " << load_text(ci["half_width_N"].get<double>(), u) << " (95 %, batch means over "
          << ci["batches"].get<size_t>() << " batches of " << std::setprecision(3) << ci["batch_s"].get<double>()
          << " s" << std::setprecision(1) << ")";
    if (!ci["meaningful"].get<bool>()) rep << " [" << ci["note"].get<std::string>() << "]";
  }
  rep << " from t = " << o.steady_start_s
      << " s, mean speed " << std::setprecision(3) << summary["mean_vessel_speed_mps"].get<double>() << " m/s\n";
  const nlohmann::json& fr = summary["fracture"];
  if (fr["enabled"].get<bool>())
    rep << "fracture: " << fr["events"]["total"] << " events (bending " << fr["events"]["bending"] << ", radial "
        << fr["events"]["radial"] << ", splitting " << fr["events"]["splitting"] << "), " << fr["pieces_created"]
        << " pieces, " << std::setprecision(4) << fr["brash_removed_kg"].get<double>() / 1e3
        << " t of brash removed\n";
  rep << "wrote " << (out_dir / "results.h5").string() << " (" << std::setprecision(1)
      << std::filesystem::file_size(out_dir / "results.h5") / 1e6 << " MB, " << results.state_body_id.size()
      << " stored body states in " << results.frames() << " frames) and " << (out_dir / "summary.json").string()
      << "\n";
  // Peak resident memory of this process (getrusage: kB on Linux), for sizing long runs and cluster jobs.
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) == 0) rep << "peak memory " << usage.ru_maxrss / 1024.0 << " MB\n";
  return rep.str();
}

}  // namespace floesim::sim
