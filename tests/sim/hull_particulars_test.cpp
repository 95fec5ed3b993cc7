// Hull angles and lengths for the ice-resistance formulas (issue #10 item 2; sim/vessel/particulars.h), measured from
// meshes whose answers are known independently of the measuring code: a box barge; the parametric icebreaker, whose
// stem angle is an option and whose entrance angle is 90 deg (its spoon bow is square across at B/4) or, with the
// wedge bow, the option entrance_angle_deg; and the two real hulls of ../shared/data/hulls against their published
// main dimensions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"
#include "sim/vessel/hull.h"
#include "sim/vessel/particulars.h"
#include "tests/sim/obj_faces.h"
#include "tests/sim/sim_fixtures.h"

#ifndef FLOESIM_SHARED_DATA_DIR
#error "FLOESIM_SHARED_DATA_DIR must be defined by the build"
#endif

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;
using testing::expect_error;
using testing::hull_file;
using testing::temp_dir;

double rad(double d) { return d * kPi / 180.0; }
double deg(double r) { return r * 180.0 / kPi; }

TriMesh merged(const std::vector<TriMesh>& parts) {
  TriMesh m;
  for (const TriMesh& p : parts) {
    const int off = static_cast<int>(m.vertices.size());
    m.vertices.insert(m.vertices.end(), p.vertices.begin(), p.vertices.end());
    for (auto t : p.triangles) m.triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
  }
  return m;
}

HullParticulars measure(const HullGeneratorOptions& o) {
  return measure_particulars(merged(generate_hull(o)), "generated hull");
}

void print(const char* label, const HullParticulars& p) {
  std::printf("[measured] %s: L %.4f m, B %.4f m, T %.4f m, phi %.3f deg, alpha %.3f deg, psi %.3f deg, phi_B4 %.3f deg, "
              "psi_B4 %.3f deg, L_par %.4f m (x %.3f .. %.3f), L_bow %.4f m\n",
              label, p.length_m, p.beam_m, p.draught_m, p.stem_angle_deg, p.entrance_angle_deg, p.normal_flare_deg,
              p.bow_angle_b4_deg, p.normal_flare_b4_deg, p.parallel_midbody_m, p.x_parallel_aft_m,
              p.x_parallel_fwd_m, p.bow_length_m);
}

TEST(HullParticulars, BoxBargeIsSquareEverywhere) {
  // A box 40 x 10 m, keel at -3 m, 8 m deep: a vertical stem (phi = psi = 90 deg), a waterline square across
  // (alpha = 90 deg), all of it parallel midbody, no bow.
  const std::vector<Vec2> rect = {Vec2(-20, -5), Vec2(20, -5), Vec2(20, 5), Vec2(-20, 5)};
  const HullParticulars p = measure_particulars(extrude_polygon(rect, -3.0, 8.0), "box");
  print("box barge", p);
  EXPECT_NEAR(p.length_m, 40.0, 1e-12);
  EXPECT_NEAR(p.beam_m, 10.0, 1e-12);
  EXPECT_NEAR(p.draught_m, 3.0, 1e-12);
  EXPECT_NEAR(p.stem_angle_deg, 90.0, 1e-9);
  EXPECT_NEAR(p.entrance_angle_deg, 90.0, 1e-9);
  EXPECT_NEAR(p.normal_flare_deg, 90.0, 1e-9);
  EXPECT_NEAR(p.bow_angle_b4_deg, 90.0, 1e-9);
  EXPECT_NEAR(p.parallel_midbody_m, 40.0, 1e-9);
  EXPECT_NEAR(p.bow_length_m, 0.0, 1e-9);
}

// Tolerance on the generated hull's angles. Its coordinates lie on a 2^-10 m grid (generate.cpp, grid()): each is
// off by at most 2^-11 m = 0.49 mm. The stem angle is fitted over T/4 = 2 m of height, the entrance angle over B/20 =
// 1.55 m of breadth; an error of 2 x 0.49 mm across such a base turns a line by at most 1e-3 / 1.55 rad = 0.037 deg.
// Between stations the surfaces fitted are planes (the spoon, the wedge), which the convex parts reproduce exactly.
constexpr double kAngleTolDeg = 0.05;

TEST(HullParticulars, GeneratedSpoonBowGivesBackItsStemAngle) {
  // The spoon bow is flat across: its stem on the centreline and its buttocks rise at the stem angle, phi_B4 = phi.
  for (double phi : {15.0, 22.0, 30.0, 45.0, 60.0}) {
    HullGeneratorOptions o;
    o.stem_angle_deg = phi;
    const HullParticulars p = measure(o);
    print(("spoon bow, stem " + std::to_string(phi)).c_str(), p);
    EXPECT_NEAR(p.stem_angle_deg, phi, kAngleTolDeg) << phi;
    EXPECT_NEAR(p.bow_angle_b4_deg, phi, kAngleTolDeg) << phi;
    // Main dimensions, closed form: the waterline runs from the immersed transom (x = -L/2) to where the spoon,
    // rising at phi from the forefoot x_fwd - D/tan(phi), crosses z = 0, (D - T)/tan(phi) aft of the stem head;
    // the widest waterline is the reamers' (a station); the keel is flat at mid waterline (to 1 cm: the mesh joins
    // stations by chords, and at phi = 15 deg mid waterline falls in the first station of the stern's rising run).
    EXPECT_NEAR(p.length_m, o.length_m - (o.depth_m - o.draught_m) / std::tan(rad(phi)), 2e-3) << phi;
    EXPECT_NEAR(p.beam_m, o.reamer_beam_m, 2e-3) << phi;
    EXPECT_NEAR(p.draught_m, o.draught_m, 0.01) << phi;
  }
}

TEST(HullParticulars, OdenLikeHullIsSquareAcrossAtQuarterBeam) {
  // The default (Oden-like) hull: phi = 22 deg. Its waterline ends in the flat spoon bottom, square across: the
  // stations bracketing the spoon's waterline crossing (x = 39.02 m) are at x = 35.92 m (bottom at z = -1.26 m, flat
  // to |y| = 11.82 m before the bilge) and x = 39.51 m (z = +0.20 m, flat to |y| = 8.80 m); between them the bottom
  // is one plane (two parallel horizontal edges), so z = 0 cuts it along a line square across for |y| up to
  // ~9.2 m, beyond B/4 + B/40 = 8.53 m. Hence alpha = 90 deg and psi = arctan(tan 22 / sin 90) = 22 deg.
  const HullGeneratorOptions o;
  const HullParticulars p = measure(o);
  print("Oden-like (default)", p);
  EXPECT_NEAR(p.stem_angle_deg, 22.0, kAngleTolDeg);
  EXPECT_NEAR(p.entrance_angle_deg, 90.0, kAngleTolDeg);
  EXPECT_NEAR(p.normal_flare_deg, 22.0, kAngleTolDeg);
  EXPECT_NEAR(p.normal_flare_b4_deg, 22.0, kAngleTolDeg);

  // Parallel midbody and bow, bracketed by the generator's waterline in closed form (generate.cpp's HullShape: the
  // half-breadth rises from beam/2 to reamer_beam/2 as 0.5 - 0.5 cos(pi s) over the shoulder, 0.12 L long, and
  // falls ahead of the reamers as the ellipse tip + (r - tip) sqrt(1 - u^2), tip = 0.30 r, to the stem head). Both
  // curves are concave near the reamers and the mesh joins stations (spaced L/30) by straight lines, which lie
  // below them: the measured stretch lies inside the continuous one and reaches to within a station spacing of
  // each of its ends.
  const double b = 0.5 * o.beam_m, r = 0.5 * o.reamer_beam_m, tip = 0.30 * r, need = 0.99 * r;
  const double x_fwd = 0.5 * o.length_m, x_reamer = x_fwd - o.depth_m / std::tan(rad(o.stem_angle_deg));
  const double x_shoulder = x_reamer - 0.12 * o.length_m;
  const double s_star = std::acos(1.0 - 2.0 * (need - b) / (r - b)) / kPi;  // 0.5 - 0.5 cos(pi s) = (need-b)/(r-b)
  const double u_star = std::sqrt(1.0 - std::pow((need - tip) / (r - tip), 2));
  const double x_a = x_shoulder + s_star * (x_reamer - x_shoulder), x_f = x_reamer + u_star * (x_fwd - x_reamer);
  const double spacing = o.length_m / o.sections;
  const double x_stem = x_fwd - (o.depth_m - o.draught_m) / std::tan(rad(o.stem_angle_deg));
  std::printf("continuous parallel midbody %.3f .. %.3f m (%.3f m), station spacing %.3f m\n", x_a, x_f, x_f - x_a,
              spacing);
  EXPECT_GE(p.x_parallel_aft_m, x_a - 1e-3);
  EXPECT_LE(p.x_parallel_aft_m, x_a + spacing);
  EXPECT_LE(p.x_parallel_fwd_m, x_f + 1e-3);
  EXPECT_GE(p.x_parallel_fwd_m, x_f - spacing);
  EXPECT_NEAR(p.bow_length_m, x_stem - p.x_parallel_fwd_m, 2e-3);  // the stem on the 2^-10 m grid
  EXPECT_NEAR(p.parallel_midbody_m, p.x_parallel_fwd_m - p.x_parallel_aft_m, 1e-9);
}

TEST(HullParticulars, GeneratedWedgeBowGivesBackItsEntranceAngleAndFlare) {
  // entrance_angle_deg < 90 cuts the bow by the planes |y| = (x_s(z) - x) tan(alpha) through the stem line x_s(z):
  // at B/4 the waterline makes alpha with the centreline, the buttocks rise at phi (the plane's slope along x is
  // that of the stem line), and the plane's slope across its waterline is psi = arctan(tan phi / sin alpha)
  // (Lindqvist's normal flare, exact for a plane). In all four cases the planes reach past B/4 + B/40 at the
  // waterline and below it to T/4 (checked by hand: the uncut half-breadth there is over 14 m).
  struct Case {
    double phi, alpha;
  };
  for (const Case c : {Case{22, 30}, Case{30, 45}, Case{22, 60}, Case{45, 30}}) {
    HullGeneratorOptions o;
    o.stem_angle_deg = c.phi;
    o.entrance_angle_deg = c.alpha;
    const HullParticulars p = measure(o);
    const std::string label = "wedge bow, stem " + std::to_string(c.phi) + ", entrance " + std::to_string(c.alpha);
    print(label.c_str(), p);
    const double psi = deg(std::atan(std::tan(rad(c.phi)) / std::sin(rad(c.alpha))));
    EXPECT_NEAR(p.stem_angle_deg, c.phi, kAngleTolDeg) << label;
    EXPECT_NEAR(p.entrance_angle_deg, c.alpha, kAngleTolDeg) << label;
    EXPECT_NEAR(p.bow_angle_b4_deg, c.phi, kAngleTolDeg) << label;
    EXPECT_NEAR(p.normal_flare_deg, psi, kAngleTolDeg) << label;
    EXPECT_NEAR(p.normal_flare_b4_deg, psi, kAngleTolDeg) << label;
    // The cut keeps the stem line, so the waterline still ends where the spoon crosses z = 0.
    EXPECT_NEAR(p.length_m, o.length_m - (o.depth_m - o.draught_m) / std::tan(rad(c.phi)), 2e-3) << label;
    // A convex, closed hull still: every part convex, the whole displacing less than the spoon bow it was cut from.
    const auto parts = generate_hull(o);
    for (const TriMesh& part : parts) EXPECT_TRUE(is_convex(part, 1e-6)) << label;
    HullGeneratorOptions spoon = o;
    spoon.entrance_angle_deg = 90;
    EXPECT_LT(hydrostatics(parts).volume_m3, hydrostatics(generate_hull(spoon)).volume_m3) << label;
  }
  // Out of range: an error naming the key.
  HullGeneratorOptions bad;
  bad.entrance_angle_deg = 5;
  expect_error([&] { generate_hull(bad); }, {"entrance_angle_deg"});
}

TEST(HullParticulars, GeneratedHullSidecarCarriesThemAndAnImportedCopyAgrees) {
  // floesim-hull writes the particulars into hull.json; the same hull read back as a user's mesh (its OBJ through
  // the loader) measures the same: the loader path and the generator path agree.
  const fs::path dir = temp_dir("hull_particulars_sidecar");
  HullGeneratorOptions o;
  o.entrance_angle_deg = 40;
  write_generated_hull(o, dir / "gen" / "hull.obj", "");
  const nlohmann::json gen = nlohmann::json::parse(std::ifstream(dir / "gen" / "hull.json"));
  ASSERT_TRUE(gen["particulars"].is_object());
  EXPECT_NEAR(gen["particulars"]["entrance_angle_deg"].get<double>(), 40.0, kAngleTolDeg);
  EXPECT_NEAR(gen["particulars"]["stem_angle_deg"].get<double>(), 22.0, kAngleTolDeg);
  EXPECT_TRUE(gen["particulars"]["definitions"].contains("entrance_angle_deg"));
  HullImportOptions imp;
  imp.file = (dir / "gen" / "hull.obj").string();
  write_imported_hull(imp, dir / "imp" / "hull.obj", "");
  const nlohmann::json got = nlohmann::json::parse(std::ifstream(dir / "imp" / "hull.json"));
  for (const char* k : {"length_m", "beam_m", "draught_m", "stem_angle_deg", "entrance_angle_deg",
                        "parallel_midbody_m", "bow_length_m", "normal_flare_deg"})
    EXPECT_NEAR(got["particulars"][k].get<double>(), gen["particulars"][k].get<double>(), 1e-6) << k;
  fs::remove_all(dir);
}

TEST(HullParticulars, NoWaterlineIsAnErrorNamingTheHull) {
  const std::vector<Vec2> rect = {Vec2(-20, -5), Vec2(20, -5), Vec2(20, 5), Vec2(-20, 5)};
  expect_error([&] { measure_particulars(extrude_polygon(rect, 1.0, 8.0), "my floating box"); },
               {"my floating box", "waterline"});
}

// ---- the real hulls ----------------------------------------------------------------------------------------------

struct Published {
  const char* file;
  double lpp_m, lwl_m, bwl_m, t_m;  // model scale
};
// KCS, scale 1:31.6 (SIMMAN 2008): Lpp 230.0 m, Lwl 232.5 m, Bwl 32.2 m, T 10.8 m full scale.
const Published kKcs{"KCS_model_scale_L7.2786m.obj", 7.2786, 232.5 / 31.6, 32.2 / 31.6, 0.3418};
// DTMB 5415 (INSEAN model, SIMMAN 2014 table): Lpp 5.719 m, Lwl 5.726 m, Bwl 0.768 m, T 0.248 m.
const Published kDtmb{"DTMB5415_model_scale_L5.72m.obj", 5.719, 5.726, 0.768, 0.248};

void check_real(const Published& pub) {
  const fs::path dir = temp_dir(std::string("hull_particulars_") + pub.file);
  HullImportOptions o;
  o.file = hull_file(pub.file).string();
  o.placement.bow_direction = "-x";  // both files lie with their bow towards -x, waterline at z = 0
  write_imported_hull(o, dir / "hull.obj", "");
  const nlohmann::json side = nlohmann::json::parse(std::ifstream(dir / "hull.json"));
  ASSERT_TRUE(side["particulars"].is_object()) << side.dump(2);
  const nlohmann::json& p = side["particulars"];
  auto get = [&](const char* k) { return p[k].get<double>(); };
  std::printf("[measured] %s: L %.4f m (Lwl %.4f, Lpp %.4f), B %.4f m (%.4f), T %.5f m (%.4f); phi %.2f deg, "
              "alpha %.2f deg, psi %.2f deg, phi_B4 %.2f deg, psi_B4 %.2f deg, L_par %.3f m, L_bow %.3f m\n",
              pub.file, get("length_m"), pub.lwl_m, pub.lpp_m, get("beam_m"), pub.bwl_m, get("draught_m"), pub.t_m,
              get("stem_angle_deg"), get("entrance_angle_deg"), get("normal_flare_deg"), get("bow_angle_b4_deg"),
              get("normal_flare_b4_deg"), get("parallel_midbody_m"), get("bow_length_m"));
  // L is the waterline length: the published L_wl within 0.3 %; so above L_pp by L_wl - L_pp (+1.1 % for KCS, whose
  // stern overhangs the aft perpendicular; +0.1 % for DTMB 5415) within the same 0.3 %.
  EXPECT_NEAR(get("length_m"), pub.lwl_m, 0.003 * pub.lwl_m);
  EXPECT_NEAR(get("length_m") - pub.lpp_m, pub.lwl_m - pub.lpp_m, 0.003 * pub.lpp_m);
  // B and T, published to 3-4 digits at model scale: within 0.3 %.
  EXPECT_NEAR(get("beam_m"), pub.bwl_m, 0.003 * pub.bwl_m);
  EXPECT_NEAR(get("draught_m"), pub.t_m, 0.003 * pub.t_m);
  // Fine merchant and naval entrances: a sharp waterline (alpha well under 45 deg), parallel midbody and bow inside
  // the length.
  EXPECT_GT(get("entrance_angle_deg"), 5.0);
  EXPECT_LT(get("entrance_angle_deg"), 45.0);
  EXPECT_GE(get("parallel_midbody_m"), 0.0);
  EXPECT_GT(get("bow_length_m"), 0.0);
  EXPECT_LT(get("parallel_midbody_m") + get("bow_length_m"), get("length_m"));
  fs::remove_all(dir);
}

TEST(HullParticulars, KcsAgainstPublishedDimensions) {
  check_real(kKcs);
  // The KCS rudder pierces the water under the counter, behind the hull's own waterline: it is left out (the
  // waterline with it, the sidecar's convex-parts figure, is 7.42 m).
}

TEST(HullParticulars, Dtmb5415AgainstPublishedDimensions) { check_real(kDtmb); }

}  // namespace
}  // namespace floesim::sim
