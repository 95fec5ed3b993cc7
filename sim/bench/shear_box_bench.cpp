// Direct shear box on a keel's rubble (issue #36, PHYSICS.md §9.2 and §9.5 check 2): the engine's shear_box_test
// (sim/engine/ridge_shear_box.h) at one normal stress, with or without freeze bonds. The rubble's cohesion c and
// friction angle phi come from the peak shear stress over several normal stresses (sim/bench/ridge-shear-box fits
// them).
//
//   shear_box_bench --normal-stress 5000 [--bonds-pa 0 ...] [--speed 0.02] [--travel 0.4] [--peak-within 0.3]
//                   [--box 8] [--height 3.2] [--window 0.5] [--threads 2] [--seed 1] [--series FILE.csv]
//
// The one consolidated sample is sheared once for each of --bonds-pa (freeze bonds of sigma_t = tau_b; 0: none).
// It prints the sample as consolidated and its balance at rest, then for each shear its peak and residual and a line
//   shear_box sigma <Pa> bonds_pa <Pa> tau_peak <Pa> sigma_at_peak <Pa> at <m> tau_residual <Pa> sigma_residual <Pa>
//   blocks <n> bonds <formed> <broken> porosity <-> height <m>
#include <chrono>
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "sim/engine/ridge_shear_box.h"

using namespace floesim;
using namespace floesim::sim;

int main(int argc, char** argv) {
  CLI::App app{"direct shear box on a keel's rubble (issue #36): the peak shear stress at one normal stress"};
  ShearBoxSpec p;
  std::string series;
  app.add_option("--normal-stress", p.normal_stress_pa, "normal stress held on the shear plane, Pa")
      ->check(CLI::Range(100.0, 1e6));
  p.bonds_pa.clear();
  app.add_option("--bonds-pa", p.bonds_pa, "freeze bonds' strength sigma_t = tau_b, Pa, for each shear of the sample "
                 "(0: no bonds)")
      ->check(CLI::NonNegativeNumber)
      ->default_str("0");
  app.add_option("--speed", p.speed_mps, "shear speed, m/s")->check(CLI::Range(0.001, 1.0));
  app.add_option("--travel", p.travel_m, "how far the bottom frame moves, m")->check(CLI::Range(0.05, 4.0));
  app.add_option("--peak-within", p.peak_within_m, "the peak is read within this travel, m")
      ->check(CLI::Range(0.01, 4.0));
  app.add_option("--box", p.box_m, "the box's inner side, m")->check(CLI::Range(2.0, 40.0));
  app.add_option("--height", p.sample_height_m, "the sample's height as released, m")->check(CLI::Range(0.5, 20.0));
  app.add_option("--window", p.window_s, "shear stress averaging window, s")->check(CLI::Range(0.01, 10.0));
  app.add_option("--threads", p.threads, "threads")->check(CLI::Range(1, 256));
  app.add_option("--seed", p.seed, "seed of the blocks")->check(CLI::Range(0, 2147483647));
  app.add_option("--series", series,
                 "write each shear's bonds, travel, shear and normal stress and plate rise per step to this CSV");
  CLI11_PARSE(app, argc, argv);
  if (p.bonds_pa.empty()) p.bonds_pa = {0};
  try {
    const auto t0 = std::chrono::steady_clock::now();
    const ShearBoxResult r = shear_box_test(p, &std::cout);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%d blocks rose to rest in %.1f s and consolidated in %.1f s at %.0f Pa: sample %.2f m high "
                "(porosity %.3f), the shear plane %.2f m under the top plate; %.0f s wall in all\n",
                r.blocks, r.rise_s, r.consolidate_s, r.sigma_consolidated_pa, r.sample_height_m, r.porosity,
                r.plane_depth_m, wall);
    std::printf("at rest: the top frame holds %.1f kN against the blocks' net buoyancy and the plate's push "
                "%.1f kN\n", r.held_down_n / 1e3, r.pushed_up_n / 1e3);
    std::string csv = "bonds_pa,travel_m,tau_pa,sigma_pa,plate_rise_m\n";
    for (const ShearTest& s : r.shears) {
      std::printf("bonds of %.0f Pa: %d formed, %ld broken; peak shear stress %.0f Pa at %.3f m (normal stress then "
                  "%.0f Pa); residual over the last quarter %.0f Pa at %.0f Pa\n", s.bonds_pa, s.bonds,
                  s.bonds_broken, s.tau_peak_pa, s.peak_at_m, s.sigma_at_peak_pa, s.tau_residual_pa,
                  s.sigma_residual_pa);
      char line[200];
      for (size_t k = 0; k < s.travel_m.size(); ++k) {
        std::snprintf(line, sizeof line, "%.0f,%.4f,%.2f,%.2f,%.5f\n", s.bonds_pa, s.travel_m[k], s.tau_pa[k],
                      s.sigma_pa[k], s.plate_rise_m[k]);
        csv += line;
      }
    }
    if (!series.empty()) write_text_atomic(series, csv);
    for (const ShearTest& s : r.shears)
      std::printf("shear_box sigma %.2f bonds_pa %.2f tau_peak %.2f sigma_at_peak %.2f at %.4f tau_residual %.2f "
                  "sigma_residual %.2f blocks %d bonds %d %ld porosity %.4f height %.4f\n",
                  p.normal_stress_pa, s.bonds_pa, s.tau_peak_pa, s.sigma_at_peak_pa, s.peak_at_m, s.tau_residual_pa,
                  s.sigma_residual_pa, r.blocks, s.bonds, s.bonds_broken, r.porosity, r.sample_height_m);
    return 0;
  } catch (const Error& e) {
    std::fprintf(stderr, "shear_box_bench: %s\n", e.what());
    return 1;
  }
}
