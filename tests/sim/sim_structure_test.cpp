// Structures in drifting ice (issue #34): a vertical cylinder crushing a level ice sheet at the crushing pressure over
// its width and clearing exactly the ice it sweeps (geometry by hand), the momentum a fixed structure carries against
// the ice's (a momentum budget in a vacuum), an upward-breaking cone bending the sheet up and being pushed down
// (PHYSICS.md §8.2.5's sign) into pieces of §8.2.4's 0.3-0.8 l_c (its break length), a moored body's offset under a
// steady pull against §8.4.1's worked catenary figures, a DP body back at its station within its thrust limits
// (§8.4.2), structures beside the vessel (each carrying its floe's momentum, its parts' forces adding up; a moored one
// at the catenary's offset), the same bits on one thread and two, and bad input named.
#include <gtest/gtest.h>

#include <cmath>

#include "pipeline/binary.h"
#include "pipeline/error.h"
#include "pipeline/options.h"
#include "pipeline/results_io.h"
#include "sim/engine/solver.h"
#include "sim/simulate/simulate.h"
#include "sim_fixtures.h"

namespace floesim::sim {
namespace {

using testing::expect_error;

HullModel structure(const std::string& shape, double width) {
  StructureShapeOptions s;
  s.shape = shape;
  s.waterline_width_m = width;
  s.neck_width_m = 0.4 * width;
  s.slope_deg = 45;
  s.depth_m = 6;
  s.height_m = 8;
  return hull_model_from_parts(generate_structure(s));
}

// A fixed structure at the origin, its x axis into the ice, in a sheet from x = 6 m drifting onto it at `drift`.
SimulateOptions drifting_sheet(double h, double drift) {
  SimulateOptions o;
  o.vessel.station_keeping.mode = "fixed";
  o.drift.speed_mps = drift;
  o.drift.direction_deg = 180;
  o.water.current_speed_mps = drift;
  o.water.current_direction_deg = 180;
  o.level_ice.extent_m = {6, -40, 86, 40};
  o.level_ice.tile_m = 80;
  o.level_ice.thickness_m = h;
  return o;
}

TEST(Structure, ACylinderCrushesTheSheetAtItsPressureOverItsWidthAndClearsWhatItSweeps) {
  const double h = 1.0, w = 10.0, v = 0.5, sigma_c = 2e6, rho_i = 900;
  SimulateOptions o = drifting_sheet(h, v);
  const HullModel cylinder = structure("cylinder", w);
  World world(build_model(FloeField{}, &cylinder, o));
  const double dt = o.time_step_s;
  // The sheet's edge is 1 m from the cylinder's face: contact at 2 s; the crushed face widens as the chord
  // 2 sqrt(2 R d - d^2) of the depth d until the front half is in the ice (d = R = 5 m, at 12 s); from 14 s on the
  // front presses on a crescent across its whole width.
  const double duration = 24.0;
  double sum = 0;
  int n = 0;
  const long steps = std::lround(duration / dt);
  for (long k = 1; k <= steps; ++k) {
    world.step();
    if (k * dt > 14.0) {
      sum += -world.report().ice_load.force.x();  // the cylinder moves +x through the ice: the ice pushes it -x
      ++n;
    }
  }
  // A round face of 32 flats, 10 m across them: the crushed face is its front half, 10 m wide.
  EXPECT_NEAR(sum / n, sigma_c * w * h, 0.02 * sigma_c * w * h);
  // Cleared: the ice the section has swept, less the crescent still pressed (at most the clearing depth deep): the
  // swept region is the front half-disc plus the width times the travel past the edge's first touch.
  const double travel = v * duration - 1.0, radius = w / 2;
  const double swept = kPi * radius * radius / 2 + w * (travel - radius);
  double cleared = 0;
  int events = 0;
  for (const FractureEvent& e : world.fracture_events()) {
    EXPECT_EQ(e.mode, kFractureCrushing);
    cleared += e.brash_mass_kg;
    ++events;
  }
  EXPECT_GT(events, 40);
  const double band = o.level_ice.clearing_depth_m * w;  // the crescent left in contact
  EXPECT_LE(cleared / (rho_i * h), swept * 1.01);
  EXPECT_GE(cleared / (rho_i * h), (swept - band) * 0.99);
}

TEST(Structure, AFixedStructureCarriesTheMomentumTheIceBrings) {
  // A vacuum without gravity: the contact is the only force on the floe, so what the structure takes over the run
  // is the floe's loss of momentum, to round-off.
  SimulateOptions o;
  o.vessel.station_keeping.mode = "fixed";
  o.water.enabled = false;
  o.water.gravity_mps2 = 0;
  o.fracture.enabled = false;
  o.sleep.enabled = false;
  FloeField field;
  field.floes.push_back(testing::rect_floe(1, 6, -8, 20, 14, 1.0));
  const HullModel caisson = structure("caisson", 10);
  World world(build_model(field, &caisson, o));
  const int floe = 1;
  world.mutable_state().velocity[floe] = Vec3(-1.0, 0.2, 0);
  const Vec3 p0 = world.model().bodies[floe].mass_kg * world.state().velocity[floe];
  Vec3 impulse = Vec3::Zero();
  for (int k = 0; k < 1500; ++k) {
    world.step();
    impulse += o.time_step_s * world.report().ice_load.force;
  }
  const Vec3 p1 = world.model().bodies[floe].mass_kg * world.state().velocity[floe];
  ASSERT_GT((p0 - p1).norm(), 0.5 * p0.norm());  // the floe hit the caisson and lost most of its momentum
  EXPECT_LT((impulse + (p1 - p0)).norm(), 1e-9 * p0.norm());
  EXPECT_EQ(world.state().position[0], world.model().bodies[0].initial_position);  // and the caisson never moved
}

TEST(Structure, AnUpwardBreakingConeBendsTheSheetUpAndIsPushedDown) {
  SimulateOptions o = drifting_sheet(0.5, 0.3);
  const HullModel cone = structure("cone", 10);
  World world(build_model(FloeField{}, &cone, o));
  double fz = 0;
  const int parts = world.model().bodies[0].part_count;
  for (int k = 0; k < 3000; ++k) {
    world.step();
    const StepReport& rep = world.report();
    fz += rep.ice_load.force.z();
    // Its parts' loads add up to its load.
    ASSERT_EQ(rep.vessel_part_force_n.size(), static_cast<size_t>(parts));
    Vec3 sum = Vec3::Zero();
    for (const Vec3& f : rep.vessel_part_force_n) sum += f;
    EXPECT_LT((sum - rep.ice_load.force).norm(), 1e-9 * (1 + rep.ice_load.force.norm()));
  }
  int bending = 0;
  for (const FractureEvent& e : world.fracture_events())
    if (e.at_structure && (e.mode == kFractureBending || e.mode == kFractureRadial)) {
      ++bending;
      EXPECT_GT(e.force_n.z(), 0) << "the cone lifts the ice it breaks";
    }
  EXPECT_GT(bending, 0);
  EXPECT_LT(fz, 0) << "the ice riding up presses the cone down (PHYSICS.md 8.2.5)";
}

TEST(Structure, TheConesBreakLengthIsTheWedgesOfTheSheetsCharacteristicLength) {
  // PHYSICS.md 8.2.4: a cone breaks the sheet into pieces of R_b = 0.3-0.8 l_c along the drift, so the load period
  // (break length over drift speed) is 4-12 h/v. The summary's break length is the pieces' extent along the drift;
  // l_c by hand from the plate's stiffness and the water's.
  SimulateOptions o = drifting_sheet(0.5, 0.3);
  o.duration_s = 40;
  o.steady_start_s = 10;
  o.output_interval_s = 1;
  const HullModel cone = structure("cone", 10);
  const Model m = build_model(FloeField{}, &cone, o);
  RunStats stats;
  const Results r = simulate(o, m, stats);
  const nlohmann::json b = summarize(o, m, r)["structure"]["breaking"]["break_length"];
  const double E = o.fracture.youngs_modulus_pa, nu = o.fracture.poisson_ratio, h = 0.5;
  const double lc = std::pow(E * h * h * h / (12 * (1 - nu * nu) * o.water.density_kg_m3 * o.water.gravity_mps2), 0.25);
  ASSERT_GE(b["pieces"].get<int>(), 3) << b.dump();
  const double median = b["median_m"].get<double>();
  std::printf("[measured] %d pieces, break length median %.2f m = %.2f l_c = %.1f h\n", b["pieces"].get<int>(), median,
              median / lc, median / h);
  EXPECT_GT(median, 0.3 * lc);
  EXPECT_LT(median, 0.8 * lc);
  EXPECT_NEAR(b["period_over_h_per_v"].get<double>(), median / h, 1e-12);
}

TEST(Structure, TheSameBitsOnOneThreadAndTwo) {
  auto loads = [](int threads) {
    SimulateOptions o = drifting_sheet(0.5, 0.3);
    o.threads = threads;
    const HullModel cone = structure("cone", 10);
    World world(build_model(FloeField{}, &cone, o));
    std::vector<double> f;
    for (int k = 0; k < 2500; ++k) {
      world.step();
      for (int i = 0; i < 3; ++i) f.push_back(world.report().ice_load.force[i]);
    }
    return f;
  };
  EXPECT_EQ(loads(1), loads(2));
}

// A floating caisson, 30 m square and 6 m deep, on the 12-line spread of PHYSICS.md §8.4.1's worked example
// (1 kN/m chain, 40 m above the seabed, 600 m long, 300 kN pretension, at 15 + 30 i degrees).
SimulateOptions moored_caisson() {
  SimulateOptions o;
  o.vessel.station_keeping.mode = "moored";
  for (int i = 0; i < 12; ++i) {
    MooringLineOptions l;
    l.azimuth_deg = 15 + 30 * i;
    o.vessel.station_keeping.lines.push_back(l);
  }
  o.vessel.vcg_m = -2.0;
  return o;
}

HullModel floating_caisson() {
  StructureShapeOptions s;
  s.shape = "caisson";
  s.waterline_width_m = 30;
  s.depth_m = 6;
  s.height_m = 6;
  return hull_model_from_parts(generate_structure(s));
}

// The reference point's offset from the station, earth frame (the run here is in the earth frame).
Vec2 offset_of(const World& w) {
  const Model& m = w.model();
  const Vec3 ref = w.state().position[0] + w.state().orientation[0] * m.station.reference_point_body;
  return (ref - m.station.position).head<2>();
}

TEST(Structure, AMooredBodyTakesTheCatenarysOffsetUnderASteadyPull) {
  // §8.4.1: 1 MN gives 1.64 m (the linear stiffness's 1.79 m would be 9 % off). The pull grows over 150 s, ten
  // natural periods (2 pi sqrt(m / K_xx) = 14 s), so the body follows it quasi-statically; then held for 150 s.
  for (const double load : {1e6, 2e6}) {
    SimulateOptions o = moored_caisson();
    o.vessel.station_keeping.applied_force_n = {load, 0};
    o.vessel.station_keeping.applied_force_ramp_s = 150;
    const HullModel caisson = floating_caisson();
    World world(build_model(FloeField{}, &caisson, o));
    double sum = 0, pull = 0, lo = 1e9, hi = -1e9;
    int n = 0;
    for (int k = 1; k <= 30000; ++k) {
      world.step();
      if (k > 20000) {
        const double x = offset_of(world).x();
        sum += x, lo = std::min(lo, x), hi = std::max(hi, x), ++n;
        pull += world.report().station_keeping.delivered[0];
      }
    }
    const double expected = load == 1e6 ? 1.64 : 2.74;  // PHYSICS.md §8.4.1, to its printed digits
    EXPECT_NEAR(sum / n, expected, 0.01) << load;
    EXPECT_LT(hi - lo, 0.1 * expected) << "a small swing about it: the pull was taken on quasi-statically";
    // The lines' mean pull balances the load: what the run recorded as the station keeping's force.
    EXPECT_NEAR(pull / n, -load, 0.005 * load);
  }
}

// A structure beside the vessel (options.structures): the vessel a fixed caisson far off, out of the way.
StructureOptions listed(const std::string& name, const std::string& mode, double x, double y) {
  StructureOptions s;
  s.name = name;
  s.body.station_keeping.mode = mode;
  s.body.x_m = x;
  s.body.y_m = y;
  return s;
}

TEST(Structure, TwoStructuresBesideTheVesselEachCarryTheMomentumOfTheFloeThatHitsThem) {
  // A vacuum without gravity, as above: each caisson takes what its floe loses, and its parts' forces add up to it.
  SimulateOptions o;
  o.vessel.station_keeping.mode = "fixed";
  o.vessel.y_m = -300;
  o.water.enabled = false;
  o.water.gravity_mps2 = 0;
  o.fracture.enabled = false;
  o.sleep.enabled = false;
  o.structures = {listed("west", "fixed", 0, 0), listed("east", "fixed", 0, 60)};
  FloeField field;
  field.floes.push_back(testing::rect_floe(1, 6, -8, 20, 14, 1.0));
  field.floes.push_back(testing::rect_floe(2, 6, 52, 20, 14, 1.0));
  const HullModel caisson = structure("caisson", 10);
  World world(build_model(field, &caisson, o, {caisson, caisson}));
  const Model& m = world.model();
  ASSERT_EQ(m.structures.size(), 2u);
  const int floes[2] = {3, 4};  // after the vessel (0) and the two structures (1, 2)
  world.mutable_state().velocity[floes[0]] = Vec3(-1.0, 0.2, 0);
  world.mutable_state().velocity[floes[1]] = Vec3(-0.5, -0.1, 0);
  Vec3 p0[2], impulse[2] = {Vec3::Zero(), Vec3::Zero()};
  for (int i = 0; i < 2; ++i) p0[i] = m.bodies[floes[i]].mass_kg * world.state().velocity[floes[i]];
  for (int k = 0; k < 1500; ++k) {
    world.step();
    for (int i = 0; i < 2; ++i) {
      const StructureReport& sr = world.report().structures[i];
      impulse[i] += o.time_step_s * sr.ice_load.force;
      Vec3 parts = Vec3::Zero();
      for (const Vec3& f : sr.part_force_n) parts += f;
      EXPECT_LT((parts - sr.ice_load.force).norm(), 1e-9 * (1 + sr.ice_load.force.norm()));
    }
    EXPECT_EQ(world.report().ice_load.force, Vec3::Zero());  // the vessel, far off, is touched by nothing
  }
  for (int i = 0; i < 2; ++i) {
    const Vec3 p1 = m.bodies[floes[i]].mass_kg * world.state().velocity[floes[i]];
    ASSERT_GT((p0[i] - p1).norm(), 0.5 * p0[i].norm()) << i;
    EXPECT_LT((impulse[i] + (p1 - p0[i])).norm(), 1e-9 * p0[i].norm()) << i;
    const int b = m.structures[i].body;
    EXPECT_EQ(world.state().position[b], m.bodies[b].initial_position);
  }
}

TEST(Structure, AMooredStructureBesideTheVesselTakesTheCatenarysOffsetUnderASteadyPull) {
  // As the moored body above, held as a structure beside the vessel: §8.4.1's 1.64 m under 1 MN, its recorded line
  // tensions those of the spread at its offset.
  SimulateOptions base = moored_caisson();
  SimulateOptions o;
  o.vessel.station_keeping.mode = "fixed";
  o.vessel.y_m = -300;
  StructureOptions s = listed("floater", "moored", 0, 0);
  s.body.station_keeping = base.vessel.station_keeping;
  s.body.station_keeping.applied_force_n = {1e6, 0};
  s.body.station_keeping.applied_force_ramp_s = 150;
  s.body.vcg_m = -2.0;
  o.structures = {s};
  const HullModel caisson = floating_caisson(), far = structure("caisson", 10);
  World world(build_model(FloeField{}, &far, o, {caisson}));
  double sum = 0;
  int n = 0;
  for (int k = 1; k <= 30000; ++k) {
    world.step();
    if (k > 20000) sum += world.report().structures[0].station_keeping.offset.x(), ++n;
  }
  EXPECT_NEAR(sum / n, 1.64, 0.01);
  const StationKeeping& sk = world.report().structures[0].station_keeping;
  const SpreadState sp = spread_at_pose(world.model().structures[0].station.mooring, sk.offset.x(), sk.offset.y(),
                                        sk.heading_change_rad);
  ASSERT_EQ(sk.line_tension_n.size(), 12u);
  for (size_t l = 0; l < 12; ++l) EXPECT_DOUBLE_EQ(sk.line_tension_n[l], sp.lines[l].fairlead_tension_n) << l;
}

TEST(Structure, ADpBodyReturnsToItsStationWithinItsLimits) {
  // §8.4.2: the caisson held by DP under a steady 0.5 MN pull; P and D alone would leave F / K_p, the integral takes
  // it back to the station. The thrusters never deliver more than their limits.
  SimulateOptions o;
  o.vessel.station_keeping.mode = "dp";
  o.vessel.vcg_m = -2.0;
  o.vessel.station_keeping.applied_force_n = {5e5, 0};
  o.vessel.station_keeping.dp.max_force_x_n = 8e5;
  const HullModel caisson = floating_caisson();
  World world(build_model(FloeField{}, &caisson, o));
  const DpOptions& d = o.vessel.station_keeping.dp;
  double largest = 0, late = 0;
  int n = 0;
  const long steps = std::lround(1200.0 / o.time_step_s);
  for (long k = 1; k <= steps; ++k) {
    world.step();
    const StationKeeping& sk = world.report().station_keeping;
    largest = std::max(largest, std::abs(sk.delivered[0]) / d.max_force_x_n);
    largest = std::max(largest, std::abs(sk.delivered[1]) / d.max_force_y_n);
    largest = std::max(largest, std::abs(sk.delivered[2]) / d.max_moment_z_nm);
    if (k * o.time_step_s > 900) late += offset_of(world).x(), ++n;
  }
  const double kp = world.model().station.dp.surge.proportional;
  EXPECT_GT(5e5 / kp, 1.0) << "without the integral the offset would be metres";
  EXPECT_LT(std::abs(late / n), 0.02 * 5e5 / kp);
  EXPECT_LE(largest, 1.0);
}

TEST(Structure, ADpWorldSavedAndRestoredStepsOnBitForBit) {
  // The controller's observer and integral carry over in the state: a world restored from its bytes in the middle
  // of the pull steps on exactly as the saved one.
  SimulateOptions o;
  o.vessel.station_keeping.mode = "dp";
  o.vessel.vcg_m = -2.0;
  o.vessel.station_keeping.applied_force_n = {3e5, 2e5};
  o.vessel.station_keeping.applied_force_ramp_s = 20;
  const HullModel caisson = floating_caisson();
  const Model model = build_model(FloeField{}, &caisson, o);
  World a(model);
  for (int k = 0; k < 1500; ++k) a.step();
  ASSERT_EQ(a.state().dp_memory.size(), static_cast<size_t>(DpController::kMemory));
  ByteWriter w;
  a.save(w);
  ByteReader r(w.bytes(), "test");
  std::unique_ptr<World> b = World::restore(model, r);
  for (int k = 0; k < 1500; ++k) {
    a.step();
    b->step();
    for (int i = 0; i < 3; ++i)
      ASSERT_EQ(a.report().station_keeping.delivered[i], b->report().station_keeping.delivered[i]) << k;
  }
  EXPECT_EQ(a.state().position[0], b->state().position[0]);
}

TEST(Structure, ARunWithAStructureBesideTheVesselResumesToTheSameBits) {
  // A DP caisson beside the vessel pulled by a tug: its controller's memory and its series carry over a checkpoint,
  // so a run resumed from it records exactly what the whole run did.
  SimulateOptions o;
  o.vessel.station_keeping.mode = "fixed";
  o.vessel.y_m = -300;
  o.duration_s = 1.0;
  o.output_interval_s = 0.1;
  o.checkpoint_interval_s = 0.5;
  StructureOptions s = listed("tugged", "dp", 0, 0);
  s.body.vcg_m = -2.0;
  s.body.station_keeping.applied_force_n = {3e5, 2e5};
  o.structures = {s};
  const HullModel caisson = floating_caisson(), far = structure("caisson", 10);
  const Model model = build_model(FloeField{}, &far, o, {caisson});
  const std::filesystem::path dir = testing::temp_dir("structure_resume") / "checkpoint";
  CheckpointPlan plan{dir, {{"program", "sim_structure_test"}}, false};
  RunStats stats;
  const Results whole = simulate(o, model, stats, nullptr, &plan);
  ASSERT_EQ(stats.checkpoints, 1);  // at 0.5 s
  plan.resume = true;
  const Results resumed = simulate(o, model, stats, nullptr, &plan);
  EXPECT_EQ(stats.resumed_at_step, 50);
  ASSERT_EQ(whole.structure_series.count("tugged/station_keeping_delivered"), 1u);
  EXPECT_EQ(whole.structure_series.at("tugged/offset").size(), 3u * 100);
  EXPECT_EQ(resumed.structure_series, whole.structure_series);
  EXPECT_EQ(resumed.attributes["structures"], whole.attributes["structures"]);
  std::filesystem::remove_all(dir.parent_path());
}

TEST(Structure, IceDriftingUnderStillAirRestsUntilTheStructureComes) {
  // In the ice's frame the still air passes the ice at the drift: 0.5 m/s of it drives a free floe at 0.5 sqrt(1.3 x
  // 0.0012 / (1025 x 0.005)) = 8.7 mm/s, below the 20 mm/s a floe sleeps under, so the field may rest; 2 m/s of wind
  // against the drift (2.5 m/s past the ice: 43 mm/s) drives it, and nothing sleeps.
  for (const double wind : {0.0, 2.0}) {
    SimulateOptions o;
    o.vessel.station_keeping.mode = "fixed";
    o.drift.speed_mps = o.water.current_speed_mps = 0.5;
    o.drift.direction_deg = o.water.current_direction_deg = 180;
    o.wind.speed_mps = wind;
    FloeField field;
    field.floes.push_back(testing::rect_floe(1, 200, -10, 20, 20, 1.0));
    const HullModel cone = structure("cone", 10);
    World world(build_model(field, &cone, o));
    for (int k = 0; k < 300; ++k) world.step();
    EXPECT_EQ(world.state().awake[1], wind == 0 ? 0 : 1) << "wind " << wind;
  }
}

TEST(Structure, MaattanensStrengthGivesTheWorkedLoads) {
  // PHYSICS.md 8.3's example (w = 5 m, h = 1 m, sigma_ref = 2.2 MPa): F = sigma (w_d h)^-1/2 w h is 7.07 MN at rest,
  // 10.60 MN at 0.104 m/s (the top of the rising branch), 8.98 at 0.2, 6.03 at 0.3 and 3.55 MN at 0.474 m/s.
  const double at_rest = 2.00e6 / std::sqrt(2.0) * 5;
  const std::vector<std::pair<double, double>> worked = {
      {0.0, 7.07e6}, {0.104, 10.60e6}, {0.2, 8.98e6}, {0.3, 6.03e6}, {0.474, 3.55e6}};
  for (const auto& [v, f] : worked) EXPECT_NEAR(at_rest * maattanen_strength_ratio(v, 5, 1, 2.2e6), f, 0.005e6) << v;
  // Above the falling branch the brittle plateau: the strength at its end, 0.5 of the one at rest.
  EXPECT_NEAR(maattanen_strength_ratio(2.0, 5, 1, 2.2e6), maattanen_strength_ratio(1.3287 / 2.8011, 5, 1, 2.2e6),
              1e-3);
  EXPECT_NEAR(maattanen_strength_ratio(2.0, 5, 1, 2.2e6), 0.502, 0.002);
}

// A compliant structure (a 5 m cylinder on its first mode) in a level ice sheet drifting onto it at `drift`.
SimulateOptions compliant_in_sheet(double drift) {
  SimulateOptions o = drifting_sheet(1.0, drift);
  o.vessel.station_keeping.mode = "compliant";
  o.vessel.station_keeping.compliant.modal_mass_kg = 1e6;
  o.vessel.station_keeping.compliant.natural_frequency_hz = 0.33;
  o.vessel.station_keeping.compliant.damping_ratio = 0.02;
  o.contact.crushing_speed_law = "maattanen";
  return o;
}

TEST(Structure, ACompliantStructureSwaysAtItsNaturalFrequencyWithItsDamping) {
  // Free vibration in open water, released 0.1 m off its station: zero crossings 1 / f_n apart (the damped period,
  // 0.02 % longer), each cycle's amplitude exp(-2 pi zeta / sqrt(1 - zeta^2)) of the one before.
  SimulateOptions o = compliant_in_sheet(0.0);
  o.level_ice.extent_m.clear();
  o.drift.speed_mps = o.water.current_speed_mps = 0;
  const HullModel cylinder = structure("cylinder", 5);
  World world(build_model(FloeField{}, &cylinder, o));
  world.mutable_state().position[0].x() += 0.1;
  std::vector<double> up, peaks;
  double last = 0.1, top = 0;
  for (int k = 1; k <= 3000; ++k) {
    world.step();
    const double x = world.report().station_keeping.offset.x();
    if (last < 0 && x >= 0) up.push_back(k * o.time_step_s - x / (x - last) * o.time_step_s);
    if (last < 0 && x >= 0 && top > 0) peaks.push_back(top), top = 0;
    if (x > 0) top = std::max(top, x);
    last = x;
  }
  ASSERT_GE(up.size(), 8u);
  const double zeta = 0.02, period = 1 / 0.33 / std::sqrt(1 - zeta * zeta);
  EXPECT_NEAR((up.back() - up.front()) / static_cast<double>(up.size() - 1), period, 0.005 * period);
  const double decay = std::exp(-2 * kPi * zeta / std::sqrt(1 - zeta * zeta));
  for (size_t i = 1; i < peaks.size(); ++i) EXPECT_NEAR(peaks[i] / peaks[i - 1], decay, 0.01) << i;
}

// The sway of a compliant 5 m cylinder (f_n 2 Hz, 2 % damping) in 1 m ice drifting at v: its velocity amplitude over
// the earth (sqrt 2 x its standard deviation) and its frequency (up-crossings of the velocity) after the start.
struct Sway {
  double amplitude_mps = 0, frequency_hz = 0;
};
Sway sway_in_sheet(double v, const char* law) {
  SimulateOptions o = compliant_in_sheet(v);
  o.vessel.station_keeping.compliant.natural_frequency_hz = 2.0;
  o.contact.crushing_speed_law = law;
  const HullModel cylinder = structure("cylinder", 5);
  World world(build_model(FloeField{}, &cylinder, o));
  const double t0 = 2.0 / v + 10, window = 20;  // in the ice after the front half's 2.5 m
  double s = 0, s2 = 0, last = 0;
  int n = 0, up = 0;
  for (long k = 1; k * o.time_step_s <= t0 + window; ++k) {
    world.step();
    const double u = world.state().velocity[0].x() + world.model().frame_velocity.x();
    if (k * o.time_step_s > t0) {
      s += u, s2 += u * u, ++n;
      up += last < 0 && u >= 0;
    }
    last = u;
  }
  const double mean = s / n;
  return {std::sqrt(2 * (s2 / n - mean * mean)), up / window};
}

TEST(Structure, MaattanensFallingStrengthDrivesACompliantStructureAtItsNaturalFrequency) {
  // PHYSICS.md 8.3: on the falling branch (0.2 m/s, for w_d = 2 m) the strength falls as the ice closes faster, a
  // negative damping far beyond the structure's 2 %: the sway grows until it is limited by the ice separating, at the
  // structure's natural frequency. With a strength that does not depend on the speed it stays small.
  const Sway flat = sway_in_sheet(0.2, "none"), falling = sway_in_sheet(0.2, "maattanen");
  EXPECT_LT(flat.amplitude_mps, 0.1 * 0.2);
  EXPECT_GT(falling.amplitude_mps, 10 * flat.amplitude_mps);
  EXPECT_GT(falling.amplitude_mps, 0.2) << "a locked structure sways at about the ice's speed";
  EXPECT_NEAR(falling.frequency_hz, 2.0, 0.5);
}

TEST(Structure, BadInputIsNamed) {
  SimulateOptions o = drifting_sheet(1.0, 0.2);
  o.level_ice.extent_m.clear();
  const HullModel cone = structure("cone", 10);
  expect_error([&] { build_model(FloeField{}, &cone, o); }, {"drift.speed_mps", "no ice"});
  Json j = options_to_json(drifting_sheet(1.0, 0.2));
  j["vessel"]["propellers"] = Json::array({Json{{"position_m", {-10, 0, -3}}}});
  expect_error([&] { read_options<SimulateOptions>(j, "case.json"); }, {"propellers", "fixed"});
  j = options_to_json(drifting_sheet(1.0, 0.2));
  j["vessel"]["station_keeping"]["mode"] = "floating";
  expect_error([&] { read_options<SimulateOptions>(j, "case.json"); }, {"station_keeping.mode"});
  // Mooring: a line shorter than the water depth, a moored body without lines, negative DP figures.
  j = options_to_json(moored_caisson());
  j["vessel"]["station_keeping"]["lines"][3]["length_m"] = 30;
  expect_error([&] { read_options<SimulateOptions>(j, "case.json"); },
               {"station_keeping.lines[3].length_m", "fairlead_height_m"});
  j = options_to_json(moored_caisson());
  j["vessel"]["station_keeping"]["lines"] = Json::array();
  expect_error([&] { read_options<SimulateOptions>(j, "case.json"); }, {"station_keeping.lines", "at least one"});
  j = options_to_json(moored_caisson());
  j["vessel"]["station_keeping"]["mode"] = "dp";
  j["vessel"]["station_keeping"]["lines"] = Json::array();
  j["vessel"]["station_keeping"]["dp"]["damping_ratio"] = -0.7;
  j["vessel"]["station_keeping"]["dp"]["max_force_y_n"] = 0;
  expect_error([&] { read_options<SimulateOptions>(j, "case.json"); },
               {"station_keeping.dp.damping_ratio", "station_keeping.dp.max_force_y_n"});
  // Structures beside the vessel: one driven as a ship, two of one name, one without a mesh or with a bad name, and
  // meshes that do not match the list.
  j = options_to_json(drifting_sheet(1.0, 0.2));
  j["structures"] = Json::array({Json{{"name", "a"}, {"hull_file", "a.obj"}, {"station_keeping", {{"mode", "fixed"}}}},
                                 Json{{"name", "a"}, {"hull_file", "b.obj"}, {"station_keeping", {{"mode", "fixed"}}}},
                                 Json{{"name", "c"}, {"hull_file", "c.obj"}}, Json{{"name", "d e"}, {"hull_file", ""},
                                 {"station_keeping", {{"mode", "dp"}}}}});
  expect_error([&] { read_options<SimulateOptions>(j, "case.json"); },
               {"two structures are named \"a\"", "structures[2].station_keeping", "drives a ship",
                "structures[3].name", "structures[3].hull_file"});
  SimulateOptions two = drifting_sheet(1.0, 0.2);
  two.structures = {listed("a", "fixed", 0, 40), listed("b", "fixed", 0, -40)};
  expect_error([&] { build_model(FloeField{}, &cone, two, {cone}); }, {"1 structure meshes for 2 structures"});
}

}  // namespace
}  // namespace floesim::sim
