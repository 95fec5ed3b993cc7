#include "sim/analysis/identify.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

#include "pipeline/atomic_file.h"
#include "pipeline/csv.h"
#include "pipeline/error.h"
#include "pipeline/provenance.h"
#include <Eigen/Dense>

#include "pipeline/geometry2d.h"
#include "pipeline/signal.h"
#include "sim/vessel/open_water.h"

namespace floesim::sim {

namespace fs = std::filesystem;

namespace {

// Plausibility limits: a value beyond them is far more likely a unit mistake (knots, km/h, deg/s, kN) than real.
constexpr double kMaxSpeedMps = 15.0;        // ~29 kn: no icebreaker goes faster through the water
constexpr double kMaxYawRateRadps = 1.0;     // 57 deg/s
constexpr double kMaxThrustN = 1e8;          // 100 MN, 4x the largest icebreaker bollard pull
constexpr double kMaxWindMps = 75.0;         // beyond hurricane force
constexpr double kMaxAccelerationMps2 = 5.0;  // half of g: an IMU with gravity left in reads ~9.81
constexpr double kMaxYawAccelerationRadps2 = 1.0;
constexpr double kMaxGapRatio = 1.5;         // a step longer than this x the median step is a gap

// Column groups: the required ones; the measured accelerations (all three or none); a known ice load (all three or
// none), which a simulated ship's data carry so that identification can be checked against it.
enum class Group { required, acceleration, known_load };

struct Column {
  const char* name;
  Group group;
  std::vector<double> MeasuredSeries::*member;
};

const Column kColumns[] = {
    {"time_s", Group::required, &MeasuredSeries::time_s},
    {"u_mps", Group::required, &MeasuredSeries::u_mps},
    {"v_mps", Group::required, &MeasuredSeries::v_mps},
    {"r_radps", Group::required, &MeasuredSeries::r_radps},
    {"thrust_n", Group::required, &MeasuredSeries::thrust_n},
    {"wind_speed_mps", Group::required, &MeasuredSeries::wind_speed_mps},
    {"wind_angle_deg", Group::required, &MeasuredSeries::wind_angle_deg},
    {"du_mps2", Group::acceleration, &MeasuredSeries::du_mps2},
    {"dv_mps2", Group::acceleration, &MeasuredSeries::dv_mps2},
    {"dr_radps2", Group::acceleration, &MeasuredSeries::dr_radps2},
    {"sim_ice_surge_n", Group::known_load, &MeasuredSeries::known_ice_surge_n},
    {"sim_ice_sway_n", Group::known_load, &MeasuredSeries::known_ice_sway_n},
    {"sim_ice_yaw_nm", Group::known_load, &MeasuredSeries::known_ice_yaw_nm},
};

// A unit mistake, not a measurement: the message says which limit and what the column's unit is.
std::string implausible(const std::string& where, const char* col, double x, const char* limit, const char* unit) {
  std::ostringstream os;
  os << where << ", column " << col << ": " << x << " is implausible (" << limit << "): wrong units? The column must be in "
     << unit;
  return os.str();
}

}  // namespace

MeasuredSeries read_measured_csv(const fs::path& file) {
  std::ifstream in(file);
  FLOESIM_REQUIRE(in, file.string(), ": cannot open the measured-data CSV");
  const std::string f = file.string();

  // 1. Header: every required column, by name, any order; the accelerations all three or none.
  std::string line;
  size_t lineno = 0;
  bool got_header = false;
  while (!got_header && std::getline(in, line)) {
    ++lineno;
    got_header = !is_blank_csv_line(line);
  }
  FLOESIM_REQUIRE(got_header, f, ": empty file (expected a header with time_s,u_mps,v_mps,r_radps,thrust_n,"
                  "wind_speed_mps,wind_angle_deg and one row per sample)");
  const std::vector<std::string> header = split_csv_line(line);
  std::map<std::string, size_t> index;
  for (size_t i = 0; i < header.size(); ++i) index.emplace(header[i], i);
  std::vector<std::string> missing;
  for (const Column& c : kColumns)
    if (c.group == Group::required && !index.count(c.name)) missing.push_back(c.name);
  if (!missing.empty()) {
    std::string names;
    for (const std::string& m : missing) names += (names.empty() ? "" : ", ") + m;
    throw Error(f + ": line " + std::to_string(lineno) + " (header): missing required column" +
                (missing.size() > 1 ? "s " : " ") + names + " (SI units: time_s, u_mps, v_mps, r_radps, thrust_n, "
                "wind_speed_mps, wind_angle_deg; optional du_mps2, dv_mps2, dr_radps2)");
  }
  const int n_acc = int(index.count("du_mps2")) + int(index.count("dv_mps2")) + int(index.count("dr_radps2"));
  FLOESIM_REQUIRE(n_acc == 0 || n_acc == 3, f, ": line ", lineno,
                  " (header): give all three measured accelerations du_mps2, dv_mps2, dr_radps2 or none (then they "
                  "come from differentiating the velocities)");
  const bool with_acc = n_acc == 3;
  const int n_known =
      int(index.count("sim_ice_surge_n")) + int(index.count("sim_ice_sway_n")) + int(index.count("sim_ice_yaw_nm"));
  FLOESIM_REQUIRE(n_known == 0 || n_known == 3, f, ": line ", lineno,
                  " (header): give all three known ice-load columns sim_ice_surge_n, sim_ice_sway_n, sim_ice_yaw_nm "
                  "or none");
  const bool with_known = n_known == 3;
  // IMUs: imu1.., each with both columns; they replace du/dv/dr, so both at once would be ambiguous.
  size_t n_imu = 0;
  for (size_t k = 1; k <= 5; ++k) {
    const std::string ax = "imu" + std::to_string(k) + "_ax_mps2", ay = "imu" + std::to_string(k) + "_ay_mps2";
    const bool hx = index.count(ax) > 0, hy = index.count(ay) > 0;
    if (!hx && !hy) break;
    FLOESIM_REQUIRE(hx && hy, f, ": line ", lineno, " (header): IMU ", k, " needs both columns ", ax, " and ", ay);
    FLOESIM_REQUIRE(k <= 4, f, ": line ", lineno, " (header): column ", ax, ": at most 4 IMUs");
    n_imu = k;
  }
  FLOESIM_REQUIRE(n_imu == 0 || !with_acc, f, ": line ", lineno,
                  " (header): give either the accelerations du_mps2, dv_mps2, dr_radps2 or IMU columns, not both");

  // 2. Rows: finite numbers, plausible units, increasing time.
  MeasuredSeries m;
  m.imu_ax_mps2.resize(n_imu);
  m.imu_ay_mps2.resize(n_imu);
  std::vector<size_t> row_line;  // the file line of each sample, for the messages below
  while (std::getline(in, line)) {
    ++lineno;
    if (is_blank_csv_line(line)) continue;
    const std::vector<std::string> cells = split_csv_line(line);
    const std::string where = f + ": line " + std::to_string(lineno) + " (data row " +
                              std::to_string(m.time_s.size() + 1) + ")";
    FLOESIM_REQUIRE(cells.size() == header.size(), where, ": ", cells.size(), " cells, the header has ",
                    header.size());
    for (const Column& c : kColumns) {
      if ((c.group == Group::acceleration && !with_acc) || (c.group == Group::known_load && !with_known)) continue;
      const std::string& s = cells[index.at(c.name)];
      double x = 0;
      FLOESIM_REQUIRE(parse_finite_number(s, x), where, ", column ", c.name, ": '", s,
                      "' is not a finite number (NaN, inf and empty cells are errors: cut the series or fill the "
                      "gap)");
      (m.*(c.member)).push_back(x);
    }
    const size_t i = m.time_s.size() - 1;
    const double u = m.u_mps[i], v = m.v_mps[i], r = m.r_radps[i], thr = m.thrust_n[i];
    FLOESIM_REQUIRE(std::abs(u) <= kMaxSpeedMps, implausible(where, "u_mps", u, "|u| > 15 m/s", "m/s"));
    FLOESIM_REQUIRE(std::abs(v) <= kMaxSpeedMps, implausible(where, "v_mps", v, "|v| > 15 m/s", "m/s"));
    FLOESIM_REQUIRE(std::abs(r) <= kMaxYawRateRadps, implausible(where, "r_radps", r, "|r| > 1 rad/s", "rad/s"));
    FLOESIM_REQUIRE(thr >= 0 && thr <= kMaxThrustN,
                    implausible(where, "thrust_n", thr, "thrust < 0 or > 1e8 N", "N (total effective thrust)"));
    FLOESIM_REQUIRE(m.wind_speed_mps[i] >= 0 && m.wind_speed_mps[i] <= kMaxWindMps,
                    implausible(where, "wind_speed_mps", m.wind_speed_mps[i], "< 0 or > 75 m/s", "m/s"));
    FLOESIM_REQUIRE(std::abs(m.wind_angle_deg[i]) <= 360,
                    implausible(where, "wind_angle_deg", m.wind_angle_deg[i], "|angle| > 360", "degrees"));
    if (with_acc) {
      FLOESIM_REQUIRE(std::abs(m.du_mps2[i]) <= kMaxAccelerationMps2,
                      implausible(where, "du_mps2", m.du_mps2[i], "|du| > 5 m/s^2; gravity not removed?", "m/s^2"));
      FLOESIM_REQUIRE(std::abs(m.dv_mps2[i]) <= kMaxAccelerationMps2,
                      implausible(where, "dv_mps2", m.dv_mps2[i], "|dv| > 5 m/s^2; gravity not removed?", "m/s^2"));
      FLOESIM_REQUIRE(std::abs(m.dr_radps2[i]) <= kMaxYawAccelerationRadps2,
                      implausible(where, "dr_radps2", m.dr_radps2[i], "|dr| > 1 rad/s^2", "rad/s^2"));
    }
    for (size_t k = 0; k < n_imu; ++k)
      for (const char* axis : {"ax", "ay"}) {
        const std::string col = "imu" + std::to_string(k + 1) + "_" + axis + "_mps2";
        const std::string& c = cells[index.at(col)];
        double x = 0;
        FLOESIM_REQUIRE(parse_finite_number(c, x), where, ", column ", col,
                        ": '", c, "' is not a finite number");
        FLOESIM_REQUIRE(std::abs(x) <= kMaxAccelerationMps2,
                        implausible(where, col.c_str(), x, "|a| > 5 m/s^2; gravity not removed?", "m/s^2"));
        (axis[1] == 'x' ? m.imu_ax_mps2 : m.imu_ay_mps2)[k].push_back(x);
      }
    FLOESIM_REQUIRE(i == 0 || m.time_s[i] > m.time_s[i - 1], where, ", column time_s: ", m.time_s[i],
                    " s is not after the previous sample's ", i == 0 ? 0.0 : m.time_s[i - 1],
                    " s (time must increase strictly: sort the rows or drop the repeated ones)");
    row_line.push_back(lineno);
  }
  const size_t n = m.time_s.size();
  FLOESIM_REQUIRE(n >= 3, f, ": ", n, " data rows; at least 3 are needed (and at least one output interval)");

  // 3. Gaps: a step much longer than the median means lost samples, which would bias the accelerations.
  std::vector<double> steps(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) steps[i] = m.time_s[i + 1] - m.time_s[i];
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  for (size_t i = 0; i + 1 < n; ++i)
    FLOESIM_REQUIRE(steps[i] <= kMaxGapRatio * median, f, ": line ", row_line[i + 1], " (data row ", i + 2,
                    "), column time_s: a gap of ", steps[i], " s after t = ", m.time_s[i],
                    " s (more than 1.5 x the median step ", median,
                    " s): identify the parts either side of the gap separately");
  return m;
}

Load3 combine_imus(const std::vector<ImuSample>& imus, double r, double r_dot) {
  FLOESIM_REQUIRE(!imus.empty(), "combine_imus: no IMU");
  // b_k = a_k + r^2 p_k = a_G + r_dot z x p_k, with z x p = (-p_y, p_x): linear in (a_Gx, a_Gy, r_dot).
  bool distinct = false;
  for (const ImuSample& s : imus)
    distinct = distinct || std::hypot(s.x_m - imus[0].x_m, s.y_m - imus[0].y_m) > 1e-6;
  if (!distinct) {  // r_dot is unobservable from one point: use the one given
    double ax = 0, ay = 0;
    for (const ImuSample& s : imus) {
      ax += s.ax_mps2 + r * r * s.x_m + r_dot * s.y_m;
      ay += s.ay_mps2 + r * r * s.y_m - r_dot * s.x_m;
    }
    return {ax / double(imus.size()), ay / double(imus.size()), r_dot};
  }
  // Least squares by the normal equations; rows (1, 0, -p_y) and (0, 1, p_x) per IMU.
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (const ImuSample& s : imus) {
    const Eigen::Vector3d rx(1, 0, -s.y_m), ry(0, 1, s.x_m);
    ata += rx * rx.transpose() + ry * ry.transpose();
    atb += rx * (s.ax_mps2 + r * r * s.x_m) + ry * (s.ay_mps2 + r * r * s.y_m);
  }
  const Eigen::Vector3d x = ata.ldlt().solve(atb);
  return {x[0], x[1], x[2]};
}

double open_water_resistance(double u, const ResistanceOptions& o) {
  if (o.model == "quadratic") return o.a_n_per_mps * u + o.b_n_per_mps2 * u * std::abs(u);
  // ITTC-57: the simulator's own curve (sim/vessel/open_water.h), fed with these particulars and water.
  Ittc57 c;
  c.length_wl_m = o.length_wl_m;
  c.wetted_surface_m2 = o.wetted_surface_m2;
  c.form_factor_k = o.form_factor_k;
  c.roughness_ca = o.roughness_ca;
  c.water_density_kg_m3 = o.water_density_kg_m3;
  c.kinematic_viscosity_m2ps = o.kinematic_viscosity_m2ps;
  return ittc57_resistance(u, c);
}

Load3 wind_load(double speed_mps, double angle_deg, const IdentifyWindOptions& o) {
  const double q = 0.5 * o.air_density_kg_m3 * speed_mps * speed_mps;
  const Eigen::Vector3d xyn = fossen_wind_xyn(q, angle_deg * kPi / 180, o.frontal_area_m2, o.lateral_area_m2, o.length_oa_m,
                                   o.cx, o.cy, o.cn);  // the simulator's own wind law
  Load3 w;
  w.surge = xyn.x();
  w.sway = xyn.y();
  w.yaw = xyn.z();
  return w;
}

namespace {

// The identified load against the known one over the mean window (see KnownLoadComparison).
KnownLoadComparison compare_with_known(const Identification& id) {
  KnownLoadComparison c;
  long double kx = 0, ky = 0, kn = 0;
  const IdentifiedSeries& s = id.samples;
  for (size_t i = 0; i < s.time_s.size(); ++i) {
    if (s.time_s[i] < id.mean_t0_s || s.time_s[i] > id.mean_t1_s) continue;
    kx += s.known[i].surge, ky += s.known[i].sway, kn += s.known[i].yaw;
  }
  const double n = double(id.mean_samples);
  c.mean_known = {double(kx / n), double(ky / n), double(kn / n)};
  c.surge_error_n = id.mean_ice.surge - c.mean_known.surge;
  c.surge_error_relative = c.mean_known.surge != 0 ? c.surge_error_n / std::abs(c.mean_known.surge) : NAN;
  const IdentifiedSeries& o = id.output;
  double se = 0, m = 0, m2 = 0;
  for (size_t k = 0; k < o.time_s.size(); ++k) {
    if (o.time_s[k] < id.mean_t0_s || o.time_s[k] > id.mean_t1_s) continue;
    const double d = o.ice[k].surge - o.known[k].surge;
    se += d * d, m += o.known[k].surge, m2 += o.known[k].surge * o.known[k].surge;
    ++c.intervals;
  }
  if (c.intervals > 0) {
    const double ni = double(c.intervals);
    c.surge_rms_n = std::sqrt(se / ni);
    c.surge_sd_n = std::sqrt(std::max(0.0, m2 / ni - (m / ni) * (m / ni)));
  }
  return c;
}

}  // namespace

Identification identify(const MeasuredSeries& m, const IdentifyOptions& o) {
  const size_t n = m.time_s.size();
  FLOESIM_REQUIRE(n >= 3, "identify: at least 3 samples are needed, got ", n);
  Identification id;

  // 1. Accelerations: measured, or central differences of the velocities (one-sided at the two ends); then the
  //    centred moving average (pipeline/signal.h), whose N comes from the median step.
  std::vector<double> steps(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) steps[i] = m.time_s[i + 1] - m.time_s[i];
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  id.median_step_s = sorted[sorted.size() / 2];
  const double T = o.filters.output_interval_s;
  FLOESIM_REQUIRE(id.median_step_s <= T, "identify: the sample step ", id.median_step_s,
                  " s is longer than the output interval ", T, " s (filters.output_interval_s): lengthen it");
  FLOESIM_REQUIRE(m.time_s.back() - m.time_s.front() >= T * (1 - 1e-9), "identify: the series lasts ",
                  m.time_s.back() - m.time_s.front(), " s, less than one output interval of ", T, " s");
  const size_t n_imu = m.imu_ax_mps2.size();
  FLOESIM_REQUIRE(n_imu == o.imus.size(), "the measured data give ", n_imu, " IMU(s) (columns imu<k>_ax_mps2, "
                  "imu<k>_ay_mps2) but the config's imus lists ", o.imus.size(), ": give one position per IMU");
  id.from_imus = n_imu > 0;
  id.differentiated = !m.has_accelerations() && !id.from_imus;
  auto derivative = [&](const std::vector<double>& x) {
    std::vector<double> d(n);
    d[0] = (x[1] - x[0]) / (m.time_s[1] - m.time_s[0]);
    d[n - 1] = (x[n - 1] - x[n - 2]) / (m.time_s[n - 1] - m.time_s[n - 2]);
    for (size_t i = 1; i + 1 < n; ++i) d[i] = (x[i + 1] - x[i - 1]) / (m.time_s[i + 1] - m.time_s[i - 1]);
    return d;
  };
  std::vector<double> du = id.differentiated ? derivative(m.u_mps) : m.du_mps2;
  std::vector<double> dv = id.differentiated ? derivative(m.v_mps) : m.dv_mps2;
  std::vector<double> dr = id.differentiated ? derivative(m.r_radps) : m.dr_radps2;
  if (id.from_imus) {
    // IMUs measure the inertial acceleration in body axes, a_G = nu_dot + [-r v, r u]: hence nu_dot.
    const std::vector<double> r_dot = derivative(m.r_radps);
    du.assign(n, 0.0), dv.assign(n, 0.0), dr.assign(n, 0.0);
    std::vector<ImuSample> at(n_imu);
    for (size_t i = 0; i < n; ++i) {
      for (size_t k = 0; k < n_imu; ++k)
        at[k] = {o.imus[k].position_m[0], o.imus[k].position_m[1], m.imu_ax_mps2[k][i], m.imu_ay_mps2[k][i]};
      const Load3 a = combine_imus(at, m.r_radps[i], r_dot[i]);
      du[i] = a.surge + m.r_radps[i] * m.v_mps[i];
      dv[i] = a.sway - m.r_radps[i] * m.u_mps[i];
      dr[i] = a.yaw;
    }
  }
  id.acceleration_window_samples = window_samples(o.filters.acceleration_window_s, id.median_step_s);
  du = moving_average_centred(du, id.acceleration_window_samples);
  dv = moving_average_centred(dv, id.acceleration_window_samples);
  dr = moving_average_centred(dr, id.acceleration_window_samples);

  // 2. Every term per sample; the ice load by difference.
  IdentifiedSeries& s = id.samples;
  s.time_s = m.time_s;
  s.u_mps = m.u_mps;
  for (size_t i = 0; i < n; ++i) {
    Load3 inertia{o.mass.surge_kg * du[i], o.mass.sway_kg * dv[i], o.mass.yaw_kg_m2 * dr[i]};
    if (o.coriolis) {  // + C(nu) nu of the diagonal M (Fossen 2011, rigid body and added mass lumped)
      const double u = m.u_mps[i], v = m.v_mps[i], r = m.r_radps[i];
      inertia.surge += -o.mass.sway_kg * v * r;
      inertia.sway += o.mass.surge_kg * u * r;
      inertia.yaw += (o.mass.sway_kg - o.mass.surge_kg) * u * v;
    }
    const Load3 thrust{m.thrust_n[i], 0, 0};
    const Load3 hydro{-open_water_resistance(m.u_mps[i], o.resistance), -o.damping.sway_n_per_mps * m.v_mps[i],
                      -o.damping.yaw_nm_per_radps * m.r_radps[i]};
    const Load3 wind = wind_load(m.wind_speed_mps[i], m.wind_angle_deg[i], o.wind);
    const Load3 ice{inertia.surge - thrust.surge - hydro.surge - wind.surge, inertia.sway - hydro.sway - wind.sway,
                    inertia.yaw - hydro.yaw - wind.yaw};
    s.inertia.push_back(inertia);
    s.thrust.push_back(thrust);
    s.hydro.push_back(hydro);
    s.wind.push_back(wind);
    s.ice.push_back(ice);
    if (m.has_known_ice()) s.known.push_back({m.known_ice_surge_n[i], m.known_ice_sway_n[i], m.known_ice_yaw_nm[i]});
  }

  // 3. Output rate: the arithmetic mean of the samples in each interval [t_0 + kT, t_0 + (k+1)T), k = 0..K-1, for
  //    the K whole intervals in the series (a last partial interval is dropped); stamped at the interval's centre.
  //    The 1e-9 keeps a sample that lies on a boundary up to round-off in the later interval.
  const double t0 = m.time_s.front();
  const size_t K = static_cast<size_t>(std::floor((m.time_s.back() - t0) / T + 1e-9));
  std::vector<std::vector<size_t>> members(K);
  for (size_t i = 0; i < n; ++i) {
    const double k = std::floor((m.time_s[i] - t0) / T + 1e-9);
    if (k >= 0 && k < double(K)) members[size_t(k)].push_back(i);
  }
  auto avg3 = [](const std::vector<Load3>& x, const std::vector<size_t>& idx) {
    Load3 a;
    for (size_t i : idx) a.surge += x[i].surge, a.sway += x[i].sway, a.yaw += x[i].yaw;
    const double c = 1.0 / double(idx.size());
    return Load3{a.surge * c, a.sway * c, a.yaw * c};
  };
  for (size_t k = 0; k < K; ++k) {
    FLOESIM_REQUIRE(!members[k].empty(), "identify: no sample in the output interval [", t0 + k * T, ", ",
                    t0 + (k + 1) * T, ") s: lengthen filters.output_interval_s");
    IdentifiedSeries& out = id.output;
    out.time_s.push_back(t0 + (k + 0.5) * T);
    out.inertia.push_back(avg3(s.inertia, members[k]));
    out.thrust.push_back(avg3(s.thrust, members[k]));
    out.hydro.push_back(avg3(s.hydro, members[k]));
    out.wind.push_back(avg3(s.wind, members[k]));
    out.ice.push_back(avg3(s.ice, members[k]));
    if (m.has_known_ice()) out.known.push_back(avg3(s.known, members[k]));
    double u = 0;
    for (size_t i : members[k]) u += m.u_mps[i];
    out.u_mps.push_back(u / double(members[k].size()));
  }

  // 4. Mean ice load (PHYSICS.md §5: the arithmetic mean of the unfiltered full-rate series) over the window.
  id.mean_t0_s = o.mean_window_s.empty() ? m.time_s.front() : o.mean_window_s[0];
  id.mean_t1_s = o.mean_window_s.empty() ? m.time_s.back() : o.mean_window_s[1];
  long double sx = 0, sy = 0, sn = 0;
  for (size_t i = 0; i < n; ++i) {
    if (m.time_s[i] < id.mean_t0_s || m.time_s[i] > id.mean_t1_s) continue;
    sx += s.ice[i].surge, sy += s.ice[i].sway, sn += s.ice[i].yaw;
    ++id.mean_samples;
  }
  FLOESIM_REQUIRE(id.mean_samples > 0, "mean_window_s [", id.mean_t0_s, ", ", id.mean_t1_s,
                  "] s holds no sample of the series (", m.time_s.front(), " to ", m.time_s.back(),
                  " s): move the window into the series");
  id.mean_ice = {double(sx / id.mean_samples), double(sy / id.mean_samples), double(sn / id.mean_samples)};
  if (m.has_known_ice()) {
    id.has_known = true;
    id.known = compare_with_known(id);
  }
  return id;
}

namespace {

std::string identified_csv(const Identification& id) {
  std::ostringstream os;
  os << std::setprecision(10);
  os << "time_s,ice_surge_n,ice_sway_n,ice_yaw_nm,u_mps,thrust_surge_n,hydro_surge_n,hydro_sway_n,hydro_yaw_nm,"
        "wind_surge_n,wind_sway_n,wind_yaw_nm,inertia_surge_n,inertia_sway_n,inertia_yaw_nm";
  if (id.has_known) os << ",known_ice_surge_n,known_ice_sway_n,known_ice_yaw_nm";
  os << '\n';
  const IdentifiedSeries& s = id.output;
  for (size_t k = 0; k < s.time_s.size(); ++k) {
    os << s.time_s[k] << ',' << s.ice[k].surge << ',' << s.ice[k].sway << ',' << s.ice[k].yaw << ',' << s.u_mps[k]
       << ',' << s.thrust[k].surge << ',' << s.hydro[k].surge << ',' << s.hydro[k].sway << ',' << s.hydro[k].yaw
       << ',' << s.wind[k].surge << ',' << s.wind[k].sway << ',' << s.wind[k].yaw << ',' << s.inertia[k].surge << ','
       << s.inertia[k].sway << ',' << s.inertia[k].yaw;
    if (id.has_known) os << ',' << s.known[k].surge << ',' << s.known[k].sway << ',' << s.known[k].yaw;
    os << '\n';
  }
  return os.str();
}

}  // namespace

std::string run_identify(const fs::path& measured_file, const fs::path& config_file, const fs::path& out_dir) {
  // 1. Inputs, all checked before anything is written.
  IdentifyOptions o;
  std::vector<NamedInput> inputs = {{"measured", measured_file}};
  if (!config_file.empty()) {
    o = read_options<IdentifyOptions>(load_json_file(config_file), config_file.string());
    inputs.push_back({"config", config_file});
  }
  const MeasuredSeries m = read_measured_csv(measured_file);
  const Identification id = identify(m, o);

  // 2. The summary.
  const nlohmann::json settings = options_to_json(o);
  nlohmann::json j;
  j["mean_surge_ice_load_n"] = id.mean_ice.surge;
  j["mean_surge_ice_resistance_n"] = -id.mean_ice.surge;
  j["mean_sway_ice_load_n"] = id.mean_ice.sway;
  j["mean_yaw_ice_load_nm"] = id.mean_ice.yaw;
  j["mean_window_s"] = {id.mean_t0_s, id.mean_t1_s};
  j["mean_samples"] = id.mean_samples;
  j["samples"] = m.time_s.size();
  j["median_step_s"] = id.median_step_s;
  j["accelerations"] = id.differentiated ? "central differences of the velocities"
                      : id.from_imus     ? "IMUs combined to the centre of gravity"
                                         : "measured";
  j["acceleration_window_samples"] = id.acceleration_window_samples;
  j["output_samples"] = id.output.time_s.size();
  j["sign_convention"] =
      "forces and moments on the ship, body axes x forward, y to port, z up; ice resisting the advance gives a "
      "negative surge load (resistance = -surge load)";
  if (id.has_known) {
    const KnownLoadComparison& k = id.known;
    j["known_load"] = {
        {"what", "the ice load given in the measured data's sim_ice_* columns (a simulated ship's)"},
        {"mean_surge_ice_load_n", k.mean_known.surge},
        {"mean_surge_ice_resistance_n", -k.mean_known.surge},
        {"mean_sway_ice_load_n", k.mean_known.sway},
        {"mean_yaw_ice_load_nm", k.mean_known.yaw},
        {"surge_error_n", k.surge_error_n},
        {"surge_error_percent", 100 * k.surge_error_relative},
        {"output_rate_surge_rms_error_n", k.surge_rms_n},
        {"output_rate_surge_known_sd_n", k.surge_sd_n},
        {"output_intervals_compared", k.intervals}};
  }
  j["settings"] = settings;
  j["provenance"] = make_provenance("floesim-identify", inputs, settings);

  // 3. Artefacts, atomically.
  ensure_directory(out_dir);
  write_text_atomic(out_dir / "identified.csv", identified_csv(id));
  write_text_atomic(out_dir / "identified.json", j.dump(2) + "\n");

  std::ostringstream rep;
  rep << std::fixed << std::setprecision(1);
  rep << "floesim-identify: " << m.time_s.size() << " samples, median step " << std::setprecision(4)
      << id.median_step_s << " s, accelerations "
      << (id.differentiated ? "from central differences" : id.from_imus ? "from the IMUs" : "measured")
      << ", moving average of "
      << id.acceleration_window_samples << " samples\n";
  rep << std::setprecision(1) << "mean surge ice load " << id.mean_ice.surge / 1e3 << " kN (resistance "
      << -id.mean_ice.surge / 1e3 << " kN) over " << id.mean_t0_s << " to " << id.mean_t1_s << " s\n";
  if (id.has_known)
    rep << std::setprecision(1) << "against the known load of the data: its mean resistance "
        << -id.known.mean_known.surge / 1e3 << " kN, the identified one " << std::showpos << std::setprecision(3)
        << -100 * id.known.surge_error_relative << std::noshowpos << " %; RMS error of the " << std::defaultfloat
        << o.filters.output_interval_s << std::fixed << " s series " << std::setprecision(1)
        << id.known.surge_rms_n / 1e3 << " kN (known series sd " << id.known.surge_sd_n / 1e3 << " kN)\n";
  rep << "wrote " << (out_dir / "identified.csv").string() << " (" << id.output.time_s.size() << " rows) and "
      << (out_dir / "identified.json").string() << "\n";
  return rep.str();
}

}  // namespace floesim::sim
