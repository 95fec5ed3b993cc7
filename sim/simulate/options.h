// The options of the simulate stage: the engine's physics settings (sim/engine/settings.h: time step, threads and the
// physics sections) and the run's own: how long, what is stored and when, checkpoints, how the hull file is loaded.
// One strict struct with sections, every field with default, unit and doc; the keys and their order are the case
// file's `simulate` section (and the resolved configuration every artefact of the stage records).
#pragma once
#include <cmath>
#include <string>

#include "pipeline/options.h"
#include "sim/engine/settings.h"
#include "sim/vessel/hull.h"

namespace floesim::sim {

struct SimulateOptions : EngineSettings {
  double duration_s = 100.0;
  double output_interval_s = 0.2;
  double steady_start_s = 20.0;   // statistics of the summary start here (skip the start-up transient)
  // Simulated time between checkpoints (sim/simulate/checkpoint.h); 0 = none. 10 s: a checkpoint costs milliseconds
  // to a fraction of a second (the world's state plus the results recorded since the last one, written once), while
  // 10 s of a large field take minutes of wall time; a stopped run then loses at most that much.
  double checkpoint_interval_s = 10.0;
  // Also write OUT/paraview (results.pvd and a .vtp per frame: pipeline/vtk_series.h). Off by default: every frame
  // holds the whole field, ~90 bytes per floe vertex, which for a long run is far more than results.h5.
  bool paraview = false;
  HullLoadOptions hull;

  template <class V>
  void visit(V& v) {
    v.field("time_step_s", time_step_s, "s", "time step", in_range(1e-5, 0.1));
    v.field("duration_s", duration_s, "s", "simulated time (a whole number of time steps)", positive());
    v.field("output_interval_s", output_interval_s, "s",
            "interval of the stored body states (a whole number of time steps)", positive());
    v.field("steady_start_s", steady_start_s, "s", "start of the steady part used for the summary statistics",
            non_negative());
    v.field("threads", threads, "-", "worker threads for the per-body force and narrow-phase stages",
            int_in_range(1, 64));
    v.field("checkpoint_interval_s", checkpoint_interval_s, "s",
            "simulated time between checkpoints in OUT/checkpoint (a whole number of time steps; 0 = none); "
            "--resume continues from the last one with byte-identical results",
            non_negative());
    v.field("paraview", paraview, "-",
            "also write OUT/paraview/results.pvd, a VTK series of the floes and hull per frame for ParaView");
    v.section("ice", ice, "ice material");
    v.section("water", water, "water, gravity and current");
    v.section("vessel", vessel, "vessel start, mass, resistance, propulsion, steering");
    v.section("wind", wind, "wind");
    v.section("solver", solver, "contact solver");
    v.section("contact", contact, "contact laws (rigid or compliant crushing) per pair of body classes");
    v.section("domain", domain, "fixed walls around the floe field (floes pack against them)");
    v.section("fracture", fracture, "ice fracture: bending, radial cracking and splitting (PHYSICS.md §2)");
    v.section("sleep", sleep, "sleeping of resting floes");
    v.section("health", health, "numerical health limits");
    v.section("hull", hull, "how the hull file is loaded (non-convex meshes)");
    v.section("level_ice", level_ice, "a level ice sheet, broken by the fracture module (issue #10)");
    v.section("drift", drift, "the ice's drift toward a structure: the run is computed in the ice's frame");
    v.list("structures", structures,
           "structures beside the vessel (fixed, moored, dp or compliant), each a hull body of its own with its "
           "loads, pose and station keeping recorded under its name: [{\"name\", \"hull_file\", placement and "
           "mass as the vessel's, \"station_keeping\"}]");
    v.list("ridges", ridges,
           "ridges in the level ice sheet, each a consolidated layer cut out of the sheet along its line and the "
           "rubble of its keel and sail released around it to settle: [{\"line\", cross-section, porosity, "
           "blocks}] (PHYSICS.md §9)");
    v.section("ridge_field", ridge_field,
              "more ridges (after those of ridges) along a route at a stated density, their sizes drawn, seeded");
    v.section("ridge_settling", ridge_settling,
              "how the ridges' rubble is settled in still water before the run, and the ridge as built measured");
    v.section("freeze_bonds", freeze_bonds,
              "freeze bonds between the ridges' blocks once settled: tensile and shear strength (PHYSICS.md §9.5)");
    for (size_t i = 0; i < structures.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (structures[i].name == structures[j].name)
          v.problem("structures", "two structures are named \"" + structures[i].name + "\": names must differ");
    // Cross-field checks: whole numbers of steps, statistics window inside the run.
    if (time_step_s > 0 && duration_s > 0) {
      const double n = duration_s / time_step_s;
      if (std::abs(n - std::round(n)) > 1e-6 * std::max(1.0, n))
        v.problem("duration_s", "must be a whole number of time steps (time_step_s = " + Json(time_step_s).dump() + ")");
    }
    if (time_step_s > 0 && output_interval_s > 0) {
      const double n = output_interval_s / time_step_s;
      if (output_interval_s < time_step_s * (1 - 1e-9))
        v.problem("output_interval_s", "must be >= time_step_s");
      else if (std::abs(n - std::round(n)) > 1e-6 * std::max(1.0, n))
        v.problem("output_interval_s", "must be a whole number of time steps");
    }
    if (duration_s > 0 && output_interval_s > duration_s) v.problem("output_interval_s", "must be <= duration_s");
    else if (duration_s > 0 && output_interval_s > 0) {
      const double n = duration_s / output_interval_s;
      if (std::abs(n - std::round(n)) > 1e-6 * std::max(1.0, n))
        v.problem("output_interval_s", "must divide duration_s (frames are stored at k x output_interval_s)");
    }
    if (steady_start_s >= duration_s) v.problem("steady_start_s", "must be < duration_s");
    if (time_step_s > 0 && checkpoint_interval_s > 0) {
      const double n = checkpoint_interval_s / time_step_s;
      if (checkpoint_interval_s < time_step_s * (1 - 1e-9))
        v.problem("checkpoint_interval_s", "must be 0 (no checkpoints) or >= time_step_s");
      else if (std::abs(n - std::round(n)) > 1e-6 * std::max(1.0, n))
        v.problem("checkpoint_interval_s", "must be a whole number of time steps");
    }
    if (time_step_s > 0 && solver.reference_horizon_s > 0) {
      const double n = solver.reference_horizon_s / time_step_s;
      if (solver.reference != "double_cap" && solver.reference != "reverse_order" &&
          solver.reference != "every_contact")
        v.problem("solver.reference_horizon_s", "a branch runs only for solver.reference double_cap, reverse_order "
                  "or every_contact (it is \"" + solver.reference + "\"): set the reference or a horizon of 0");
      else if (n < 1 - 1e-9 || std::abs(n - std::round(n)) > 1e-6 * std::max(1.0, n))
        v.problem("solver.reference_horizon_s", "must be 0 or a whole number of time steps (time_step_s = " +
                  Json(time_step_s).dump() + ")");
    }
  }

  long steps() const { return std::lround(duration_s / time_step_s); }
  long output_every() const { return std::lround(output_interval_s / time_step_s); }
  long checkpoint_every() const { return std::lround(checkpoint_interval_s / time_step_s); }  // 0: none
};

}  // namespace floesim::sim
