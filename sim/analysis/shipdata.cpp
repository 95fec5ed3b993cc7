#include "sim/analysis/shipdata.h"

#include <cmath>
#include <iomanip>
#include <random>
#include <sstream>

#include "pipeline/geometry2d.h"
#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/provenance.h"
#include "sim/engine/model.h"
#include "sim/simulate/options.h"

namespace fs = std::filesystem;

namespace floesim::sim {

namespace {

double number_at(const nlohmann::json& j, const char* section, const char* key) {
  FLOESIM_REQUIRE(j.contains(section) && j[section].is_object() && j[section].contains(key) &&
                      j[section][key].is_number(),
                  "summary.json has no number ", section, ".", key,
                  ": give the summary.json that floesim-simulate wrote with these results");
  return j[section][key].get<double>();
}

// The identify config that matches the simulated ship (model.cpp, forces.cpp): M = rigid body + the added mass the
// simulator puts on surge, sway and yaw; the same ITTC-57 curve; the same wind coefficients.
IdentifyOptions matching_config(const SimulateOptions& s, const nlohmann::json& summary) {
  IdentifyOptions c;
  const double mass = number_at(summary, "vessel", "mass_kg");
  const auto& rg = summary["vessel"]["radii_of_gyration_m"];
  FLOESIM_REQUIRE(rg.is_array() && rg.size() == 3, "summary.json has no vessel.radii_of_gyration_m [3]");
  // The radii are those of the inertia's diagonal (also when vessel.inertia_kg_m2 is given), so I_zz = m r_z^2.
  const double izz = mass * rg[2].get<double>() * rg[2].get<double>();
  const bool water = s.water.enabled;
  c.mass.surge_kg = mass * (1 + (water ? s.vessel.surge_added_mass_ratio : 0.0));
  c.mass.sway_kg = mass * (1 + (water ? s.vessel.sway_added_mass_ratio : 0.0));
  c.mass.yaw_kg_m2 = izz * (1 + (water ? s.vessel.yaw_added_inertia_ratio : 0.0));
  if (water) {
    c.resistance.model = "ittc57";
    c.resistance.length_wl_m = number_at(summary, "vessel", "length_wl_m");
    c.resistance.wetted_surface_m2 = number_at(summary, "vessel", "wetted_surface_m2");
    c.resistance.form_factor_k = s.vessel.form_factor_k;
    c.resistance.roughness_ca = s.vessel.roughness_ca;
    c.resistance.water_density_kg_m3 = s.water.density_kg_m3;
    c.resistance.kinematic_viscosity_m2ps = s.water.kinematic_viscosity_m2ps;
  } else {
    c.resistance.model = "quadratic";  // no water: no resistance
    c.resistance.a_n_per_mps = 0;
    c.resistance.b_n_per_mps2 = 0;
  }
  // The simulator's sway and yaw damping is quadratic cross flow over strips (vessel_cross_flow), which identify's
  // linear Y_v, N_r cannot express: left at 0, so the sway and yaw "ice" loads carry it (the surge load does not).
  c.damping = DampingOptions{};
  c.wind.air_density_kg_m3 = s.wind.air_density_kg_m3;
  c.wind.frontal_area_m2 = s.wind.frontal_area_m2;
  c.wind.lateral_area_m2 = s.wind.lateral_area_m2;
  c.wind.length_oa_m = number_at(summary, "vessel", "length_oa_m");
  c.wind.cx = s.wind.cx;
  c.wind.cy = s.wind.cy;
  c.wind.cn = s.wind.cn;
  // The mean over the simulation's steady part, as summary.json's mean_surge_ice_load_N (t >= steady_start_s).
  c.mean_window_s = {s.steady_start_s - 0.5 * s.time_step_s, s.duration_s};
  // The simulator integrates the world velocity with M = diag(m + A) along the body axes and no Munk terms: its
  // surge balance is M11 (u_dot - r v), which identify's Fossen C(nu) (-M22 v r) does not reproduce exactly; in a
  // straight transit r v is small, and M nu_dot alone (the seed's model) is kept.
  c.coriolis = false;
  return c;
}

}  // namespace

ShipData make_ship_data(const Results& results, const nlohmann::json& summary, const ShipDataOptions& o) {
  // 1. The simulation's settings, checked against the results' own record of them.
  FLOESIM_REQUIRE(summary.contains("settings") && summary["settings"].is_object(),
                  "summary.json has no settings: give the summary.json that floesim-simulate wrote");
  const nlohmann::json& settings = summary["settings"];
  if (results.attributes.contains("provenance") && results.attributes["provenance"].contains("config"))
    FLOESIM_REQUIRE(results.attributes["provenance"]["config"] == settings,
                    "summary.json's settings differ from the configuration recorded in results.h5: the summary "
                    "is of another run");
  const SimulateOptions s = read_options<SimulateOptions>(settings, "summary.json settings");

  ShipData d;
  d.identify = matching_config(s, summary);
  d.mean_t0_s = d.identify.mean_window_s[0];
  d.mean_t1_s = d.identify.mean_window_s[1];

  // 2. The series, at the simulation step.
  const auto& t = results.get("time_s");
  const auto& q = results.get("vessel_quaternion_wxyz");
  const auto& vel = results.get("vessel_velocity_mps");      // body axes
  const auto& om = results.get("vessel_angular_velocity_radps");  // body axes
  const auto& prop = results.get("propulsion_load");
  const auto& ice = results.get("ice_load");
  const size_t n = t.size();
  FLOESIM_REQUIRE(n >= 2, "results.h5 has ", n, " steps: at least 2 are needed");
  const double cdir = s.water.current_direction_deg * kPi / 180, wdir = s.wind.direction_deg * kPi / 180;
  const Vec3 current = s.water.current_speed_mps * Vec3(std::cos(cdir), std::sin(cdir), 0);
  const Vec3 wind = s.wind.speed_mps * Vec3(std::cos(wdir), std::sin(wdir), 0);
  d.wind = s.wind.speed_mps > 0;
  std::vector<double> u(n), v(n), r(n), ws(n, 0.0), wa(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    const Mat3 R = Quat(q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]).normalized().toRotationMatrix();
    const Vec3 vb(vel[3 * i], vel[3 * i + 1], vel[3 * i + 2]);
    const Vec3 rel = vb - R.transpose() * (s.water.enabled ? current : Vec3::Zero().eval());
    u[i] = rel.x();
    v[i] = rel.y();
    r[i] = om[3 * i + 2];
    if (d.wind) {
      // As vessel_wind: the air velocity relative to the vessel, body axes; gamma the angle it comes from.
      const Vec3 a = R.transpose() * wind - vb;
      ws[i] = std::hypot(a.x(), a.y());
      wa[i] = ws[i] > 0 ? std::atan2(-a.y(), -a.x()) * 180 / kPi : 0.0;
    }
  }
  // Backward differences at the simulation step (forward for the first row).
  auto diff = [&](const std::vector<double>& x) {
    std::vector<double> dx(n);
    for (size_t i = 1; i < n; ++i) dx[i] = (x[i] - x[i - 1]) / (t[i] - t[i - 1]);
    dx[0] = dx[1];
    return dx;
  };
  const std::vector<double> du = diff(u), dv = diff(v), dr = diff(r);

  // 3. Every k-th step, with the noise (one generator, drawn in row order: deterministic for a seed).
  std::mt19937_64 rng(static_cast<uint64_t>(o.seed));
  std::normal_distribution<double> normal(0.0, 1.0);
  const ShipDataNoiseOptions& e = o.noise;
  auto noisy = [&](double x, double sd, double bias) { return x + bias + (sd > 0 ? sd * normal(rng) : 0.0); };
  MeasuredSeries& m = d.measured;
  for (size_t i = static_cast<size_t>(o.every) - 1; i < n; i += static_cast<size_t>(o.every)) {
    m.time_s.push_back(t[i]);
    m.u_mps.push_back(noisy(u[i], e.velocity_sd_mps, 0));
    m.v_mps.push_back(noisy(v[i], e.velocity_sd_mps, 0));
    m.r_radps.push_back(noisy(r[i], e.yaw_rate_sd_radps, 0));
    m.thrust_n.push_back(prop[6 * i]);
    m.wind_speed_mps.push_back(ws[i]);
    m.wind_angle_deg.push_back(wa[i]);
    if (o.write_accelerations) {
      m.du_mps2.push_back(noisy(du[i], e.surge_sd_mps2, e.surge_bias_mps2));
      m.dv_mps2.push_back(noisy(dv[i], e.sway_sd_mps2, e.sway_bias_mps2));
      m.dr_radps2.push_back(noisy(dr[i], e.yaw_sd_radps2, e.yaw_bias_radps2));
    }
    d.sim_ice.push_back({ice[6 * i], ice[6 * i + 1], ice[6 * i + 5]});
  }
  FLOESIM_REQUIRE(m.time_s.size() >= 2, "every = ", o.every, " leaves ", m.time_s.size(), " of ", n,
                  " steps: lower it");
  return d;
}

std::string ship_data_csv(const ShipData& d, const ShipDataOptions& o) {
  const MeasuredSeries& m = d.measured;
  const bool acc = m.has_accelerations();
  std::ostringstream os;
  os << std::setprecision(15);
  os << "time_s,u_mps,v_mps,r_radps,thrust_n,wind_speed_mps,wind_angle_deg";
  if (acc) os << ",du_mps2,dv_mps2,dr_radps2";
  if (o.truth_columns) os << ",sim_ice_surge_n,sim_ice_sway_n,sim_ice_yaw_nm";
  os << '\n';
  for (size_t i = 0; i < m.time_s.size(); ++i) {
    os << m.time_s[i] << ',' << m.u_mps[i] << ',' << m.v_mps[i] << ',' << m.r_radps[i] << ',' << m.thrust_n[i]
       << ',' << m.wind_speed_mps[i] << ',' << m.wind_angle_deg[i];
    if (acc) os << ',' << m.du_mps2[i] << ',' << m.dv_mps2[i] << ',' << m.dr_radps2[i];
    if (o.truth_columns) os << ',' << d.sim_ice[i].surge << ',' << d.sim_ice[i].sway << ',' << d.sim_ice[i].yaw;
    os << '\n';
  }
  return os.str();
}

std::string run_shipdata(const fs::path& results_file, const fs::path& summary_file, const fs::path& config_file,
                         const fs::path& out_csv) {
  // 1. Inputs, all checked before anything is written.
  ShipDataOptions o;
  const fs::path summary_path = summary_file.empty() ? results_file.parent_path() / "summary.json" : summary_file;
  FLOESIM_REQUIRE(fs::exists(summary_path), summary_path.string(),
                  " does not exist: floesim-shipdata needs the summary.json floesim-simulate wrote beside "
                  "results.h5 (or give --summary)");
  std::vector<NamedInput> inputs = {{"results", results_file}, {"summary", summary_path}};
  if (!config_file.empty()) {
    o = read_options<ShipDataOptions>(load_json_file(config_file), config_file.string());
    inputs.push_back({"config", config_file});
  }
  FLOESIM_REQUIRE(out_csv.extension() == ".csv", "--out ", out_csv.string(), " must end in .csv (the identify "
                  "config is written beside it with the extension .json)");
  const Results results = read_results(results_file, false);
  const nlohmann::json summary = load_json_file(summary_path);
  const ShipData d = make_ship_data(results, summary, o);

  // 2. Artefacts, atomically: the CSV, the identify config (strict: nothing else in it) and the provenance.
  fs::path sidecar = out_csv, prov_file = out_csv;
  sidecar.replace_extension(".json");
  prov_file.replace_extension(".provenance.json");
  if (!out_csv.parent_path().empty()) ensure_directory(out_csv.parent_path());
  const nlohmann::json settings = options_to_json(o);
  nlohmann::json prov = make_provenance("floesim-shipdata", inputs, settings);
  prov["identify_config"] = sidecar.filename().string();
  write_text_atomic(out_csv, ship_data_csv(d, o));
  write_text_atomic(sidecar, options_to_json(d.identify).dump(2) + "\n");
  write_text_atomic(prov_file, prov.dump(2) + "\n");

  std::ostringstream rep;
  rep << "floesim-shipdata: " << d.measured.time_s.size() << " rows (every " << o.every << " of "
      << results.steps() << " steps), accelerations " << (o.write_accelerations ? "written" : "left to identify")
      << ", wind " << (d.wind ? "from the case" : "none") << "\n";
  rep << std::setprecision(6) << "identify config: M = diag[" << d.identify.mass.surge_kg << " kg, "
      << d.identify.mass.sway_kg << " kg, " << d.identify.mass.yaw_kg_m2 << " kg m^2], resistance "
      << d.identify.resistance.model << ", mean window [" << d.mean_t0_s << ", " << d.mean_t1_s << "] s\n";
  rep << "wrote " << out_csv.string() << ", " << sidecar.string() << " and " << prov_file.string() << "\n";
  return rep.str();
}

}  // namespace floesim::sim
