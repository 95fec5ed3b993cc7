// Velocity-level contact solver: matrix-free projected Gauss-Seidel on the cone complementarity problem
// (PHYSICS.md §1.4-1.6), one normal row and two friction rows per contact, with warm starting. Rigid rows: the ERP
// push-out bias, normal impulse >= 0. Crushing rows (compliant contacts, §1.8(c)): the three-branch local law
// (separating -> 0; rigid below the crushing force dt F_0; crushing above it, hardening with K_t implicitly in the
// end-of-step velocity), never a push-out bias, so crushed overlap stays and nothing springs back (a pair backed off
// from its crushed depth only gets the free approach over the gap); the pressure of the pressure-area law is that of
// the body pair's whole contact area. Friction on the same row for both. Laid out like Chrono's ChSolverPSOR in
// numbered steps.
#pragma once
#include <vector>

#include "sim/model.h"
#include "sim/state.h"

namespace floesim::sim {

struct SolverReport {
  int iterations = 0;     // sweeps of the last solve
  double residual = 0;    // largest contact velocity change in the last sweep (m/s)
};

// Per-body data the solver needs (world frame), filled by the caller for the bodies of the step.
struct SolverBodies {
  std::vector<Mat3> inv_mass;           // translational inverse mass matrix, world (with the added mass, §3.3)
  std::vector<Mat3> inv_inertia_world;
};

// 1. Auxiliary data (lever arms, tangents, effective masses, bias) and 2. the warm start: impulses taken from the
// previous step's cache (matched by body/part pair and nearest local point) and applied to the velocities.
void prepare_contacts(const Model& model, const SolverBodies& bodies, State& state, std::vector<Contact>& contacts,
                      double dt);

// 3. Gauss-Seidel sweeps until the largest velocity change of a sweep is below `tolerance` or `iterations` sweeps.
// use_bias = false is the relax pass: rigid rows only keep non-penetration (and speculative gaps), no push-out;
// crushing rows have the same local law in both passes (their bias is only the free approach to the crushed depth).
SolverReport solve_contacts(const Model& model, const SolverBodies& bodies, State& state,
                            std::vector<Contact>& contacts, double dt, bool use_bias, int iterations,
                            double tolerance);

// 4. Keeps the impulses for the next step's warm start (sorted, as the contacts are).
void store_impulses(const Model& model, State& state, const std::vector<Contact>& contacts);

}  // namespace floesim::sim
