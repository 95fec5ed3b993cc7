// Direct shear box on a keel's rubble (issue #36, PHYSICS.md §9.2 and §9.5 check 2): the engine's shear_box_test
// (sim/engine/ridge_shear_box.h) at one normal stress, with or without freeze bonds. The rubble's cohesion c and
// friction angle phi come from the peak shear stress over several normal stresses (sim/bench/ridge-shear-box fits
// them).
//
//   shear_box_bench --normal-stress 5000 [--tensile-pa 0] [--shear-pa 0] [--speed 0.02] [--travel 0.8] [--box 8]
//                   [--height 3.2] [--window 0.5] [--threads 2] [--seed 1] [--series FILE.csv]
//
// It prints the sample as consolidated, its balance at rest, the peak and the residual, and last a line
//   shear_box sigma <Pa> tau_peak <Pa> sigma_at_peak <Pa> at <m> tau_residual <Pa> sigma_residual <Pa> blocks <n>
//   bonds <formed> <broken> porosity <-> height <m>
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
  app.add_option("--tensile-pa", p.tensile_pa, "freeze bonds' tensile strength, Pa (0: no bonds)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--shear-pa", p.shear_pa, "freeze bonds' shear strength, Pa (0: no bonds)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--speed", p.speed_mps, "shear speed, m/s")->check(CLI::Range(0.001, 1.0));
  app.add_option("--travel", p.travel_m, "how far the bottom frame moves, m")->check(CLI::Range(0.05, 4.0));
  app.add_option("--box", p.box_m, "the box's inner side, m")->check(CLI::Range(2.0, 40.0));
  app.add_option("--height", p.sample_height_m, "the sample's height as released, m")->check(CLI::Range(0.5, 20.0));
  app.add_option("--window", p.window_s, "shear stress averaging window, s")->check(CLI::Range(0.01, 10.0));
  app.add_option("--threads", p.threads, "threads")->check(CLI::Range(1, 256));
  app.add_option("--seed", p.seed, "seed of the blocks")->check(CLI::Range(0, 2147483647));
  app.add_option("--series", series, "write travel, shear and normal stress, plate rise per step to this CSV");
  CLI11_PARSE(app, argc, argv);
  if ((p.tensile_pa > 0) != (p.shear_pa > 0)) {
    std::fprintf(stderr, "shear_box_bench: --tensile-pa and --shear-pa: give both (> 0) or neither\n");
    return 2;
  }
  try {
    const auto t0 = std::chrono::steady_clock::now();
    const ShearBoxResult r = shear_box_test(p, &std::cout);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%d blocks rose to rest in %.1f s and consolidated in %.1f s at %.0f Pa: sample %.2f m high "
                "(porosity %.3f), the shear plane %.2f m under the top plate; %d freeze bonds; %.0f s wall in all\n",
                r.blocks, r.rise_s, r.consolidate_s, r.sigma_consolidated_pa, r.sample_height_m, r.porosity,
                r.plane_depth_m, r.bonds, wall);
    std::printf("at rest: the top frame holds %.1f kN against the blocks' net buoyancy and the plate's push "
                "%.1f kN\n", r.held_down_n / 1e3, r.pushed_up_n / 1e3);
    std::printf("peak shear stress %.0f Pa at %.3f m (normal stress then %.0f Pa); residual over the last quarter "
                "%.0f Pa at %.0f Pa; %ld bonds broken\n", r.tau_peak_pa, r.peak_at_m, r.sigma_at_peak_pa,
                r.tau_residual_pa, r.sigma_residual_pa, r.bonds_broken);
    if (!series.empty()) {
      std::string csv = "travel_m,tau_pa,sigma_pa,plate_rise_m\n";
      char line[160];
      for (size_t k = 0; k < r.travel_m.size(); ++k) {
        std::snprintf(line, sizeof line, "%.4f,%.2f,%.2f,%.5f\n", r.travel_m[k], r.tau_pa[k], r.sigma_pa[k],
                      r.plate_rise_m[k]);
        csv += line;
      }
      write_text_atomic(series, csv);
    }
    std::printf("shear_box sigma %.2f tau_peak %.2f sigma_at_peak %.2f at %.4f tau_residual %.2f sigma_residual %.2f "
                "blocks %d bonds %d %ld porosity %.4f height %.4f\n",
                p.normal_stress_pa, r.tau_peak_pa, r.sigma_at_peak_pa, r.peak_at_m, r.tau_residual_pa,
                r.sigma_residual_pa, r.blocks, r.bonds, r.bonds_broken, r.porosity, r.sample_height_m);
    return 0;
  } catch (const Error& e) {
    std::fprintf(stderr, "shear_box_bench: %s\n", e.what());
    return 1;
  }
}
