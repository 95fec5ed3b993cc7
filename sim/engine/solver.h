// Velocity-level contact solver: matrix-free projected Gauss-Seidel on the cone complementarity problem
// (PHYSICS.md §1.4-1.6), one normal row and two friction rows per contact, with warm starting. Rigid rows: the ERP
// push-out bias, normal impulse >= 0. Crushing rows (compliant contacts, §1.8(c)): the three-branch local law
// (separating -> 0; rigid below the crushing force dt F_0; crushing above it, hardening with K_t implicitly in the
// end-of-step velocity), never a push-out bias, so crushed overlap stays and nothing springs back (a pair backed off
// from its crushed depth only gets the free approach over the gap); the pressure of the pressure-area law is that of
// the body pair's whole contact area. Friction on the same row for both. Laid out like Chrono's ChSolverPSOR in
// numbered steps.
//
// Heavy-on-light chains (a 13,000 t hull pushing a 10 t piece against a 7,000 t floe) converge in thousands of
// Gauss-Seidel sweeps, not tens: the light body passes on a tiny share of the momentum per sweep. So every few
// sweeps that leave the tolerance unmet, a subspace minimisation (PGS-SM: Silcowitz, Niebe & Erleben 2010) solves
// the rows whose state the sweeps have settled (normal rows pressing, rigid or crushing; friction rows sticking)
// exactly with a sparse LDL^T factorisation of their Delassus matrix J M^-1 J^T, the other rows held at their
// impulses; the sweeps then project and correct what changed state. A chain converges in one such step.
#pragma once
#include <vector>

#include "sim/engine/model.h"
#include "sim/engine/parallel.h"
#include "sim/engine/state.h"

namespace floesim::sim {

struct SolverReport {
  // Over the islands of the solve: the most sweeps, all subspace solves, any island capped, the largest residual
  // and violation.
  int iterations = 0;            // sweeps of the last solve
  int subspace_solves = 0;       // subspace minimisations done
  bool capped = false;           // stopped at the sweep cap with the tolerance unmet
  double residual = 0;           // largest contact velocity change in the last sweep (m/s)
  // The largest violation of the contact law left (m/s): over every row, how far one more exact local update
  // would change the row's velocity (normal: complementarity with the bias, crushing: the three-branch law,
  // friction: the Coulomb disk). Zero at the exact solution; measured after the last sweep.
  double complementarity = 0;
};

// Per-body data the solver needs (world frame), filled by the caller for the bodies of the step.
struct SolverBodies {
  std::vector<Mat3> inv_mass;           // translational inverse mass matrix, world (with the added mass, §3.3)
  std::vector<Mat3> inv_inertia_world;
};

// The contacts grouped into islands: contacts that share a body the impulses move (directly or through other
// contacts) are in one island; a fixed body (a wall) joins nothing. Islands are ordered by their first contact and
// keep the contacts' order, so one island holding every contact is solved exactly as the whole list was.
struct ContactIslands {
  std::vector<int> index;  // contact indices, island after island
  std::vector<int> begin;  // island k: index[begin[k] .. begin[k + 1])
  int count() const { return static_cast<int>(begin.size()) - 1; }
};

// 1. Auxiliary data (lever arms, tangents, effective masses, bias, which bodies are fixed), 2. the warm start:
// impulses taken from the previous step's cache (matched by body/part pair and nearest local point) and applied to
// the velocities, and the contacts' islands (the same for every pass over these contacts).
// Maattanen's ice strength at the stress rate a closing speed v (m/s) gives against a structure w wide in ice h thick
// (PHYSICS.md 8.3; w_d = min(w, 2 h), sigma_dot = v 8 sigma_ref / (pi w_d)), over its value at rest: 1 at rest, 1.5 at
// the top of the rising branch, falling to 0.5 at the brittle plateau. contact.crushing_speed_law "maattanen" scales
// the crushing pressure against a structure by it.
double maattanen_strength_ratio(double closing_mps, double width_m, double thickness_m, double reference_pa);

ContactIslands prepare_contacts(const Model& model, const SolverBodies& bodies, State& state,
                                std::vector<Contact>& contacts, double dt);

// 3. Gauss-Seidel sweeps until the largest velocity change of a sweep is below `tolerance` or `iterations` sweeps,
// with a subspace minimisation every solver.subspace_every sweeps while unconverged (solver.method
// "pgs_subspace"). use_bias = false is the relax pass: rigid rows only keep non-penetration (and speculative
// gaps), no push-out; crushing rows have the same local law in both passes (their bias is only the free approach to
// the crushed depth).
// The contacts are solved as islands (joined by bodies that move), each to its own convergence, on the pool's
// threads if one is given; the report is that of the worst island (sweeps, residual, violation). `options`
// replaces model.settings.solver (the reference solves of solver.reference).
SolverReport solve_contacts(const Model& model, const SolverBodies& bodies, State& state,
                            std::vector<Contact>& contacts, const ContactIslands& islands, double dt, bool use_bias,
                            int iterations, double tolerance, ThreadPool* pool = nullptr,
                            const SolverOptions* options = nullptr);

// 4. Keeps the impulses for the next step's warm start (sorted, as the contacts are).
void store_impulses(const Model& model, State& state, const std::vector<Contact>& contacts);

}  // namespace floesim::sim
