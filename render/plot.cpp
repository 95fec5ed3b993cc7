#include "render/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "pipeline/atomic_file.h"
#include "pipeline/csv.h"
#include "pipeline/error.h"
#include "pipeline/geometry2d.h"
#include "pipeline/provenance.h"
#include "render/gnuplot.h"
#include "pipeline/signal.h"
#include "pipeline/units.h"

namespace floesim::render {

namespace fs = std::filesystem;

PlotOptions read_plot_options(const fs::path& config) {
  return read_options<PlotOptions>(load_json_file(config), config.string());
}

namespace {

// NaN has no JSON spelling: null.
nlohmann::json json_number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

// A short name for the script building below.
std::string quoted(const std::string& s) { return gnuplot_quoted(s); }

// For the drawing only (the CSV keeps every sample): with far more samples than pixels, keep each bin's minimum
// and maximum in time order, so that single-step spikes stay visible and files stay small.
void write_decimated(std::ostream& os, const std::vector<double>& t, const std::vector<double>& x, size_t bins) {
  const size_t n = t.size();
  if (n <= 4 * bins) {
    for (size_t i = 0; i < n; ++i) os << fmt("%.9g", t[i]) << ' ' << fmt("%.9g", x[i]) << '\n';
    return;
  }
  for (size_t b = 0; b < bins; ++b) {
    const size_t lo = b * n / bins, hi = (b + 1) * n / bins;
    size_t imin = lo, imax = lo;
    for (size_t i = lo; i < hi; ++i) {
      if (x[i] < x[imin]) imin = i;
      if (x[i] > x[imax]) imax = i;
    }
    const size_t a = std::min(imin, imax), c = std::max(imin, imax);
    os << fmt("%.9g", t[a]) << ' ' << fmt("%.9g", x[a]) << '\n';
    if (c != a) os << fmt("%.9g", t[c]) << ' ' << fmt("%.9g", x[c]) << '\n';
  }
}

}  // namespace

namespace {

// The centred moving average of step 2.
struct MovingAverage {
  std::vector<double> ma;
  size_t f0 = 0, f1 = 0;  // [f0, f1): the samples reported (whole windows; all if the run is shorter)
};

// 2. The window ("auto" follows the contact model the simulator recorded, PHYSICS.md §5) and the centred moving
// average. Only samples whose whole window lies in the run are reported: near the ends a cut window averages what
// is left (e.g. 10 s of open water and one spike) and looks like data it is not. If the run is shorter than the
// window, the cut averages are all there is; they are shown and flagged.
MovingAverage centred_moving_average(const Results& r, const PlotOptions& o, const std::vector<double>& res,
                                     const std::string& source, SurgeLoadSummary& s) {
  s.contact_model = recorded_contact_model(r, source);
  MovingAverage m;
  if (o.moving_average_window_s.is_string()) {
    FilteredLoad f = auto_filtered_surge_ice_resistance_kN(r, source);
    s.window_s = f.window_s;
    s.filter = f.text;
    m.ma = std::move(f.kN);
    s.window_samples = window_samples(s.window_s, s.time_step_s);
  } else {
    s.window_s = o.moving_average_window_s.get<double>();
    s.window_samples = window_samples(s.window_s, s.time_step_s);
    s.filter = fmt("%g", s.window_s) + " s centred moving average";
    m.ma = moving_average_centred(res, s.window_samples);
  }
  auto [f0, f1] = full_window_range(res.size(), s.window_samples);
  s.moving_average_complete = f0 < f1;
  if (!s.moving_average_complete) f0 = 0, f1 = res.size();
  m.f0 = f0;
  m.f1 = f1;
  return m;
}

// 3. The steady part and its mean (of the unfiltered signal: the primary validation metric), the moving average's
// spread and peak over it (reported samples only), and the raw peak.
void steady_statistics(const Results& r, const PlotOptions& o, const std::vector<double>& t,
                       const std::vector<double>& res, const MovingAverage& m, const std::string& source,
                       SurgeLoadSummary& s) {
  s.steady_start_s =
      o.steady_start_s.is_number() ? o.steady_start_s.get<double>() : recorded_steady_start_s(r, source);
  const SteadyMean sm = mean_from(t, res, s.steady_start_s);
  s.mean_kN = sm.mean;
  s.steady_samples = sm.samples;
  std::vector<double> steady;
  for (size_t i = 0; i < t.size(); ++i)
    if (t[i] >= s.steady_start_s) steady.push_back(res[i]);
  s.interval = mean_interval(steady, s.time_step_s);
  double sum2 = 0, mx = -1e300;
  size_t c = 0;
  for (size_t i = m.f0; i < m.f1; ++i)
    if (t[i] >= s.steady_start_s) {
      const double d = m.ma[i] - sm.mean;
      sum2 += d * d, mx = std::max(mx, m.ma[i]), ++c;
    }
  s.moving_average_std_kN = c > 0 ? std::sqrt(sum2 / static_cast<double>(c)) : std::nan("");
  s.moving_average_max_kN = c > 0 ? mx : std::nan("");
  s.raw_max_kN = *std::max_element(res.begin(), res.end());
}

// The times of the fracture events at the vessel, by marker style.
struct VesselEvents {
  std::vector<double> split_t, bend_t;
};

// 4. Fracture events. Only those at the vessel are marked: the plot is of the load on the vessel, and a floe that
// breaks against another floe changes it only indirectly. Every event goes into fracture_events.csv.
VesselEvents vessel_fracture_events(const Results& r, const std::string& source, SurgeLoadSummary& s) {
  const size_t events = r.fracture_time_s.size();
  const std::string problem = fracture_problem(r);
  FLOESIM_REQUIRE(problem.empty(), source, ": ", problem);
  VesselEvents ev;
  for (size_t k = 0; k < events; ++k)
    if (r.fracture_at_structure[k] == 1 && r.fracture_mode[k] != kFractureCrushing)  // crushing clears, not a crack
      (r.fracture_mode[k] == kFractureSplitting ? ev.split_t : ev.bend_t).push_back(r.fracture_time_s[k]);
  s.fracture_events = events;
  s.vessel_splitting_events = ev.split_t.size();
  s.vessel_bending_radial_events = ev.bend_t.size();
  return ev;
}

// 5. The CSV of every sample; the average is empty where its window is cut.
void write_samples_csv(const AtomicFile& csv, const std::vector<double>& t, const std::vector<double>& res,
                       const MovingAverage& m) {
  std::ostringstream os;
  os << "time_s,ice_resistance_kN,moving_average_kN\n";  // average empty where its window is cut
  for (size_t i = 0; i < t.size(); ++i)
    os << fmt("%.10g", t[i]) << ',' << fmt("%.10g", res[i]) << ','
       << (i >= m.f0 && i < m.f1 ? fmt("%.10g", m.ma[i]) : std::string()) << '\n';
  write_file_checked(csv.tmp(), os.str(), csv.path());
}

// 5. The CSV of every fracture event (force on the floe in the world frame, as recorded).
void write_events_csv(const AtomicFile& events_csv, const Results& r) {
  std::ostringstream os;
  os << "time_s,mode,parent_id,at_structure,force_x_n,force_y_n,force_z_n,threshold_n,children\n";
  for (size_t k = 0; k < r.fracture_time_s.size(); ++k) {
    os << fmt("%.10g", r.fracture_time_s[k]) << ',' << fracture_mode_name(r.fracture_mode[k]) << ','
       << r.fracture_parent_id[k] << ',' << r.fracture_at_structure[k];
    for (int c = 0; c < 3; ++c) os << ',' << fmt("%.10g", r.fracture_force_n[3 * k + c]);
    os << ',' << fmt("%.10g", r.fracture_threshold_n[k]) << ',';
    // The pieces' floe ids, space-separated in one field (a CSV cell per event, however many pieces).
    for (int64_t c = r.fracture_child_offset[k]; c < r.fracture_child_offset[k + 1]; ++c)
      os << (c > r.fracture_child_offset[k] ? " " : "") << r.fracture_child_id[c];
    os << '\n';
  }
  write_file_checked(events_csv.tmp(), os.str(), events_csv.path());
}

// 6. The unit that suits the loads' size (N for a tank model, kN for a ship): chosen from the larger of the mean
// and the moving average's peak.
ForceUnit plot_unit(const MovingAverage& m, double mean_kN) {
  const auto b = m.ma.begin() + static_cast<long>(m.f0), e = m.ma.begin() + static_cast<long>(m.f1);
  const double ma_abs_max = std::max(std::abs(*std::max_element(b, e)), std::abs(*std::min_element(b, e)));
  return force_unit_for(1000.0 * std::max(std::abs(mean_kN), ma_abs_max));
}

// A series in kN times to_unit (into the display unit).
std::vector<double> scaled(const std::vector<double>& x, double to_unit) {
  std::vector<double> y(x);
  for (double& v : y) v *= to_unit;
  return y;
}

// 6. The plot data, in the display unit (to_unit per kN): the raw series and the moving average decimated to ~2
// points per pixel column (bins), the steady mean's line, and the event times (the script places the markers).
void write_plot_data(const AtomicFile& data, const std::vector<double>& t, const std::vector<double>& res,
                     const MovingAverage& m, const VesselEvents& ev, const SurgeLoadSummary& s, double to_unit,
                     size_t bins) {
  std::ostringstream os;
  write_decimated(os, t, scaled(res, to_unit), bins);
  os << "\n\n";
  const std::vector<double> tm(t.begin() + static_cast<long>(m.f0), t.begin() + static_cast<long>(m.f1)),
      mm(m.ma.begin() + static_cast<long>(m.f0), m.ma.begin() + static_cast<long>(m.f1));
  write_decimated(os, tm, scaled(mm, to_unit), bins);
  os << "\n\n";
  // The mean's line and its 95 % band (collapsed onto the line when there is no interval).
  const double t_mean0 = std::max(s.steady_start_s, t.front());
  const double hw = std::isfinite(s.interval.half_width) ? s.interval.half_width : 0.0;
  for (double tm : {t_mean0, t.back()})
    os << fmt("%.9g", tm) << ' ' << fmt("%.9g", s.mean_kN * to_unit) << ' '
       << fmt("%.9g", (s.mean_kN - hw) * to_unit) << ' ' << fmt("%.9g", (s.mean_kN + hw) * to_unit) << '\n';
  // Event times only: the script places the markers along the bottom of the plot area.
  for (const auto* times : {&ev.split_t, &ev.bend_t}) {
    if (times->empty()) continue;  // an empty block would be an empty plot element (a gnuplot error)
    os << "\n\n";
    for (double te : *times) os << fmt("%.9g", te) << '\n';
  }
  write_file_checked(data.tmp(), os.str(), data.path());
}

// The plot's axes, loads in kN.
struct PlotRange {
  double x_lo = 0;
  double y_lo = 0, y_hi = 0;
  double raw_min = 0;  // the raw series' lowest value (for the note on cut-off spikes)
};

// 6. The axes. Rigid contacts give single-step spikes one or two orders of magnitude above the average; "auto"
// keeps the average readable (top at 3 x its peak, or the raw peak if lower); negative surge loads (ice pushing the
// hull ahead) are brief: shown down to a fifth of the top. Time starts at 0 when the series starts within the
// first 5 % (it starts at the first step's end).
PlotRange plot_range(const std::vector<double>& t, const std::vector<double>& res, const MovingAverage& m,
                     const PlotOptions& o, const SurgeLoadSummary& s) {
  PlotRange p;
  const double ma_max = *std::max_element(m.ma.begin() + static_cast<long>(m.f0), m.ma.begin() + static_cast<long>(m.f1)),
               ma_min = *std::min_element(m.ma.begin() + static_cast<long>(m.f0), m.ma.begin() + static_cast<long>(m.f1));
  p.raw_min = *std::min_element(res.begin(), res.end());
  p.y_hi = o.y_max_kN.is_number() ? o.y_max_kN.get<double>()
                                  : std::max({std::min(s.raw_max_kN, 3.0 * ma_max), 1.25 * s.mean_kN, 1e-3});
  p.y_lo = std::min({0.0, ma_min, std::max(p.raw_min, -0.2 * p.y_hi)});
  p.y_lo -= 0.03 * (p.y_hi - p.y_lo);
  if (!o.y_max_kN.is_number()) p.y_hi += 0.05 * (p.y_hi - p.y_lo);
  p.x_lo = t.front() > 0 && t.front() < 0.05 * t.back() ? 0.0 : t.front();
  return p;
}

// A load given in kN as text in the display unit, with the unit's name.
std::string load_text_in(double x_kN, const ForceUnit& unit) {
  const double to_unit = 1000.0 / unit.newtons;  // kN -> the display unit
  return load_number(x_kN * to_unit) + " " + unit.name;
}

// 6. The script's settings: PNG terminal, labels, grid, key and ranges in the display unit, and a note on how far
// the raw signal goes when the axis cuts it off.
void script_settings(std::ostream& gp, const AtomicFile& png, const PlotOptions& o, const SurgeLoadSummary& s,
                     const std::vector<double>& t, const PlotRange& p, bool marked) {
  const ForceUnit& unit = s.display_unit;
  const double to_unit = 1000.0 / unit.newtons;  // kN -> the display unit
  const double y_lo_u = p.y_lo * to_unit, y_hi_u = p.y_hi * to_unit;  // the axis, in the display unit
  const bool clipped = s.raw_max_kN > p.y_hi || p.raw_min < p.y_lo;
  gp << "set encoding utf8\n"
     << "set terminal pngcairo size " << o.width_px << "," << o.height_px
     << " enhanced font 'DejaVu Sans,11' linewidth 1.0\n"
     << "set output " << quoted(png.tmp().string()) << "\n";
  if (!o.title.empty()) gp << "set title " << quoted(o.title) << " noenhanced font ',14'\n";
  gp << "set xlabel 'Time (s)'\n"
     << "set ylabel 'Ice resistance  −F_x  (" << unit.name << ")'\n"
     << "set border lc rgb '#404040'\n"
     << "set bmargin " << (marked ? 8 : 6) << "\n"
     << "set grid xtics ytics mxtics lc rgb '#d9d9d9' lw 1 dt 1\n"
     << "set mxtics 2\n"
     << "set key outside below center horizontal maxrows " << (marked ? 2 : 1) << " samplen 2.5 width -6\n"
     << "set style textbox opaque fillcolor rgb 'white' border lc rgb '#b0b0b0' margins 4,3\n"
     << "set xrange [" << fmt("%.9g", p.x_lo) << ":" << fmt("%.9g", t.back()) << "]\n"
     << "set yrange [" << fmt("%.9g", y_lo_u) << ":" << fmt("%.9g", y_hi_u) << "]\n"
     << "set format y '%.0f'\n";
  if (y_hi_u - y_lo_u < 10) gp << "set format y '%g'\n";
  if (clipped)
    gp << "set label 1 "
       << quoted("raw signal spans " + load_text_in(p.raw_min, unit) + " to " + load_text_in(s.raw_max_kN, unit) +
                 " (cut off here)")
       << " at graph 0.99, graph 0.96 right boxed noenhanced font ',9' tc rgb '#505050' front\n";
}

// 6. The script's plot command: raw series, moving average, steady mean, and the fracture markers in the margin
// below the lowest data (y_lo lies 3 % under it), in the video's colours: amber triangles for splitting, blue
// diamonds for bending and radial.
void script_plot_command(std::ostream& gp, const AtomicFile& data, const SurgeLoadSummary& s,
                         const std::vector<double>& t, const PlotRange& p, const VesselEvents& ev) {
  const double to_unit = 1000.0 / s.display_unit.newtons;  // kN -> the display unit
  const double y_lo_u = p.y_lo * to_unit, y_hi_u = p.y_hi * to_unit;
  const std::string mean_title =
      (s.steady_start_s > t.front() ? "mean for t ≥ " + fmt("%g", s.steady_start_s) + " s: "
                                    : std::string("mean: ")) +
      load_text_in(s.mean_kN, s.display_unit) +
      (std::isfinite(s.interval.half_width)
           ? " ± " + load_text_in(s.interval.half_width, s.display_unit) + " (95 %, batch means)" +
                 (s.interval.meaningful ? "" : ": the run is too short for the interval")
           : std::string());
  gp << "plot " << quoted(data.tmp().string())
     << " index 0 using 1:2 with lines lc rgb '#a9b8c6' lw 0.8 title "
     << quoted("ice resistance, every time step (Δt = " + fmt("%g", s.time_step_s) + " s)") << " noenhanced, \\\n"
     << "  '' index 1 using 1:2 with lines lc rgb '#101010' lw 2 title "
     << quoted(s.filter + (s.moving_average_complete ? "" : " (longer than the run: cut windows)"))
     << " noenhanced, \\\n"
     << "  '' index 2 using 1:3:4 with filledcurves fc rgb '#d1232a' fs transparent solid 0.18 noborder notitle, \\\n"
     << "  '' index 2 using 1:2 with lines lc rgb '#d1232a' lw 2.5 dt (8,4) title " << quoted(mean_title)
     << " noenhanced";
  const std::string y_mark = fmt("%.9g", y_lo_u + 0.012 * (y_hi_u - y_lo_u));
  auto events_title = [](const char* what, size_t n) {
    return std::string(what) + " at the vessel: " + std::to_string(n) + (n == 1 ? " event" : " events");
  };
  int index = 3;
  if (!ev.split_t.empty())
    gp << ", \\\n  '' index " << index++ << " using 1:(" << y_mark
       << ") with points pt 9 ps 1.5 lc rgb '#e08a00' title "
       << quoted(events_title("fracture by splitting", ev.split_t.size())) << " noenhanced";
  if (!ev.bend_t.empty())
    gp << ", \\\n  '' index " << index++ << " using 1:(" << y_mark
       << ") with points pt 13 ps 1.5 lc rgb '#2f7fc1' title "
       << quoted(events_title("fracture by bending or radial cracking", ev.bend_t.size())) << " noenhanced";
  gp << "\n";
}

// 6. The gnuplot script: the PNG, then the same plot again as SVG.
void write_plot_script(const AtomicFile& script, const AtomicFile& png, const AtomicFile& svg,
                       const AtomicFile& data, const PlotOptions& o, const SurgeLoadSummary& s,
                       const std::vector<double>& t, const PlotRange& p, const VesselEvents& ev) {
  const bool marked = !ev.split_t.empty() || !ev.bend_t.empty();  // two legend rows then
  std::ostringstream gp;
  script_settings(gp, png, o, s, t, p, marked);
  script_plot_command(gp, data, s, t, p, ev);
  gp << "set terminal svg size " << o.width_px << "," << o.height_px
     << " dynamic enhanced font 'DejaVu Sans,11' background rgb 'white'\n"
     << "set output " << quoted(svg.tmp().string()) << "\n"
     << "replot\n"
     << "unset output\n";
  write_file_checked(script.tmp(), gp.str(), script.path());
}

// 8. The numbers of the plot (plot.json), with the provenance.
nlohmann::json plot_numbers(const SurgeLoadSummary& s, const VesselEvents& ev, const nlohmann::json& provenance) {
  return {
      {"series", "ice_load column 0 (Fx, surge, body x)"},
      {"quantity", "ice resistance = -Fx"},
      {"unit", "kN"},
      {"plot_unit", s.display_unit.name},  // the unit of the drawing (N for a tank model, kN for a ship)
      {"contact_model", s.contact_model},
      {"time_step_s", s.time_step_s},
      {"moving_average",
       {{"kind", "centred"},
        {"window_s", s.window_s},
        {"filter", s.filter},
        {"window_samples", s.window_samples},
        {"complete_windows", s.moving_average_complete}}},
      {"steady_start_s", s.steady_start_s},
      {"steady_samples", s.steady_samples},
      {"mean_kN", s.mean_kN},
      {"mean_interval",
       {{"method", "batch means (" + std::to_string(s.interval.batches) + " batches of " +
                       fmt("%g", s.interval.batch_s) + " s), Student t"},
        {"half_width_kN", json_number(s.interval.half_width)},
        {"standard_error_kN", json_number(s.interval.standard_error)},
        {"meaningful", s.interval.meaningful},
        {"note", s.interval.note}}},
      {"moving_average_std_kN", json_number(s.moving_average_std_kN)},
      {"moving_average_max_kN", json_number(s.moving_average_max_kN)},
      {"raw_max_kN", s.raw_max_kN},
      {"fracture",
       {{"events", s.fracture_events},
        {"at_vessel", {{"splitting", ev.split_t.size()}, {"bending_or_radial", ev.bend_t.size()}}},
        {"marked", "events at the vessel (at_structure = 1), along the bottom of the plot"},
        {"csv", "fracture_events.csv: every event; force on the floe in the world frame (N)"}}},
      {"files", {"surge_ice_load.png", "surge_ice_load.svg", "surge_ice_load.csv", "fracture_events.csv"}},
      {"provenance", provenance},
  };
}

}  // namespace

SurgeLoadSummary plot_surge_load(const Results& r, const PlotOptions& o, const fs::path& out_dir,
                                 const nlohmann::json& provenance, const std::string& source) {
  SurgeLoadSummary s;
  // 1. The signal: ice resistance = -Fx (body x, surge) in kN.
  const std::vector<double>& t = r.get("time_s");
  const std::vector<double> res = surge_ice_resistance_kN(r, source);
  s.time_step_s = uniform_step(t, (source + ": series time_s").c_str());

  // 2. The window and the centred moving average.
  const MovingAverage ma = centred_moving_average(r, o, res, source, s);

  // 3. The steady part and its mean (of the unfiltered signal: the primary validation metric).
  steady_statistics(r, o, t, res, ma, source, s);

  // 4. Fracture events (those at the vessel are marked).
  const VesselEvents ev = vessel_fracture_events(r, source, s);

  ensure_directory(out_dir);
  AtomicFile png(out_dir / "surge_ice_load.png"), svg(out_dir / "surge_ice_load.svg"),
      csv(out_dir / "surge_ice_load.csv"), events_csv(out_dir / "fracture_events.csv"), side(out_dir / "plot.json");
  // Working files: AtomicFiles never committed, so they are removed whatever happens.
  AtomicFile data(out_dir / "surge_ice_load.plot-data.txt"), script(out_dir / "surge_ice_load.plot.gp"),
      log(out_dir / "surge_ice_load.gnuplot.log");

  // 5. CSVs: every sample, and every fracture event.
  write_samples_csv(csv, t, res, ma);
  write_events_csv(events_csv, r);

  // 6. Plot data and the script, in the unit that suits the loads' size (N for a tank model, kN for a ship).
  s.display_unit = plot_unit(ma, s.mean_kN);
  write_plot_data(data, t, res, ma, ev, s, 1000.0 / s.display_unit.newtons, static_cast<size_t>(o.width_px));
  write_plot_script(script, png, svg, data, o, s, t, plot_range(t, res, ma, o, s), ev);

  // 7. gnuplot, checked: exit status, and both images non-empty.
  run_gnuplot(script.tmp(), log.tmp(), {png.tmp(), svg.tmp()}, png.path().string());

  // 8. The numbers, then everything into place.
  write_file_checked(side.tmp(), plot_numbers(s, ev, provenance).dump(2) + "\n", side.path());
  png.commit();
  svg.commit();
  csv.commit();
  events_csv.commit();
  side.commit();
  return s;
}

std::vector<std::string> plot_structure_loads(const fs::path& results, const fs::path& config,
                                              const fs::path& out_dir) {
  return plot_structure_loads(read_results(results, /*with_states=*/false), read_plot_options(config), out_dir);
}

SurgeLoadSummary plot_surge_load(const fs::path& results, const fs::path& config, const fs::path& out_dir) {
  const PlotOptions o = read_plot_options(config);
  const Results r = read_results(results, /*with_states=*/false);
  const auto prov = make_provenance("floesim-plot", {{"results", results}, {"config", config}}, options_to_json(o));
  return plot_surge_load(r, o, out_dir, prov, results.string());
}

std::vector<std::string> plot_structure_loads(const Results& r, const PlotOptions& o, const fs::path& out_dir) {
  std::vector<std::string> written;
  const nlohmann::json list = r.attributes.value("structures", nlohmann::json::array());
  if (list.empty()) return written;
  const std::vector<double>& t = r.get("time_s");
  FLOESIM_REQUIRE(t.size() >= 2, "the results hold ", t.size(), " steps; at least 2 are needed for a plot");
  const double dt = t[1] - t[0];
  const size_t nw = window_samples(0.5, dt);  // the compliant contacts' filter (PHYSICS.md 5)
  ensure_directory(out_dir);
  for (const nlohmann::json& st : list) {
    const std::string name = st.at("name").get<std::string>();
    const auto it = r.structure_series.find(name + "/ice_force_n");
    FLOESIM_REQUIRE(it != r.structure_series.end() && it->second.size() == 3 * t.size(), "the results' structure ",
                    name, " has no ice_force_n for every step");
    // 1. The horizontal load along the structure's heading at its station (the ice's action along the drift on a
    // structure facing it) and the vertical load, raw and through the 0.5 s centred moving average.
    const double a = st.value("station_heading_deg", 0.0) * kPi / 180, c = std::cos(a), sn = std::sin(a);
    std::vector<double> h(t.size()), v(t.size());
    double typical = 0;
    for (size_t i = 0; i < t.size(); ++i) {
      h[i] = -(c * it->second[3 * i] + sn * it->second[3 * i + 1]);
      v[i] = it->second[3 * i + 2];
      typical = std::max({typical, std::abs(h[i]), std::abs(v[i])});
    }
    const ForceUnit unit = force_unit_for(typical);
    for (double& x : h) x /= unit.newtons;
    for (double& x : v) x /= unit.newtons;
    // Only the samples whose whole window lies in the run (as the surge load's plot).
    const auto [f0, f1] = full_window_range(t.size(), nw);
    const std::vector<double> hc = moving_average_centred(h, nw), vc = moving_average_centred(v, nw);
    const std::vector<double> hf(hc.begin() + static_cast<long>(f0), hc.begin() + static_cast<long>(f1));
    const std::vector<double> vf(vc.begin() + static_cast<long>(f0), vc.begin() + static_cast<long>(f1));
    // 2. Data and script; gnuplot draws both images.
    const std::string stem = "structure_" + name + "_load";
    AtomicFile png(out_dir / (stem + ".png")), svg(out_dir / (stem + ".svg"));
    AtomicFile data(out_dir / (stem + ".plot-data.txt")), script(out_dir / (stem + ".plot.gp")),
        log(out_dir / (stem + ".gnuplot.log"));
    {
      std::ostringstream os;
      write_decimated(os, t, h, static_cast<size_t>(o.width_px));
      os << "\n\n";
      const std::vector<double> tf(t.begin() + static_cast<long>(f0), t.begin() + static_cast<long>(f1));
      write_decimated(os, tf, hf, static_cast<size_t>(o.width_px));
      os << "\n\n";
      write_decimated(os, tf, vf, static_cast<size_t>(o.width_px));
      write_file_checked(data.tmp(), os.str(), data.path());
    }
    {
      std::ostringstream gp;
      gp << "set encoding utf8\n"
         << "set terminal pngcairo size " << o.width_px << "," << o.height_px
         << " enhanced font 'DejaVu Sans,11' linewidth 1.0\n"
         << "set output " << quoted(png.tmp().string()) << "\n"
         << "set title " << quoted("Ice load on " + name + " (" + st.value("kind", std::string()) + ")")
         << " noenhanced font ',14'\n"
         << "set xlabel 'Time (s)'\nset ylabel 'Load (" << unit.name << ")'\n"
         << "set border lc rgb '#404040'\nset grid xtics ytics lc rgb '#d9d9d9' lw 1 dt 1\n"
         << "set key outside below center horizontal samplen 2.5 width 2\n"
         << "set xrange [" << fmt("%.9g", t.front()) << ":" << fmt("%.9g", t.back()) << "]\n"
         << "plot " << quoted(data.tmp().string())
         << " index 0 using 1:2 with lines lc rgb '#a6c8e6' lw 1 title 'horizontal, each step', \\\n"
         << "  '' index 1 using 1:2 with lines lc rgb '#2f7fc1' lw 2 title 'horizontal, 0.5 s moving average', \\\n"
         << "  '' index 2 using 1:2 with lines lc rgb '#d1232a' lw 1.5 title 'vertical (up), 0.5 s moving average'\n"
         << "set terminal svg size " << o.width_px << "," << o.height_px
         << " dynamic enhanced font 'DejaVu Sans,11' background rgb 'white'\n"
         << "set output " << quoted(svg.tmp().string()) << "\nreplot\nunset output\n";
      write_file_checked(script.tmp(), gp.str(), script.path());
    }
    run_gnuplot(script.tmp(), log.tmp(), {png.tmp(), svg.tmp()}, png.path().string());
    png.commit();
    svg.commit();
    written.push_back(stem);
  }
  return written;
}

IdentifiedPlotSummary plot_identified_load(const fs::path& identify_dir, const PlotOptions& o,
                                           const fs::path& out_dir) {
  // 1. The identification's numbers: its series (resistance = -surge load) and its means.
  const NumericCsv c = read_numeric_csv(identify_dir / "identified.csv", {"time_s", "ice_surge_n"});
  const Json id = load_json_file(identify_dir / "identified.json");
  const std::string idf = (identify_dir / "identified.json").string();
  FLOESIM_REQUIRE(id.contains("mean_surge_ice_resistance_n") && id["mean_surge_ice_resistance_n"].is_number() &&
                      id.contains("mean_window_s") && id["mean_window_s"].is_array() &&
                      id["mean_window_s"].size() == 2,
                  idf, ": no mean_surge_ice_resistance_n or mean_window_s: rerun floesim-identify");
  IdentifiedPlotSummary s;
  const std::vector<double>& t = c.column("time_s");
  FLOESIM_REQUIRE(t.size() >= 2, c.file.string(), ": ", t.size(), " rows; at least 2 are needed for a plot");
  s.samples = t.size();
  s.known = c.has("known_ice_surge_n") && id.contains("known_load");
  s.mean_identified_kN = id["mean_surge_ice_resistance_n"].get<double>() / 1000;
  if (s.known) s.mean_known_kN = id["known_load"].value("mean_surge_ice_resistance_n", NAN) / 1000;
  const double w0 = id["mean_window_s"][0].get<double>(), w1 = id["mean_window_s"][1].get<double>();
  // Drawn in the unit that suits the loads' size (N for a tank model, kN for a ship), as the load plot is.
  double typical_n = 1000.0 * std::abs(s.mean_identified_kN);
  for (double x : c.column("ice_surge_n")) typical_n = std::max(typical_n, std::abs(x));
  const ForceUnit unit = force_unit_for(typical_n);
  const double to_unit = 1000.0 / unit.newtons;  // kN -> the display unit
  auto resistance = [&](const std::vector<double>& surge_n) {
    std::vector<double> r(surge_n.size());
    for (size_t i = 0; i < r.size(); ++i) r[i] = -surge_n[i] / unit.newtons;
    return r;
  };
  const std::vector<double> ident = resistance(c.column("ice_surge_n"));
  const std::vector<double> known = s.known ? resistance(c.column("known_ice_surge_n")) : std::vector<double>();
  auto load = [&](double x_kN) { return load_number(x_kN * to_unit) + " " + unit.name; };
  const double step = t[1] - t[0];

  // 2. Data and script; gnuplot draws both images.
  ensure_directory(out_dir);
  AtomicFile png(out_dir / "identified_load.png"), svg(out_dir / "identified_load.svg");
  AtomicFile data(out_dir / "identified_load.plot-data.txt"), script(out_dir / "identified_load.plot.gp"),
      log(out_dir / "identified_load.gnuplot.log");
  {
    std::ostringstream os;
    for (size_t i = 0; i < t.size(); ++i)
      os << fmt("%.9g", t[i]) << ' ' << fmt("%.9g", ident[i]) << ' '
         << (s.known ? fmt("%.9g", known[i]) : std::string("NaN")) << '\n';
    os << "\n\n"
       << fmt("%.9g", std::max(w0, t.front())) << ' ' << fmt("%.9g", s.mean_identified_kN * to_unit) << ' '
       << fmt("%.9g", s.mean_known_kN * to_unit) << '\n'
       << fmt("%.9g", std::min(w1, t.back())) << ' ' << fmt("%.9g", s.mean_identified_kN * to_unit) << ' '
       << fmt("%.9g", s.mean_known_kN * to_unit) << '\n';
    write_file_checked(data.tmp(), os.str(), data.path());
  }
  double lo = 0, hi = 0;
  for (double x : ident) lo = std::min(lo, x), hi = std::max(hi, x);
  for (double x : known) lo = std::min(lo, x), hi = std::max(hi, x);
  if (o.y_max_kN.is_number()) hi = o.y_max_kN.get<double>() * to_unit;
  const double pad = 0.05 * std::max(hi - lo, 1e-3);
  {
    std::ostringstream gp;
    gp << "set encoding utf8\n"
       << "set terminal pngcairo size " << o.width_px << "," << o.height_px
       << " enhanced font 'DejaVu Sans,11' linewidth 1.0\n"
       << "set output " << quoted(png.tmp().string()) << "\n"
       << "set title " << quoted("Surge ice load identified from the ship's data") << " noenhanced font ',14'\n"
       << "set xlabel 'Time (s)'\nset ylabel 'Ice resistance  −F_x  (" << unit.name << ")'\n"
       << "set border lc rgb '#404040'\nset grid xtics ytics lc rgb '#d9d9d9' lw 1 dt 1\n"
       << "set key outside below center horizontal maxrows 2 samplen 2.5 width 2\n"
       << "set xrange [" << fmt("%.9g", t.front()) << ":" << fmt("%.9g", t.back()) << "]\n"
       << "set yrange [" << fmt("%.9g", lo - pad) << ":" << fmt("%.9g", hi + pad) << "]\n";
    const std::string rate = fmt("%g", step) + " s means";
    gp << "plot " << quoted(data.tmp().string()) << " index 0 using 1:2 with lines lc rgb '#2f7fc1' lw 1.2 title "
       << quoted("identified (" + rate + ")") << " noenhanced";
    if (s.known)
      gp << ", \\\n  '' index 0 using 1:3 with lines lc rgb '#101010' lw 1.2 title "
         << quoted("simulated, the same " + rate) << " noenhanced";
    gp << ", \\\n  '' index 1 using 1:2 with lines lc rgb '#2f7fc1' lw 2.5 dt (8,4) title "
       << quoted("identified mean: " + load(s.mean_identified_kN)) << " noenhanced";
    if (s.known)
      gp << ", \\\n  '' index 1 using 1:3 with lines lc rgb '#d1232a' lw 2.5 dt (8,4) title "
         << quoted("simulated mean: " + load(s.mean_known_kN)) << " noenhanced";
    gp << "\nset terminal svg size " << o.width_px << "," << o.height_px
       << " dynamic enhanced font 'DejaVu Sans,11' background rgb 'white'\n"
       << "set output " << quoted(svg.tmp().string()) << "\nreplot\nunset output\n";
    std::ostringstream os;
    os << gp.str();
    write_file_checked(script.tmp(), os.str(), script.path());
  }
  run_gnuplot(script.tmp(), log.tmp(), {png.tmp(), svg.tmp()}, png.path().string());
  png.commit();
  svg.commit();
  return s;
}

}  // namespace floesim::render
