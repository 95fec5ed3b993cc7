// The simulate stage end to end on tiny cases: the results layout (rows per step, frames at the output interval),
// the mean ice load against the momentum given to the ice, the ice's momentum budget over a transit, and
// byte-identical reruns.
#include <gtest/gtest.h>

#include <cstring>

#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <random>

#include "pipeline/provenance.h"
#include "sim/simulate/simulate.h"
#include "sim/engine/world.h"
#include "sim_fixtures.h"

namespace floesim::sim {
namespace {

using testing::coarse_hull;
using testing::box_hull;
using testing::rect_floe;
using testing::temp_dir;

// 20 square floes (7 m, gaps of 1.5 m) in a 4 x 5 block ahead of a bow that starts at x ~ 54 m.
FloeField floe_block(double x0 = 60) {
  FloeField field;
  int id = 1;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 5; ++j) field.floes.push_back(rect_floe(id++, x0 + i * 8.5, -21 + j * 8.5, 7, 7, 1.0));
  return field;
}

// The results layout of a 20 s transit: rows per step, frames at the output interval (the loads' magnitudes are
// checked against independent numbers below).
TEST(SimTransit, LayoutIsExact) {
  const HullModel hull = coarse_hull(8);
  SimulateOptions o;
  o.duration_s = 20;
  o.steady_start_s = 5;
  o.output_interval_s = 0.2;
  const Model m = build_model(floe_block(), &hull, o);
  ASSERT_EQ(m.floe_count(), 20);
  RunStats stats;
  const Results r = simulate(o, m, stats);
  // Exactly duration / dt rows and duration / output_interval frames, at t = k * output_interval, k = 1..N.
  ASSERT_EQ(r.steps(), 2000u);
  ASSERT_EQ(r.frames(), 100u);
  EXPECT_NEAR(r.frame_time_s.front(), 0.2, 1e-12);
  EXPECT_NEAR(r.frame_time_s.back(), 20.0, 1e-12);
  EXPECT_NEAR(r.get("time_s").back(), 20.0, 1e-12);
  for (const FieldSpec& f : series_fields()) EXPECT_EQ(r.get(f.name).size(), 2000u * f.cols) << f.name;
  EXPECT_EQ(r.floe_id.size(), 20u);
  EXPECT_EQ(r.state_body_id[0], 0);
  // Every frame holds the vessel and the 20 floes (replayed: a frame stores only the bodies that changed).
  FrameReplay replay(r, "results");
  for (size_t k = 0; k < r.frames(); ++k) {
    replay.seek(k);
    EXPECT_EQ(replay.rows().size(), 21u) << "frame " << k;
    EXPECT_EQ(r.state_body_id[replay.vessel_row()], 0);
  }

  const nlohmann::json s = summarize(o, m, r);
  std::printf("[measured] mean surge ice load %.1f kN, mean speed %.3f m/s, mean vessel contacts %.2f, "
              "mean sweeps %.1f, %.3f ms/step\n",
              s["mean_surge_ice_load_N"].get<double>() / 1e3, s["mean_vessel_speed_mps"].get<double>(), s["mean_vessel_contacts"].get<double>(),
              s["solver"]["mean_sweeps"].get<double>(), 1e3 * stats.wall_s / stats.steps);
  EXPECT_GT(s["mean_vessel_contacts"].get<double>(), 0.5);          // the transit does meet the ice
  EXPECT_NEAR(s["mean_vessel_speed_mps"].get<double>(), 2.0, 0.1);  // the speed controller holds 2 m/s
}

// The frames as stored (only the bodies new or changed since their last row) replay to the state of every alive
// body that a second run, stepping the world by hand and reading its whole state at each output time, sees: the
// same bodies and bit-identical poses at every frame. Checked on a transit with floes far off that fall asleep
// (they must stop costing rows) and on level ice, where wedges break off (parents must leave, pieces appear).
void expect_frames_replay_to_world_states(const SimulateOptions& o, const Model& m, size_t* stored_rows,
                                          size_t* dense_rows) {
  RunStats stats;
  const Results r = simulate(o, m, stats);
  FrameReplay replay(r, "results");
  World w(m);
  const long every = o.output_every();
  size_t frame = 0;
  *dense_rows = 0;
  for (long k = 1; k <= o.steps(); ++k) {
    w.step();
    if (k % every) continue;
    ASSERT_LT(frame, r.frames());
    replay.seek(frame);
    std::map<int32_t, int64_t> row_of;
    for (const int64_t row : replay.rows()) row_of[r.state_body_id[static_cast<size_t>(row)]] = row;
    const State& s = w.state();
    size_t alive = 0;
    for (size_t b = 0; b < w.model().bodies.size(); ++b) {
      const Body& body = w.model().bodies[b];
      if (body.kind == BodyKind::wall || !s.alive[b]) continue;
      ++alive;
      const int32_t id = body.kind == BodyKind::vessel ? 0 : body.id;
      const auto it = row_of.find(id);
      ASSERT_NE(it, row_of.end()) << "body " << id << " missing at frame " << frame;
      const double* x = &r.state_position_m[3 * static_cast<size_t>(it->second)];
      const double* q = &r.state_quaternion[4 * static_cast<size_t>(it->second)];
      EXPECT_TRUE(x[0] == s.position[b].x() && x[1] == s.position[b].y() && x[2] == s.position[b].z())
          << "body " << id << " frame " << frame;
      EXPECT_TRUE(q[0] == s.orientation[b].w() && q[1] == s.orientation[b].x() && q[2] == s.orientation[b].y() &&
                  q[3] == s.orientation[b].z())
          << "body " << id << " frame " << frame;
    }
    EXPECT_EQ(replay.rows().size(), alive) << "frame " << frame;
    *dense_rows += alive;
    ++frame;
  }
  EXPECT_EQ(frame, r.frames());
  *stored_rows = r.state_body_id.size();
}

TEST(SimTransit, StoredFramesReplayToEveryBodysStateAndSleepingFloesCostNoRows) {
  const HullModel hull = coarse_hull(8);
  SimulateOptions o;
  o.duration_s = 20;
  o.output_interval_s = 0.2;
  FloeField field = floe_block();
  for (int i = 0; i < 10; ++i) field.floes.push_back(rect_floe(100 + i, 60 + 10 * i, 150, 7, 7, 1.0));  // far off
  const Model m = build_model(field, &hull, o);
  size_t stored = 0, dense = 0;
  expect_frames_replay_to_world_states(o, m, &stored, &dense);
  std::printf("[measured] %zu state rows stored against %zu with every body in every frame\n", stored, dense);
  // The ten far floes settle and sleep within seconds: of their 1,000 frame-rows, most are not stored.
  EXPECT_LT(stored + 800, dense);
}

TEST(SimTransit, StoredFramesReplayThroughFractureOfLevelIce) {
  const SimulateOptions o = testing::level_ice_transit_options();
  const HullModel hull = coarse_hull();
  const Model m = build_model(FloeField{}, &hull, o);
  size_t stored = 0, dense = 0;
  expect_frames_replay_to_world_states(o, m, &stored, &dense);
  std::printf("[measured] level ice: %zu state rows stored against %zu dense\n", stored, dense);
  EXPECT_LT(stored, dense);  // the fixed tiles are stored once
}

// A flat-faced vessel (the 4 m x 30 m wall of testing::box_hull, kinematic: water.density 1e12 makes it 3.6e14 kg
// with the water switched off) at U = 2 m/s meets three floes abreast, staggered by 4 m, in vacuum (no water, no
// gravity; the floes 3 mm off the face's positions at the ends of steps, so that no contact starts with exactly
// coplanar faces). Crushed ice does not spring back, so every floe ends up moving with the face at U, and no force is
// needed after that: the hull has given the ice the momentum M U, M = rho_i x the floes' volume (by hand,
// 3 x 6 m x 6 m x 1 m). The mean surge ice load over the run, as the results summary reports it, is then -M U / T.
// (Floes in line would not do: the second impact kicks the first floe into a slow turn, and its centre then runs
// ahead of the face.) Tolerance 1e-4: the floes' final speeds are U to the solver's tolerance (1e-5 m/s against
// 2 m/s); the wall's own speed changes by M U / 3.6e14 kg ~ 1e-10.
// /states/in_contact against what the vessel felt: in a frame's step the ice load on the vessel is the sum of its
// contacts' impulses, so it is non-zero exactly when some floe pressed on the hull; and a floe marked in contact
// lies within the hull's reach (its centre within the hull's extent plus the floe's half-diagonal).
TEST(SimTransit, FloesMarkedInContactAreTheOnesTheHullPressesOn) {
  const HullModel hull = coarse_hull(8);
  SimulateOptions o;
  o.duration_s = 12;
  o.output_interval_s = 0.1;
  FloeField field = floe_block();
  field.floes.push_back(rect_floe(99, 80, 80, 7, 7, 1.0));  // far to port: never reached
  const Model m = build_model(field, &hull, o);
  RunStats stats;
  const Results r = simulate(o, m, stats);
  ASSERT_EQ(r.state_in_contact.size(), r.state_body_id.size());
  double hx = 0, hy = 0;  // hull half-extents (body frame)
  for (size_t i = 0; i < r.hull_vertices_m.size() / 3; ++i) {
    hx = std::max(hx, std::abs(r.hull_vertices_m[3 * i]));
    hy = std::max(hy, std::abs(r.hull_vertices_m[3 * i + 1]));
  }
  const std::vector<double>& t = r.get("time_s");
  const std::vector<double>& load = r.get("ice_load");
  size_t frames_in_contact = 0, step = 0;
  for (size_t k = 0; k < r.frames(); ++k) {
    while (step < t.size() && std::abs(t[step] - r.frame_time_s[k]) > 1e-9) ++step;
    ASSERT_LT(step, t.size()) << "frame " << k << " has no step";
    const bool loaded = load[6 * step] != 0 || load[6 * step + 1] != 0 || load[6 * step + 2] != 0;
    Vec3 vessel = Vec3::Zero();
    Quat q = Quat::Identity();
    int marked = 0;
    for (int64_t row = r.frame_offset[k]; row < r.frame_offset[k + 1]; ++row) {
      const double* p = &r.state_position_m[3 * row];
      if (r.state_body_id[row] == 0) {
        EXPECT_EQ(r.state_in_contact[row], 0) << "the vessel is never in contact with itself";
        vessel = Vec3(p[0], p[1], p[2]);
        const double* w = &r.state_quaternion[4 * row];
        q = Quat(w[0], w[1], w[2], w[3]);
        continue;
      }
      if (!r.state_in_contact[row]) continue;
      ++marked;
      EXPECT_NE(r.state_body_id[row], 99) << "the far floe was marked in contact at t = " << r.frame_time_s[k];
      const Vec3 local = q.conjugate() * (Vec3(p[0], p[1], p[2]) - vessel);
      EXPECT_LT(std::abs(local.x()), hx + 5.0) << "floe " << r.state_body_id[row] << " at t = " << r.frame_time_s[k];
      EXPECT_LT(std::abs(local.y()), hy + 5.0) << "floe " << r.state_body_id[row] << " at t = " << r.frame_time_s[k];
    }
    EXPECT_EQ(marked > 0, loaded) << "t = " << r.frame_time_s[k] << ": " << marked << " floes marked, ice load "
                                  << load[6 * step] << " N";
    frames_in_contact += marked > 0;
  }
  std::printf("[measured] %zu of %zu frames with a floe in contact\n", frames_in_contact, r.frames());
  EXPECT_GT(frames_in_contact, 5u) << "the bow reaches the block";
}

// The kinematic face of the two tests below: the box hull at 2 m/s with no thrust, in vacuum without gravity, 12 s.
SimulateOptions kinematic_face_options() {
  SimulateOptions o = testing::floe_options();
  o.water.enabled = false;
  o.water.gravity_mps2 = 0;
  o.water.density_kg_m3 = 1e12;
  o.vessel.x_m = 50;  // face at x = 52 m
  o.vessel.initial_speed_mps = 2.0;
  o.vessel.autopilot.enabled = false;
  o.vessel.propulsion.mode = "constant_thrust";
  o.vessel.propulsion.thrust_n = 0;
  o.duration_s = 12;
  o.steady_start_s = 0;
  o.output_interval_s = 1.0;
  return o;
}

// The interval of summary.json's mean (issue #37) on a series with a known answer: a real run's surge ice load
// replaced by a stationary AR(1), x_t = phi x_{t-1} + e_t with e_t of 100 kN standard deviation, whose mean is 0
// and whose squared standard error by batch means has the closed form E[SE^2] = (V(m) - V(n)) / (b - 1), V(k) the
// variance of the mean of k consecutive samples (the sweep's test, tests/render/gather_test.cpp). With phi = 0.9
// (a correlation time of 19 samples against batches of 250) the 95 % interval holds 0 in about 95 % of 200
// replicates (binomial spread 1.5 %) and its independence test flags about 5 %; with phi = 0.999 (1,999 samples)
// the interval holds 0 in about half and the test flags nearly all: the run is too short for its interval.
TEST(SimTransit, SummaryIntervalOfAnAr1LoadHasItsNominalCoverageAndFlagsARunTooShort) {
  SimulateOptions o = kinematic_face_options();
  o.duration_s = 50;  // 5,000 steps of 0.01 s, all of them steady
  o.steady_start_s = 0;
  FloeField field;
  field.floes.push_back(rect_floe(1, 500, 0, 5, 5, 1.0));  // far off: the run only makes a valid results set
  const HullModel hull = box_hull(4, 30, -3, 6);
  const Model m = build_model(field, &hull, o);
  RunStats stats;
  Results r = simulate(o, m, stats);
  const size_t n = r.steps(), b = 20, k = n / b;
  ASSERT_EQ(n, 5000u);
  auto variance_of_mean = [](double phi, double len) {  // unit innovations
    return 1.0 / (1.0 - phi * phi) / len *
           ((1 + phi) / (1 - phi) - 2 * phi * (1 - std::pow(phi, len)) / (len * (1 - phi) * (1 - phi)));
  };
  std::mt19937_64 rng(20261202);
  std::normal_distribution<double> normal(0.0, 1e5);
  for (const double phi : {0.9, 0.999}) {
    const int replicates = 200;
    int covered = 0, flagged = 0;
    double se2 = 0;
    for (int rep = 0; rep < replicates; ++rep) {
      std::vector<double>& load = r.series["ice_load"];
      double x = normal(rng) / std::sqrt(1 - phi * phi);  // stationary from the first sample
      for (size_t i = 0; i < n; ++i, x = phi * x + normal(rng)) load[6 * i] = x;
      const nlohmann::json s = summarize(o, m, r);
      const nlohmann::json& ci = s["mean_surge_ice_load_interval"];
      covered += ci["low_N"].get<double>() <= 0 && 0 <= ci["high_N"].get<double>();
      flagged += !ci["meaningful"].get<bool>();
      se2 += std::pow(ci["standard_error_N"].get<double>(), 2) / replicates;
      if (rep == 0) {
        EXPECT_EQ(ci["batches"], 20);
        EXPECT_NEAR(ci["batch_s"].get<double>(), 2.5, 1e-12);
        EXPECT_NEAR(ci["half_width_N"].get<double>(), 2.093024 * ci["standard_error_N"].get<double>(),
                    1e-6 * ci["half_width_N"].get<double>())
            << "Student t, 19 degrees of freedom";
      }
    }
    const double expected_se2 = 1e10 * (variance_of_mean(phi, k) - variance_of_mean(phi, n)) / (b - 1);
    std::printf("[measured] phi %.3f: interval held the true mean in %d of %d, flagged too short %d, mean SE^2 "
                "over the closed form %.3f\n",
                phi, covered, replicates, flagged, se2 / expected_se2);
    if (phi < 0.95) {
      EXPECT_NEAR(se2 / expected_se2, 1.0, 0.1);  // 200 replicates: 2.3 % spread
      EXPECT_NEAR(covered / 200.0, 0.95, 0.045);
      EXPECT_LE(flagged, 24) << "about 5 % false alarms";
    } else {
      EXPECT_LT(covered / 200.0, 0.8) << "batches shorter than the correlation time: the interval is too narrow";
      EXPECT_GE(flagged, 160) << "and the summary says so";
    }
  }
}

TEST(SimTransit, MeanLoadIsTheMomentumGivenToTheIce) {
  SimulateOptions o = kinematic_face_options();
  o.fracture.enabled = false;  // the contact law alone
  FloeField field;
  for (int i = 0; i < 3; ++i) field.floes.push_back(rect_floe(i + 1, 53.003 + 4 * i, -13 + 10 * i, 6, 6, 1.0));
  const HullModel hull = box_hull(4, 30, -3, 6);
  const Model m = build_model(field, &hull, o);
  RunStats stats;
  const Results r = simulate(o, m, stats);
  const double mean = summarize(o, m, r)["mean_surge_ice_load_N"].get<double>();
  const double M = o.ice.density_kg_m3 * 3 * 6 * 6 * 1.0, U = 2.0, T = o.duration_s;
  // Every floe's final speed: its advance over the last second (frames 1 s apart, bodies in the same order).
  const size_t last = r.frames() - 1;
  double worst_speed = 0;
  for (int64_t k = 0; k < r.frame_offset[last + 1] - r.frame_offset[last]; ++k) {
    const int64_t i = r.frame_offset[last] + k, j = r.frame_offset[last - 1] + k;
    ASSERT_EQ(r.state_body_id[i], r.state_body_id[j]);
    if (r.state_body_id[i] == 0) continue;
    worst_speed = std::max(worst_speed, std::abs(r.state_position_m[3 * i] - r.state_position_m[3 * j] - U * 1.0));
  }
  std::printf("[measured] mean surge ice load %.2f kN, -M U / T = %.2f kN (%+.2e); floe speeds within %.1e m/s of "
              "U\n",
              mean / 1e3, -M * U / T / 1e3, mean / (-M * U / T) - 1, worst_speed);
  EXPECT_NEAR(mean / (-M * U / T), 1.0, 1e-4);
  EXPECT_LT(worst_speed, 1e-4);
}

// The same kinematic face meeting brash (issue #33): three blocks 0.8 m x 0.8 m x 1 m, narrower than thick and under
// fracture.min_piece_area_m2, are bodies with rigid contacts (no crushing rows). Rigid contacts without restitution
// leave each block moving with the face at U, so the mean surge ice load is again -M U / T (M = rho_i x 3 x 0.64 m^3
// by hand), all of it recorded as the rigid part.
TEST(SimTransit, BrashMeanLoadIsTheMomentumItIsGivenAndIsTheRigidPart) {
  const SimulateOptions o = kinematic_face_options();
  FloeField field;
  for (int i = 0; i < 3; ++i) field.floes.push_back(rect_floe(i + 1, 53.003 + 4 * i, -13 + 10 * i, 0.8, 0.8, 1.0));
  const HullModel hull = box_hull(4, 30, -3, 6);
  const Model m = build_model(field, &hull, o);
  for (const Body& b : m.bodies) {
    if (b.kind == BodyKind::floe) {
      ASSERT_TRUE(b.brash) << "floe " << b.id;
    }
  }
  RunStats stats;
  const Results r = simulate(o, m, stats);
  const nlohmann::json s = summarize(o, m, r);
  const double mean = s["mean_surge_ice_load_N"].get<double>();
  const double M = o.ice.density_kg_m3 * 3 * 0.8 * 0.8 * 1.0, U = 2.0, T = o.duration_s;
  std::printf("[measured] brash: mean surge ice load %.4f kN, -M U / T = %.4f kN (%+.2e), rigid part %.4f kN\n",
              mean / 1e3, -M * U / T / 1e3, mean / (-M * U / T) - 1,
              s["mean_surge_ice_load_rigid_N"].get<double>() / 1e3);
  EXPECT_NEAR(mean / (-M * U / T), 1.0, 1e-3);
  EXPECT_DOUBLE_EQ(s["mean_surge_ice_load_rigid_N"].get<double>(), mean);
  EXPECT_EQ(s["mean_surge_ice_load_compliant_N"].get<double>(), 0.0);
}

// Momentum budget of the ice over a short transit of the generated hull through 20 floes in water (compliant
// contacts, fracture and sleeping off so that no floe leaves or is stopped by hand): the impulse the hull gives the
// ice (minus the recorded ice load on the vessel, integrated) equals the change of the ice's momentum minus the
// impulse of the water and gravity on it (the external wrenches of the forces stage). The floes' momentum is
// M v with M their mass tensor including the added mass the solver uses (a33 along each floe's normal), taken
// at the start of each step. Floe-floe contacts cancel in the sum. The budget holds exactly in the discrete scheme,
// so only round-off remains (1e-9 of the hull's impulse allows ~1e5 terms at 1e-14 each).
TEST(SimTransit, IceMomentumBudget) {
  const HullModel hull = coarse_hull(8);
  SimulateOptions o;
  o.fracture.enabled = false;
  o.sleep.enabled = false;
  const Model m = build_model(floe_block(56), &hull, o);
  World w(m);
  const double dt = o.time_step_s;
  Vec3 hull_impulse = Vec3::Zero(), momentum_change = Vec3::Zero(), external_impulse = Vec3::Zero();
  std::vector<Mat3> mass(m.bodies.size());
  std::vector<Vec3> v0(m.bodies.size());
  for (int i = 0; i < 1000; ++i) {
    for (size_t b = 1; b < m.bodies.size(); ++b) {
      const Mat3 R = w.state().orientation[b].toRotationMatrix();
      mass[b] = R * w.model().bodies[b].inv_mass_added.cwiseInverse().asDiagonal() * R.transpose();
      v0[b] = w.state().velocity[b];
    }
    w.step();
    hull_impulse -= dt * w.report().ice_load.force;
    for (size_t b = 1; b < m.bodies.size(); ++b) {
      momentum_change += mass[b] * (w.state().velocity[b] - v0[b]);
      external_impulse += dt * w.external_wrenches()[b].force;
    }
  }
  const Vec3 residual = momentum_change - external_impulse - hull_impulse;
  std::printf("[measured] ice momentum budget over 10 s: hull impulse (%.4g, %.4g, %.4g) N s, momentum change "
              "(%.4g, %.4g, %.4g), water + gravity (%.4g, %.4g, %.4g); residual %.2e of the hull's impulse\n",
              hull_impulse.x(), hull_impulse.y(), hull_impulse.z(), momentum_change.x(), momentum_change.y(),
              momentum_change.z(), external_impulse.x(), external_impulse.y(), external_impulse.z(),
              residual.norm() / hull_impulse.norm());
  EXPECT_GT(hull_impulse.x(), 1e5);  // the hull did push the ice (~100 kN s or more over 10 s)
  EXPECT_LT(residual.norm(), 1e-9 * hull_impulse.norm());
}

std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Writes a tiny case (floes right at the bow, so contacts start at once) and returns the config path.
std::filesystem::path write_case(const std::filesystem::path& dir, int threads) {
  FloeField field = floe_block(52);
  write_floes(dir / "floes.geojson", field);
  HullGeneratorOptions g;
  g.sections = 8;
  write_obj(dir / "hull.obj", generate_hull(g), "test hull");
  nlohmann::json cfg = {{"duration_s", 4.0}, {"steady_start_s", 1.0}, {"output_interval_s", 0.5},
                        {"threads", threads}, {"vessel", {{"x_m", 5.0}}}};
  std::ofstream(dir / "simulate.json") << cfg.dump(2);
  return dir / "simulate.json";
}

TEST(SimTransit, RerunsAreByteIdentical) {
  const auto dir = temp_dir("determinism");
  const auto cfg = write_case(dir, 1);
  run_simulate(dir / "floes.geojson", dir / "hull.obj", cfg, dir / "a");
  run_simulate(dir / "floes.geojson", dir / "hull.obj", cfg, dir / "b");
  const std::string a = file_bytes(dir / "a" / "results.h5"), b = file_bytes(dir / "b" / "results.h5");
  ASSERT_GT(a.size(), 1000u);
  std::printf("[measured] results.h5 sha256 %s (run 1) %s (run 2)\n", sha256_bytes(a).substr(0, 16).c_str(),
              sha256_bytes(b).substr(0, 16).c_str());
  EXPECT_TRUE(a == b);
  EXPECT_EQ(file_bytes(dir / "a" / "summary.json"), file_bytes(dir / "b" / "summary.json"));
  const Results ra = read_results(dir / "a" / "results.h5");
  double contacts = 0;
  for (double c : ra.get("vessel_contact_count")) contacts += c;
  EXPECT_GT(contacts, 0);  // the case does exercise contacts

  // Two threads give the same numbers (only the recorded configuration differs).
  const auto dir2 = temp_dir("determinism_threads");
  const auto cfg2 = write_case(dir2, 2);
  run_simulate(dir2 / "floes.geojson", dir2 / "hull.obj", cfg2, dir2 / "c");
  const Results rc = read_results(dir2 / "c" / "results.h5");
  // Bit for bit (memcmp, not ==: a series not measured is NaN, and NaN == NaN is false).
  auto same_bits = [](const std::vector<double>& x, const std::vector<double>& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(double)) == 0;
  };
  for (const FieldSpec& f : series_fields()) EXPECT_TRUE(same_bits(ra.get(f.name), rc.get(f.name))) << f.name;
  EXPECT_TRUE(ra.state_position_m == rc.state_position_m);
  EXPECT_TRUE(ra.state_quaternion == rc.state_quaternion);
}

}  // namespace
}  // namespace floesim::sim
