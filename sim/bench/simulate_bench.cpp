// Simulation benchmark (issue #4): the generated Oden-like hull driven at 2 m/s through a generated Oden-size floe
// field (1.3 km x 0.7 km, 60 % concentration, n(D) ~ D^-2 for D = 5-150 m, about a thousand floes, h = 1 m,
// SAMS Table 1 parameters), then through fields 4x and 9x larger in area with the same floe statistics. For each
// field it prints the floes, the awake floes and contacts per step (mean), wall time, ms per step, simulated
// seconds per wall second, the stage times, the time to record and write the results, and the peak memory. The
// vessel covers the same ~400 m in every field, so the cost must stay with the floes it sets in motion, not grow
// with the field. Fracture (PHYSICS.md §2) is on as in the cases; the Oden-size field runs first without it, in the
// same process, so that its cost is a ratio of one run: events per simulated second, floe bodies at the start and
// the end, the fracture stage's time, who presses on the hull (input floes, pieces), and
// `fracture_speed_ratio <with / without>`. It also runs the Oden-size field with fracture at the hull only and with
// brash removed (the model before issue #33), so that the cost of ice-ice failure and of keeping brash as rigid
// bodies is a ratio of the same run (`rigid_brash_speed_ratio <brash kept / removed, simulated s per wall s, with
// ice-ice failure>`). The last line is `realtime_factor <simulated s per wall s on the Oden-size field, the defaults>`.
//
//   floesim-bench [--duration 200] [--threads 2] [--scales 1,4,9] [--seed 1] [--keep DIR] [--no-compare]
//
// The field is generated here (star-shaped floes placed by rejection sampling, largest first), not by imaging/:
// sim and imaging never link each other. Everything is seeded: two runs simulate the same thing.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/floes_io.h"
#include "pipeline/results_io.h"
#include "pipeline/stage_main.h"
#include "sim/vessel/hull.h"
#include "sim/simulate/simulate.h"
#include "sim/engine/world.h"
#include "pipeline/geometry2d.h"

using namespace floesim;
using namespace floesim::sim;
namespace fs = std::filesystem;

namespace {


struct FieldSpec {
  double width_m = 1300, height_m = 700;
  double concentration = 0.60;
  double d_min_m = 5, d_max_m = 150;  // floe size (diameter of the circle of equal area), n(D) ~ D^-2
  double thickness_m = 1.0;
  double gap_m = 0.3;                 // smallest clearance between generated floes (no contacts at t = 0)
  uint64_t seed = 1;
};

// Star-shaped floe of equivalent diameter d about the origin: a radius made of a few low Fourier modes, mildly
// non-convex like digitised floes (so that floes have several convex parts, as real ones do).
Polygon star_floe(double d, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const int k = std::clamp(static_cast<int>(8 + d / 6), 8, 24);
  double amp[3], phase[3];
  for (int m = 0; m < 3; ++m) {
    amp[m] = 0.22 * U(rng) / (m + 1);
    phase[m] = 2 * kPi * U(rng);
  }
  Polygon p;
  const double rot = 2 * kPi * U(rng);
  for (int i = 0; i < k; ++i) {
    const double t = rot + 2 * kPi * (i + 0.35 * (U(rng) - 0.5)) / k;
    double r = 1 + 0.16 * (U(rng) - 0.5);
    for (int m = 0; m < 3; ++m) r += amp[m] * std::cos((m + 2) * t + phase[m]);
    p.emplace_back(r * std::cos(t), r * std::sin(t));
  }
  const double s = std::sqrt(kPi * d * d / 4 / signed_area(p));
  for (Vec2& v : p) v *= s;
  return p;
}

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

bool segments_cross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double d1 = cross2(b - a, c - a), d2 = cross2(b - a, d - a);
  const double d3 = cross2(d - c, a - c), d4 = cross2(d - c, b - c);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0));
}

bool inside(const Polygon& p, const Vec2& q) {
  bool in = false;
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++)
    if ((p[i].y() > q.y()) != (p[j].y() > q.y()) &&
        q.x() < (p[j].x() - p[i].x()) * (q.y() - p[i].y()) / (p[j].y() - p[i].y()) + p[i].x())
      in = !in;
  return in;
}

bool polygons_overlap(const Polygon& a, const Polygon& b) {
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < b.size(); ++j)
      if (segments_cross(a[i], a[(i + 1) % a.size()], b[j], b[(j + 1) % b.size()])) return true;
  return inside(b, a[0]) || inside(a, b[0]);
}

// Floe sizes drawn from n(D) ~ D^-2 until their area reaches the target, placed largest first at uniformly random
// positions (up to `tries` each; a floe that finds no room is dropped, the small ones then fill the gaps).
FloeField generate_field(const FieldSpec& spec) {
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double target = spec.concentration * spec.width_m * spec.height_m;
  const double a = 1 / spec.d_min_m, b = 1 / spec.d_max_m;
  // Sizes for the whole target area; floes that find no room leave a deficit, which later rounds fill with new
  // draws from the same distribution (the big ones then rarely fit: the field ends a little finer than n(D)).
  auto draw = [&](double need) {
    std::vector<double> sizes;
    double area = 0;
    while (area < need) {
      const double d = 1 / (a - U(rng) * (a - b));  // inverse CDF of D^-2 on [d_min, d_max]
      sizes.push_back(d);
      area += kPi * d * d / 4;
    }
    std::sort(sizes.begin(), sizes.end(), std::greater<double>());
    return sizes;
  };
  // Uniform grid of placed floes' boxes for the overlap queries.
  const double cell = 25;
  const int nx = static_cast<int>(std::ceil(spec.width_m / cell)), ny = static_cast<int>(std::ceil(spec.height_m / cell));
  std::vector<std::vector<int>> grid(static_cast<size_t>(nx) * ny);
  std::vector<Polygon> placed, inflated;
  std::vector<Vec2> centre;
  std::vector<double> radius;
  std::vector<int> stamp;
  int tick = 0;
  FloeField field;
  field.width_m = spec.width_m;
  field.height_m = spec.height_m;
  double covered = 0;
  for (int round = 0; round < 8 && covered < 0.995 * target; ++round)
  for (double d : draw(target - covered)) {
    const Polygon shape = star_floe(d, rng);
    double r = 0;
    for (const Vec2& v : shape) r = std::max(r, v.norm());
    if (2 * r >= std::min(spec.width_m, spec.height_m)) continue;
    for (int t = 0; t < 400; ++t) {
      const Vec2 c(r + U(rng) * (spec.width_m - 2 * r), r + U(rng) * (spec.height_m - 2 * r));
      const int x0 = std::max(0, static_cast<int>((c.x() - r - spec.gap_m) / cell));
      const int x1 = std::min(nx - 1, static_cast<int>((c.x() + r + spec.gap_m) / cell));
      const int y0 = std::max(0, static_cast<int>((c.y() - r - spec.gap_m) / cell));
      const int y1 = std::min(ny - 1, static_cast<int>((c.y() + r + spec.gap_m) / cell));
      ++tick;
      Polygon cand;  // the candidate enlarged by the gap (scaled about its star centre)
      const double grow = (r + spec.gap_m) / r;
      for (const Vec2& v : shape) cand.push_back(c + grow * v);
      bool ok = true;
      for (int iy = y0; iy <= y1 && ok; ++iy)
        for (int ix = x0; ix <= x1 && ok; ++ix)
          for (int j : grid[static_cast<size_t>(iy) * nx + ix]) {
            if (stamp[j] == tick) continue;
            stamp[j] = tick;
            if ((centre[j] - c).norm() > radius[j] + r + spec.gap_m) continue;
            if (polygons_overlap(cand, placed[j])) {
              ok = false;
              break;
            }
          }
      if (!ok) continue;
      Polygon p;
      for (const Vec2& v : shape) p.push_back(c + v);
      const int id = static_cast<int>(placed.size());
      placed.push_back(p);
      centre.push_back(c);
      radius.push_back(r);
      stamp.push_back(0);
      for (int iy = std::max(0, static_cast<int>((c.y() - r) / cell)); iy <= std::min(ny - 1, static_cast<int>((c.y() + r) / cell)); ++iy)
        for (int ix = std::max(0, static_cast<int>((c.x() - r) / cell)); ix <= std::min(nx - 1, static_cast<int>((c.x() + r) / cell)); ++ix)
          grid[static_cast<size_t>(iy) * nx + ix].push_back(id);
      Floe f;
      f.id = id + 1;
      f.outline = p;
      f.area_m2 = signed_area(p);
      f.thickness_m = spec.thickness_m;
      covered += f.area_m2;
      field.floes.push_back(std::move(f));
      break;
    }
  }
  return field;
}

double peak_memory_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;  // ru_maxrss is in kB on Linux
}

// Who presses on the hull, from the results' in_contact flags (every stored frame): the input floes and the pieces
// broken from them, per frame on average, and the longest time one piece stayed against the hull (frames in a row).
// With fracture on, the pieces that ride the bow are where the extra contacts of a step come from.
struct HullPressers {
  double input_floes = 0, pieces = 0, longest_piece_s = 0;
};

HullPressers hull_pressers(const Results& r) {
  HullPressers h;
  if (r.frames() == 0) return h;
  FrameReplay replay(r, "the bench's results");
  std::vector<int> run(r.floe_id.size(), 0);  // per floe: frames in a row it has pressed on the hull
  int longest = 0;
  for (size_t f = 0; f < r.frames(); ++f) {
    replay.seek(f);
    std::vector<uint8_t> pressing(r.floe_id.size(), 0);
    for (size_t k = 0; k < replay.rows().size(); ++k) {
      const int32_t floe = replay.floes()[k];
      if (floe < 0 || !r.state_in_contact[replay.rows()[k]]) continue;
      pressing[floe] = 1;
      (r.floe_generation[floe] > 0 ? h.pieces : h.input_floes) += 1;
    }
    for (size_t g = 0; g < run.size(); ++g) {
      run[g] = pressing[g] ? run[g] + 1 : 0;
      if (r.floe_generation[g] > 0) longest = std::max(longest, run[g]);
    }
  }
  h.input_floes /= static_cast<double>(r.frames());
  h.pieces /= static_cast<double>(r.frames());
  const double interval = r.frames() > 1 ? r.frame_time_s[1] - r.frame_time_s[0] : 0;
  h.longest_piece_s = longest * interval;
  return h;
}

struct BenchOptions {
  double duration_s = 200;
  int threads = 2;
  std::vector<int> scales = {1, 4, 9};
  uint64_t seed = 1;
  std::string keep_dir;  // if set, the results of each field are kept there
  bool compare = true;   // the Oden-size field without fracture first
};

// The ice model a field runs with: fracture off, or on with (or without) failure at ice-ice contacts and brash
// kept as rigid bodies (or removed, the model before issue #33).
struct Variant {
  const char* name;
  bool fracture, ice_ice;
  const char* brash;
};
constexpr Variant kDefaults{"fracture on (ice-ice failure, rigid brash)", true, true, "rigid"};
constexpr Variant kCompared[] = {
    {"fracture off", false, false, "rigid"},
    {"fracture at the hull only, brash removed", true, false, "removed"},
    {"fracture at the hull only, rigid brash", true, false, "rigid"},
    {"fracture with ice-ice failure, brash removed", true, true, "removed"},
};

// One field: generate, build, simulate (with the recorder), write the results; returns simulated s per wall s.
double run_field(int scale, const BenchOptions& bo, const HullModel& hull, const Variant& v) {
  const bool fracture = v.fracture;
  FieldSpec spec;
  const double s = std::sqrt(static_cast<double>(scale));
  spec.width_m *= s;
  spec.height_m *= s;
  spec.seed = bo.seed + static_cast<uint64_t>(scale);
  const auto g0 = std::chrono::steady_clock::now();
  const FloeField field = generate_field(spec);
  double floe_area = 0;
  for (const Floe& f : field.floes) floe_area += f.area_m2;

  SimulateOptions o;  // defaults: SAMS Table 1 (rho_i 900, rho_w 1025, C_f 0.005, C_d 0.5, mu 0.15, dt 0.01 s)
  o.duration_s = bo.duration_s;
  o.output_interval_s = 0.2;
  o.steady_start_s = std::min(40.0, 0.5 * bo.duration_s);
  o.threads = bo.threads;
  o.vessel.x_m = -60;
  o.vessel.y_m = spec.height_m / 2;
  o.vessel.heading_deg = 0;
  o.vessel.initial_speed_mps = 2.0;
  o.vessel.propulsion.mode = "speed";
  o.vessel.propulsion.speed_mps = 2.0;
  o.fracture.enabled = fracture;
  o.fracture.ice_ice = v.ice_ice;
  o.fracture.brash = v.brash;
  const Model model = build_model(field, &hull, o);
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - g0).count();
  size_t floe_parts = 0;
  for (const Body& b : model.bodies)
    if (b.kind == BodyKind::floe) floe_parts += b.part_count;

  std::printf("field %dx, %s: %.0f m x %.0f m, %d floes (%zu convex parts), concentration %.3f, "
              "h = %.1f m (generated and built in %.2f s)\n",
              scale, v.name, spec.width_m, spec.height_m, model.floe_count(), floe_parts,
              floe_area / (spec.width_m * spec.height_m), spec.thickness_m, build_s);
  std::fflush(stdout);

  if (!bo.keep_dir.empty()) {
    ensure_directory(bo.keep_dir);
    write_floes(fs::path(bo.keep_dir) / ("floes_" + std::to_string(scale) + "x.geojson"), field);
  }
  RunStats st;
  Results r = simulate(o, model, st);
  const double record_s = st.stage_s[kStageCount];
  const fs::path dir = bo.keep_dir.empty() ? fs::temp_directory_path() / "floesim_bench" : fs::path(bo.keep_dir);
  ensure_directory(dir);
  const fs::path file = dir / ("results_" + std::to_string(scale) + "x.h5");
  const auto w0 = std::chrono::steady_clock::now();
  write_results(file, r);
  const double write_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  const double mb = fs::file_size(file) / 1e6;
  if (bo.keep_dir.empty()) fs::remove(file);

  const double rtf = bo.duration_s / st.wall_s;
  std::printf("  per step (mean): awake floes %.1f, contacts %.1f, broad-phase part pairs %.1f, solver sweeps %.1f\n",
              st.mean_awake_floes, st.mean_contacts, st.mean_pairs, st.mean_iterations);
  std::printf("  steps %ld, wall %.2f s, %.3f ms/step, %.2f simulated s per wall s (%d threads)\n", st.steps,
              st.wall_s, 1e3 * st.wall_s / st.steps, rtf, bo.threads);
  {
    // How well the contact solver converged (the results' solver series): a faster step must not be a worse answer.
    auto mean = [&](const char* name) {
      const auto& x = r.get(name);
      double sum = 0;
      for (double v : x) sum += v;
      return x.empty() ? 0.0 : sum / static_cast<double>(x.size());
    };
    std::printf("  solver (mean per step): capped %.3f (relax %.3f), complementarity %.3g m/s (relax %.3g), "
                "relax sweeps %.1f, subspace solves %.2f\n",
                mean("solver_capped"), mean("relax_capped"), mean("solver_complementarity"),
                mean("relax_complementarity"), mean("relax_iterations"), mean("solver_subspace_solves"));
  }
  std::printf("  stage ms/step:");
  for (int i = 0; i < kStageCount; ++i) std::printf(" %s %.3f", stage_name(i), 1e3 * st.stage_s[i] / st.steps);
  std::printf("\n  results: record %.2f s (in the wall time, %.1f %%), write %.2f s (%.1f MB, %zu frames)\n",
              record_s, 100 * record_s / st.wall_s, write_s, mb, r.frames());
  if (fracture) {
    int mode[4] = {0, 0, 0, 0};
    for (int32_t m : r.fracture_mode) ++mode[std::clamp(m, 0, 3)];
    const auto& bodies = r.get("floe_bodies");
    std::printf("  fracture: %zu events (bending %d, radial %d, splitting %d), %.2f per simulated s; floe bodies "
                "%d at the start, %.0f at the end; fracture stage %.3f ms/step\n",
                r.fracture_mode.size(), mode[1], mode[2], mode[3], r.fracture_mode.size() / bo.duration_s,
                model.floe_count(), bodies.empty() ? 0.0 : bodies.back(), 1e3 * st.stage_s[kFracture] / st.steps);
    double removed = 0;
    for (double b : r.fracture_brash_mass_kg) removed += b;
    const auto& ice = r.get("ice_load");
    const auto& rigid = r.get("ice_load_rigid");
    double total = 0, from_rigid = 0;
    for (size_t k = 0; k < ice.size(); k += 6) total += ice[k], from_rigid += rigid[k];
    std::printf("  brash: %.1f t removed; rigid contacts carry %.1f %% of the mean surge ice load\n", removed / 1e3,
                total != 0 ? 100 * from_rigid / total : 0.0);
  }
  const HullPressers hp = hull_pressers(r);
  std::printf("  pressing on the hull (mean per frame): input floes %.1f, pieces %.1f; longest a piece stayed "
              "pressed %.1f s\n", hp.input_floes, hp.pieces, hp.longest_piece_s);
  std::printf("  peak memory (ru_maxrss, whole process so far) %.0f MB\n", peak_memory_mb());
  std::fflush(stdout);
  return rtf;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Simulation benchmark: the Oden-like hull at 2 m/s through generated Oden-size floe fields (1x, 4x, "
               "9x the area); prints per-step cost and ends with 'realtime_factor <simulated s per wall s on the "
               "Oden-size field>'.",
               "floesim-bench"};
  BenchOptions bo;
  app.add_option("--duration", bo.duration_s, "simulated seconds per field (200 for the reported figures)")
      ->check(CLI::PositiveNumber);
  app.add_option("--threads", bo.threads, "worker threads")->check(CLI::Range(1, 64));
  app.add_option("--scales", bo.scales, "field areas in multiples of 1.3 km x 0.7 km; the first must be 1")
      ->delimiter(',');
  app.add_option("--seed", bo.seed, "field generator seed");
  app.add_option("--keep", bo.keep_dir, "keep each field's results.h5 in this folder");
  bool no_compare = false;
  app.add_flag("--no-compare", no_compare, "skip the Oden-size field without fracture");
  return run_stage(app, argc, argv, [&] {
    FLOESIM_REQUIRE(!bo.scales.empty() && bo.scales.front() == 1,
                    "--scales must start with 1 (realtime_factor is measured on the Oden-size field)");
    for (int s : bo.scales) FLOESIM_REQUIRE(s >= 1 && s <= 100, "--scales: ", s, " is not in 1..100");
    const double n = bo.duration_s / 0.01;
    FLOESIM_REQUIRE(std::abs(n - std::round(n)) < 1e-6 && std::fmod(bo.duration_s + 1e-9, 0.2) < 1e-6, "--duration ",
                    bo.duration_s, " must be a multiple of the 0.2 s output interval");
    // The generated Oden-like hull, through the same OBJ writer and loader as a case's hull stage.
    const fs::path tmp = fs::temp_directory_path() / "floesim_bench";
    ensure_directory(tmp);
    write_obj(tmp / "hull.obj", generate_hull(HullGeneratorOptions{}), "floesim-bench hull");
    const HullModel hull = load_hull(tmp / "hull.obj");
    bo.compare = !no_compare;
    std::vector<double> compared;
    if (bo.compare)
      for (const Variant& v : kCompared) compared.push_back(run_field(1, bo, hull, v));
    double rtf1 = 0;
    for (size_t i = 0; i < bo.scales.size(); ++i) {
      const double rtf = run_field(bo.scales[i], bo, hull, kDefaults);
      if (i == 0) rtf1 = rtf;
    }
    if (bo.compare) {
      // Speed of the defaults against each other model on the Oden-size field, in this one run (> 1: faster).
      for (size_t i = 1; i < compared.size(); ++i)
        std::printf("speed ratio against %s: %.3f\n", kCompared[i].name, rtf1 / compared[i]);
      // Brash kept as rigid bodies against brash removed, with ice-ice failure on (>= 1: keeping it costs nothing).
      std::printf("rigid_brash_speed_ratio %.3f\n", rtf1 / compared[3]);
      std::printf("fracture_speed_ratio %.3f\n", rtf1 / compared[0]);
    }
    std::printf("realtime_factor %.2f\n", rtf1);
  });
}
