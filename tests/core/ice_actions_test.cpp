// The structure load formulas of the core (pipeline/ice_actions.h) against the worked examples of PHYSICS.md
// §8.1-8.2, reproduced by ../shared/docs/physics-scripts/structures_ridges.py: ISO 19906's crushing pressure (2019 and
// 2010 forms, and OpenFAST IceFloe's test log), Croasdale's five terms on IceFloe's test cone (its log to 5 digits)
// and on the brief's cone, Ralston's method on IceFloe's IEC test input; the 0.68 of Croasdale's breaking term as an
// elastic beam's break load (a second derivation); bad input refused with the field named. And §9, ridges:
// Dolgopolov's keel load (the worked example, its band, the surcharge bound and the trend in keel depth), its 2-D part
// against a quadrature of Rankine's passive pressure, the keel's bound on a ship's bow, the hydrostatic keel-to-sail
// ratio.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"
#include "pipeline/ice_actions.h"

using namespace floesim;

namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(IsoCrushing, TheBriefsWorkedPressuresAndIceFloesLog) {
  // §8.1: 2019 form, h = 1 m, w = 10 m: p_G = 2.059 MPa, F_G = 20.59 MN; h = 0.5 m, w = 5 m: 2.678 MPa, 6.70 MN.
  const IsoCrushing a = iso_global_crushing(1.0, 10.0);
  EXPECT_NEAR(a.pressure_pa, 2.059e6, 0.0005e6);
  EXPECT_NEAR(a.force_n, 20.59e6, 0.005e6);
  const IsoCrushing b = iso_global_crushing(0.5, 5.0);
  EXPECT_NEAR(b.pressure_pa, 2.678e6, 0.0005e6);
  EXPECT_NEAR(b.force_n, 6.70e6, 0.005e6);
  // 2010 form (no aspect-ratio term): 19.37 MN; IceFloe's test (h = 1 m, D = 5 m, C_R = 2.2 MPa): 8.50271E+06 N.
  EXPECT_NEAR(iso_global_crushing(1.0, 10.0, 2.8e6, IsoCrushingForm::iso2010).force_n, 19.37e6, 0.005e6);
  EXPECT_NEAR(iso_global_crushing(1.0, 5.0, 2.2e6, IsoCrushingForm::iso2010).force_n, 8.50271e6, 20.0);
  EXPECT_NE(error_of([] { iso_global_crushing(0, 10); }).find("thicknesses_m"), std::string::npos);
  EXPECT_NE(error_of([] { iso_global_crushing(1, -1); }).find("structure.waterline_width_m"), std::string::npos);
}

// IceFloe's Croasdale test cone (GLA_proto_flex_ISO.log, made with g = 9.81).
SlopingStructure icefloe_cone() {
  SlopingStructure s;
  s.waterline_width_m = 5;
  s.neck_width_m = 1.5;
  s.slope_deg = 60;
  return s;
}

StructureIce icefloe_ice() {
  StructureIce i;
  i.thickness_m = 1;
  i.flexural_strength_pa = 0.7e6;
  i.youngs_modulus_pa = 8e9;
  i.poisson_ratio = 0.3;
  i.ice_density_kg_m3 = 916.2;
  i.water_density_kg_m3 = 999.8;
  i.gravity_mps2 = 9.81;
  i.friction = 0.15;
  return i;
}

TEST(Croasdale, IceFloesTestConeToTheLogsDigits) {
  Rubble r;
  r.height_m = 3;
  r.porosity = 0.3;
  r.cohesion_pa = 0;
  r.pile_slope_deg = 40;
  r.friction_angle_deg = 45;
  r.ice_ice_friction = 0.05;
  const CroasdaleLoad c = croasdale(icefloe_cone(), icefloe_ice(), r);
  EXPECT_NEAR(c.characteristic_length_m, 16.53, 0.005);
  EXPECT_NEAR(c.effective_width_m, 45.79, 0.005);
  EXPECT_NEAR(c.xi, 2.543, 0.0005);
  // The log: Hp 2242, Hl 209678, Ht 42609, Hr 408262, Hb 1.84414e6, total 2.65997e6 N.
  EXPECT_NEAR(c.push_through_n, 2242, 1.0);
  EXPECT_NEAR(c.lift_n, 209678, 3e-5 * 209678);
  EXPECT_NEAR(c.turning_n, 42609, 1.0);
  EXPECT_NEAR(c.ride_up_n, 408262, 3e-5 * 408262);
  EXPECT_NEAR(c.breaking_n, 1.84414e6, 3e-5 * 1.84414e6);
  EXPECT_NEAR(c.horizontal_n, 2.65997e6, 3e-5 * 2.65997e6);
  EXPECT_NEAR(c.vertical_breaking_n, 725e3, 0.5e3);
}

TEST(Croasdale, TheBriefsConeClearAndWithRubble) {
  // w = 10 m, 45 deg, h = 1 m, sigma_f 0.5 MPa, E 5 GPa, mu 0.15, rho_i 900, rho_w 1025.
  SlopingStructure s;
  s.waterline_width_m = 10;
  s.slope_deg = 45;
  const StructureIce ice;  // the defaults are the brief's
  Rubble clear;
  clear.pile_slope_deg = 35;
  const CroasdaleLoad a = croasdale(s, ice, clear);
  EXPECT_NEAR(a.breaking_n, 797.6e3, 0.05e3);
  EXPECT_NEAR(a.turning_n, 155.8e3, 0.05e3);
  EXPECT_NEAR(a.horizontal_n, 987.6e3, 0.05e3);
  EXPECT_NEAR(a.vertical_breaking_n, 589.5e3, 0.05e3);
  EXPECT_EQ(a.ride_up_n, 0.0);
  Rubble pile = clear;
  pile.height_m = 3;
  pile.ice_ice_friction = 0.1;
  const CroasdaleLoad b = croasdale(s, ice, pile);
  EXPECT_NEAR(b.ride_up_n, 532.4e3, 0.05e3);
  EXPECT_NEAR(b.lift_n, 82.1e3, 0.05e3);
  EXPECT_NEAR(b.push_through_n, 3.6e3, 0.05e3);
  EXPECT_NEAR(b.horizontal_n, 1.63e6, 0.005e6);
  // A vertical face of the same width takes 20.6 MN (§8.1): the cone carries 5-8 % of it.
  const double ratio = b.horizontal_n / iso_global_crushing(1.0, 10.0).force_n;
  EXPECT_GT(a.horizontal_n / iso_global_crushing(1.0, 10.0).force_n, 0.04);
  EXPECT_LT(ratio, 0.08);
}

TEST(Croasdale, TheBreakingTermIsAnElasticBeamsBreakLoadTurnedByXi) {
  // §8.2.2: a semi-infinite beam on a Winkler foundation under an end load P per width has M_max = l P e^(-pi/4),
  // so it breaks at P = (e^(pi/4)/6) sigma_f h^2 / l with l = (E h^3 / (12 rho_w g))^(1/4) (no Poisson factor);
  // H_B = xi P L_eff to the 0.68 Croasdale rounds e^(pi/4) 12^(1/4) / 6 = 0.6804 to.
  SlopingStructure s;
  const StructureIce ice;
  const CroasdaleLoad c = croasdale(s, ice, Rubble{});
  const double l = std::pow(ice.youngs_modulus_pa * std::pow(ice.thickness_m, 3) /
                                (12 * ice.water_density_kg_m3 * ice.gravity_mps2),
                            0.25);
  const double p = std::exp(kPi / 4) / 6 * ice.flexural_strength_pa * ice.thickness_m * ice.thickness_m / l;
  EXPECT_NEAR(c.breaking_n / (c.xi * p * c.effective_width_m), 0.68 / 0.6804, 1e-4);
}

TEST(Ralston, IceFloesIecTestCone) {
  // IceFloe's IEC input: w 5 m, w_T 1.5 m, h 1 m, h_R 2.5 m, sigma_f 0.7 MPa, 60 deg, mu 0.15, rho_i 916.2, g 9.80665:
  // G = 0.0802, x = 1.7915, g_r = 2.217, H_B = 3.077 MN, W = 255.5 kN, H_R = 667 kN, F = 3.745 MN.
  StructureIce ice = icefloe_ice();
  ice.gravity_mps2 = 9.80665;
  Rubble r;
  r.ride_up_thickness_m = 2.5;
  const RalstonLoad o = ralston(icefloe_cone(), ice, r);
  EXPECT_NEAR(o.g_ratio, 0.0802, 0.00005);
  EXPECT_NEAR(o.x, 1.7915, 0.00005);
  EXPECT_NEAR(o.g_r, 2.217, 0.0005);
  EXPECT_NEAR(o.breaking_n, 3.077e6, 0.0005e6);
  EXPECT_NEAR(o.ride_up_weight_n, 255.5e3, 0.05e3);
  EXPECT_NEAR(o.ride_up_n, 667e3, 0.5e3);
  EXPECT_NEAR(o.horizontal_n, 3.7445e6, 100);  // the script's 5 digits (A&S K and E there, exact here: 1e-5 apart)
  // The brief's cone without ride-up: H_B = 1406 kN against Croasdale's 798 kN.
  SlopingStructure s;
  s.waterline_width_m = 10;
  s.neck_width_m = 5;
  EXPECT_NEAR(ralston(s, StructureIce{}, Rubble{}).breaking_n, 1406e3, 0.5e3);
}

TEST(SlopingStructures, BadInputNamesTheField) {
  const StructureIce ice;
  SlopingStructure steep;
  steep.slope_deg = 80;
  EXPECT_NE(error_of([&] { croasdale(steep, ice, Rubble{}); }).find("structure.slope_deg"), std::string::npos);
  StructureIce slippery;
  slippery.friction = 1.2;  // above cot 45 deg = 1
  EXPECT_NE(error_of([&] { croasdale(SlopingStructure{}, slippery, Rubble{}); }).find("ice.mu_ice_structure"),
            std::string::npos);
  Rubble steep_pile;
  steep_pile.pile_slope_deg = 50;  // steeper than the 45 deg cone
  EXPECT_NE(error_of([&] { croasdale(SlopingStructure{}, ice, steep_pile); }).find("rubble.pile_slope_deg"),
            std::string::npos);
  SlopingStructure neck;
  neck.neck_width_m = 12;  // wider than the 10 m waterline
  EXPECT_NE(error_of([&] { ralston(neck, ice, Rubble{}); }).find("structure.neck_width_m"), std::string::npos);
}

// PHYSICS.md §9.3's worked example (structures_ridges.py "9.2 keel load"): h_k = 8 m, w = 10 m, phi = 30 deg,
// c = 5 kPa, e = 0.3, rho_w = 1025, rho_i = 900.
TEST(RidgeKeel, DolgopolovsWorkedExampleAndItsSurchargeBound) {
  const StructureIce ice;  // rho_i 900, rho_w 1025, g 9.81
  RidgeKeel k;             // 8 m, e 0.3, c 5 kPa, phi 30 deg
  const KeelLoad r = dolgopolov_keel_load(k, 10.0, ice);
  EXPECT_NEAR(r.unit_weight_npm3, 858.4, 0.05);
  EXPECT_NEAR(r.mu_phi, std::sqrt(3.0), 1e-12);  // tan 60 deg
  EXPECT_NEAR(r.force_n / 1e6, 2.504, 0.0005);
  EXPECT_NEAR(r.friction_n / 1e6, 0.934, 0.0005);
  EXPECT_NEAR(r.cohesion_n / 1e6, 1.570, 0.0005);
  EXPECT_NEAR(r.surcharge_bound_n / 1e6, 5.39, 0.005);  // h_k + w/2 = 13 m
  // The parameter band of §9.3: phi 25-45 deg, c 2-10 kPa.
  double lo = 1e300, hi = 0;
  for (double phi : {25.0, 45.0})
    for (double c : {2e3, 10e3}) {
      RidgeKeel b = k;
      b.friction_angle_deg = phi, b.cohesion_pa = c;
      const double f = dolgopolov_keel_load(b, 10.0, ice).force_n;
      lo = std::min(lo, f), hi = std::max(hi, f);
    }
  EXPECT_NEAR(lo / 1e6, 1.34, 0.005);
  EXPECT_NEAR(hi / 1e6, 6.19, 0.005);
}

TEST(RidgeKeel, TheTrendInKeelDepthWithAndWithoutCohesion) {
  // §9.3's table (w = 10 m, phi = 30 deg): F_K in MN at h_k = 2, 4, 6, 8, 12 m, with c = 5 kPa and with c = 0.
  const double depth[] = {2, 4, 6, 8, 12};
  const double with_c[] = {0.411, 0.959, 1.653, 2.504, 4.719};
  const double without_c[] = {0.053, 0.220, 0.510, 0.934, 2.225};
  const StructureIce ice;
  for (int i = 0; i < 5; ++i) {
    RidgeKeel k;
    k.depth_m = depth[i];
    EXPECT_NEAR(dolgopolov_keel_load(k, 10.0, ice).force_n / 1e6, with_c[i], 0.0005) << "h_k " << depth[i];
    k.cohesion_pa = 0;
    EXPECT_NEAR(dolgopolov_keel_load(k, 10.0, ice).force_n / 1e6, without_c[i], 0.0005) << "h_k " << depth[i];
  }
}

TEST(RidgeKeel, ThePlaneStrainPartIsRankinesPassivePressureIntegratedOverTheKeel) {
  // A second algorithm: F_K / (1 + h_k / 6w) against w times the integral, by Simpson's rule, of the passive pressure
  // sigma_h = K_p gamma_e zeta + 2 c sqrt(K_p) over the keel's depth (zeta from its bottom).
  const StructureIce ice;
  for (double phi : {25.0, 35.0, 45.0})
    for (double c : {0.0, 3e3, 8e3}) {
      RidgeKeel k;
      k.depth_m = 6.5, k.friction_angle_deg = phi, k.cohesion_pa = c, k.porosity = 0.28;
      const double w = 12.0;
      const KeelLoad r = dolgopolov_keel_load(k, w, ice);
      const double kp = std::pow(std::tan((45 + phi / 2) * kPi / 180), 2);
      const double gamma = (1 - k.porosity) * (ice.water_density_kg_m3 - ice.ice_density_kg_m3) * ice.gravity_mps2;
      auto sigma = [&](double z) { return kp * gamma * z + 2 * c * std::sqrt(kp); };
      const int n = 64;
      double sum = sigma(0) + sigma(k.depth_m);
      for (int i = 1; i < n; ++i) sum += (i % 2 ? 4 : 2) * sigma(k.depth_m * i / n);
      const double plane = w * sum * k.depth_m / (3 * n);
      EXPECT_NEAR(r.force_n / (1 + k.depth_m / (6 * w)), plane, 1e-9 * plane) << "phi " << phi << " c " << c;
    }
}

TEST(RidgeKeel, TheBoundOnAShipsBowAndTheFullKeel) {
  // §9.4: B = 20 m, T = 7 m, h_c = 1.5 m, keel draft H_k = 8 m, phi = 30 deg, c = 5 kPa: Rankine over the draught
  // 2.97 MN; Dolgopolov's full keel with w = B and h_k = H_k - h_c = 6.5 m, 3.52 MN.
  const StructureIce ice;
  RidgeKeel k;
  EXPECT_NEAR(keel_ship_bound_n(k, 20, 7, 1.5, ice) / 1e6, 2.97, 0.005);
  RidgeKeel full = k;
  full.depth_m = 6.5;
  EXPECT_NEAR(dolgopolov_keel_load(full, 20, ice).force_n / 1e6, 3.52, 0.005);
  // A keel that does not reach below the consolidated layer within the draught: no keel load.
  RidgeKeel shallow = k;
  shallow.depth_m = 1.2;
  EXPECT_EQ(keel_ship_bound_n(shallow, 20, 7, 1.5, ice), 0.0);
  // It scales with the beam (cohesion and friction alike).
  EXPECT_NEAR(keel_ship_bound_n(k, 40, 7, 1.5, ice), 2 * keel_ship_bound_n(k, 20, 7, 1.5, ice), 1e-6);
}

TEST(RidgeKeel, HydrostaticKeelToSailRatio) {
  StructureIce ice;
  EXPECT_NEAR(keel_sail_area_ratio(ice), 7.20, 0.005);
  ice.ice_density_kg_m3 = 917;
  EXPECT_NEAR(keel_sail_area_ratio(ice), 8.49, 0.005);
}

TEST(RidgeKeel, BadInputNamesTheField) {
  const StructureIce ice;
  RidgeKeel k;
  k.porosity = 1.2;
  EXPECT_NE(error_of([&] { dolgopolov_keel_load(k, 10, ice); }).find("ridge.porosity"), std::string::npos);
  k = RidgeKeel{};
  k.depth_m = 0;
  EXPECT_NE(error_of([&] { dolgopolov_keel_load(k, 10, ice); }).find("ridge.keel_depth_m"), std::string::npos);
  k = RidgeKeel{};
  k.friction_angle_deg = 95;
  EXPECT_NE(error_of([&] { keel_ship_bound_n(k, 20, 7, 1.5, ice); }).find("ridge.friction_angle_deg"),
            std::string::npos);
  StructureIce sinking;
  sinking.ice_density_kg_m3 = 1100;
  EXPECT_NE(error_of([&] { keel_sail_area_ratio(sinking); }).find("ice.density_kg_m3"), std::string::npos);
  EXPECT_NE(error_of([&] { dolgopolov_keel_load(RidgeKeel{}, -1, ice); }).find("structure.waterline_width_m"),
            std::string::npos);
}

}  // namespace
