// Punch test on a built keel (issue #36, PHYSICS.md §9.2 and §9.5 check 2): the engine's punch_test
// (sim/engine/ridge_punch.h) at one keel depth, with or without freeze bonds. The rubble's cohesion c and friction
// angle phi come from tau over several depths (sim/bench/ridge-punch fits them).
//
//   punch_bench --keel-depth 3 [--tensile-pa 0] [--shear-pa 0] [--speed 0.05] [--travel 1.5] [--rest 2]
//               [--window 0.5] [--threads 2] [--seed 1]
//
// It prints the keel as built, F_0 against the plug's net buoyancy by hand, the load's peak and residual, and last a
// line
//   punch keel_depth <m> plug_height <m> porosity <-> gamma_e <N/m^3> f0 <N> f0_by_hand <N> fpeak <N> at <m> tau <Pa>
//   bonds <formed> <broken> tau_residual <Pa>
#include <chrono>
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "pipeline/error.h"
#include "sim/engine/ridge_punch.h"

using namespace floesim;
using namespace floesim::sim;

int main(int argc, char** argv) {
  CLI::App app{"punch test on a keel built by settling (issue #36): the rubble's shear strength"};
  PunchSpec p;
  app.add_option("--keel-depth", p.keel_depth_m, "keel depth as given, m")->check(CLI::Range(1.5, 8.0));
  app.add_option("--tensile-pa", p.tensile_pa, "freeze bonds' tensile strength, Pa (0: no bonds)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--shear-pa", p.shear_pa, "freeze bonds' shear strength, Pa (0: no bonds)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--speed", p.speed_mps, "punch speed, m/s")->check(CLI::Range(0.001, 1.0));
  app.add_option("--travel", p.travel_m, "how far the punch moves down, m")->check(CLI::Range(0.05, 5.0));
  app.add_option("--rest", p.rest_s, "rest before the push, s")->check(CLI::Range(0.1, 60.0));
  app.add_option("--window", p.window_s, "load averaging window, s")->check(CLI::Range(0.01, 10.0));
  app.add_option("--threads", p.threads, "threads")->check(CLI::Range(1, 256));
  app.add_option("--seed", p.seed, "seed of the keel's blocks")->check(CLI::Range(0, 2147483647));
  CLI11_PARSE(app, argc, argv);
  if ((p.tensile_pa > 0) != (p.shear_pa > 0)) {
    std::fprintf(stderr, "punch_bench: --tensile-pa and --shear-pa: give both (> 0) or neither\n");
    return 2;
  }
  try {
    const auto t0 = std::chrono::steady_clock::now();
    const PunchResult r = punch_test(p, &std::cout);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("keel %.2f m deep as given: %d blocks settled in %.1f s, %d freeze bonds; as built %.2f m deep in the "
                "middle (%.2f m under the sheet), porosity %.3f by volume; %.0f s wall in all\n",
                p.keel_depth_m, r.blocks, r.settle_s, r.bonds, r.keel_depth_middle_m, r.plug_height_m, r.porosity,
                wall);
    std::printf("buoyant plug load F_0 %.1f kN (by hand, gamma_e a^2 h_p: %.1f kN); peak %.1f kN at %.3f m; mean "
                "shear stress on the plug's sides %.0f Pa; mean vertical stress there gamma_e h_p / 2 = %.0f Pa\n",
                r.f0_n / 1e3, r.f0_by_hand_n / 1e3, r.fpeak_n / 1e3, r.peak_at_m, r.tau_pa,
                r.gamma_e * r.plug_height_m / 2);
    std::printf("residual load over the push's last third %.1f kN: %.0f Pa on the plug's sides\n", r.fresidual_n / 1e3,
                r.tau_residual_pa);
    std::printf("punch keel_depth %.3f plug_height %.4f porosity %.4f gamma_e %.2f f0 %.1f f0_by_hand %.1f fpeak %.1f "
                "at %.4f tau %.2f bonds %d %ld tau_residual %.2f\n",
                p.keel_depth_m, r.plug_height_m, r.porosity, r.gamma_e, r.f0_n, r.f0_by_hand_n, r.fpeak_n,
                r.peak_at_m, r.tau_pa, r.bonds, r.bonds_broken, r.tau_residual_pa);
    return 0;
  } catch (const Error& e) {
    std::fprintf(stderr, "punch_bench: %s\n", e.what());
    return 1;
  }
}
