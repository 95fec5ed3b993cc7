#include "render/sweep_plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <set>
#include <sstream>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/units.h"
#include "render/gnuplot.h"

namespace floesim::render {

namespace fs = std::filesystem;
using namespace floesim::sweep;

namespace {

// A file name part from a key: "simulate.vessel.y_m" -> "simulate_vessel_y_m".
std::string file_part(const std::string& key) {
  std::string s = key;
  for (char& ch : s)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-')) ch = '_';
  return s;
}

const char* const kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
const char* colour(size_t i) { return kColours[i % (sizeof kColours / sizeof *kColours)]; }

// One plot's files: the images (committed with the rest) and its working files (never committed, so removed).
struct PlotFiles {
  PlotFiles(const fs::path& dir, const std::string& stem)
      : png(dir / (stem + ".png")),
        svg(dir / (stem + ".svg")),
        data(dir / (stem + ".plot-data.txt")),
        script(dir / (stem + ".plot.gp")),
        log(dir / (stem + ".gnuplot.log")),
        stem(stem) {}
  AtomicFile png, svg, data, script, log;
  std::string stem;

  // The terminal lines around `body` (the set-up and the plot command), PNG then the same plot as SVG.
  void draw(const std::string& body, const std::string& data_text) {
    write_text_atomic_tmp(data, data_text);
    std::ostringstream gp;
    gp << "set encoding utf8\n"
       << "set terminal pngcairo size 1100,700 enhanced font 'DejaVu Sans,11' linewidth 1.0\n"
       << "set output " << gnuplot_quoted(png.tmp().string()) << "\n"
       << "set border lc rgb '#404040'\n"
       << "set grid xtics ytics lc rgb '#d9d9d9' lw 1 dt 1\n"
       << "set key outside below center horizontal samplen 2.5\n"
       << "set style textbox opaque fillcolor rgb 'white' border lc rgb '#b0b0b0' margins 4,3\n"
       << "data = " << gnuplot_quoted(data.tmp().string()) << "\n"
       << body << "\n"
       << "set terminal svg size 1100,700 dynamic enhanced font 'DejaVu Sans,11' background rgb 'white'\n"
       << "set output " << gnuplot_quoted(svg.tmp().string()) << "\n"
       << "replot\n"
       << "unset output\n";
    write_text_atomic_tmp(script, gp.str());
    run_gnuplot(script.tmp(), log.tmp(), {png.tmp(), svg.tmp()}, png.path().string());
  }
  static void write_text_atomic_tmp(const AtomicFile& f, const std::string& text) {
    write_file_checked(f.tmp(), text, f.path());
  }
};

// The plots' load unit (pipeline/units.h: N for a sweep of tank models, kN for ships) from the members' means, in
// kN; and the factor from kN to it.
ForceUnit plot_unit(const GatherResult& g, double* kN_to_unit) {
  double typical_kN = 0;
  for (const MemberResult& m : g.members)
    if (m.ok && std::isfinite(m.mean_resistance_kN)) typical_kN = std::max(typical_kN, std::abs(m.mean_resistance_kN));
  const ForceUnit u = force_unit_for(1000.0 * typical_kN);
  *kN_to_unit = 1000.0 / u.newtons;
  return u;
}

// Mean resistance against axis k: a line per combination of the other axes' values, 95 % CI error bars, the
// members as open circles. Non-numeric axes are categories, placed in the plan's order.
void draw_axis_plot(const SweepPlan& plan, const GatherResult& g, size_t k, PlotFiles& f) {
  const PlanAxis& ax = plan.axes[k];
  const bool numeric = std::all_of(ax.values.begin(), ax.values.end(), [](const Json& v) { return v.is_number(); });
  auto x_of = [&](const Json& v) {
    return numeric ? v.get<double>()
                   : static_cast<double>(std::find(ax.values.begin(), ax.values.end(), v) - ax.values.begin());
  };
  // 1. Lines: grid points grouped by their other axes' values, in order of first appearance.
  std::vector<std::string> labels;
  std::vector<std::vector<size_t>> lines;
  for (const GridPointResult& gp : g.grid_points) {
    std::string label;
    for (size_t a = 0; a < plan.axes.size(); ++a)
      if (a != k)
        label += (label.empty() ? "" : ", ") + axis_title(plan.axes[a]) + " = " + value_text(gp.axes[plan.axes[a].key]);
    if (label.empty()) label = "ensemble mean";
    const size_t i = std::find(labels.begin(), labels.end(), label) - labels.begin();
    if (i == labels.size()) labels.push_back(label), lines.emplace_back();
    lines[i].push_back(gp.index);
  }
  // 2. Data: per line, a block of (x, mean, low, high) sorted by x, then a block of its members (x, mean). A grid
  // point of one ok member has that member's batch-means interval; one without ok members is left out.
  double to_unit = 1;
  const ForceUnit unit = plot_unit(g, &to_unit);
  std::ostringstream data, plot;
  int block = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    std::vector<const GridPointResult*> pts;
    for (size_t gi : lines[i])
      if (g.grid_points[gi].ci.n > 0) pts.push_back(&g.grid_points[gi]);
    if (pts.empty()) continue;
    std::sort(pts.begin(), pts.end(),
              [&](auto* a, auto* b) { return x_of(a->axes[ax.key]) < x_of(b->axes[ax.key]); });
    if (block > 0) data << "\n\n";
    for (const GridPointResult* p : pts) {
      const double hw = std::isfinite(p->half_width_kN) ? p->half_width_kN : 0.0;
      data << fmt("%.10g", x_of(p->axes[ax.key])) << ' ' << fmt("%.10g", to_unit * p->ci.mean) << ' '
           << fmt("%.10g", to_unit * (p->ci.mean - hw)) << ' ' << fmt("%.10g", to_unit * (p->ci.mean + hw)) << '\n';
    }
    data << "\n\n";
    for (const GridPointResult* p : pts)
      for (const MemberResult& m : g.members)
        if (m.ok && m.grid_point == p->index)
          data << fmt("%.10g", x_of(p->axes[ax.key])) << ' ' << fmt("%.10g", to_unit * m.mean_resistance_kN) << '\n';
    plot << (block == 0 ? "plot data" : ", \\\n  data") << " index " << block
         << " using 1:2:3:4 with yerrorlines lc rgb '" << colour(i) << "' lw 2 pt 7 ps 1.2 title "
         << gnuplot_quoted(labels[i]) << " noenhanced, \\\n  data index " << block + 1
         << " using 1:2 with points lc rgb '" << colour(i) << "' pt 6 ps 0.8 notitle";
    block += 2;
  }
  plot << ", \\\n  NaN with points lc rgb '#606060' pt 6 ps 0.8 title 'members'";
  // 3. Axes: a tic at every value of the axis, labelled as in the plan.
  double lo = 0, hi = static_cast<double>(ax.values.size()) - 1;
  if (numeric) {
    lo = hi = ax.values.front().get<double>();
    for (const Json& v : ax.values) lo = std::min(lo, v.get<double>()), hi = std::max(hi, v.get<double>());
  }
  const double pad = hi > lo ? 0.08 * (hi - lo) : std::max(0.5, 0.1 * std::abs(lo));
  std::string tics;
  for (const Json& v : ax.values)
    tics += (tics.empty() ? "" : ", ") + gnuplot_quoted(value_text(v)) + " " + fmt("%.10g", x_of(v));
  std::ostringstream body;
  body << "set title " << gnuplot_quoted(plan.name + ": ice resistance against " + axis_title(ax))
       << " noenhanced font ',14'\n"
       << "set xlabel " << gnuplot_quoted(axis_title(ax)) << " noenhanced\n"
       << "set ylabel 'Mean ice resistance (" << unit.name << "): ensemble mean and 95 % confidence interval'\n"
       << "set xtics (" << tics << ") noenhanced\n"
       << "set xrange [" << fmt("%.10g", lo - pad) << ":" << fmt("%.10g", hi + pad) << "]\n"
       << "set yrange [*:*]\n"
       << plot.str();
  f.draw(body.str(), data.str());
}

// Level ice: each member's mean resistance with its 95 % interval (batch means, Student t with batches - 1 degrees
// of freedom) against its mean speed, a colour per sheet thickness (the axis "simulate.level_ice.thickness_m" if the sweep has it, else
// one colour), with Lindqvist (solid) and Riska (dashed) at the same speeds.
void draw_level_ice_plot(const SweepPlan& plan, const GatherResult& g, PlotFiles& f) {
  const std::string hkey = "simulate.level_ice.thickness_m";
  std::vector<std::string> groups;
  std::vector<std::vector<const MemberResult*>> members;
  for (size_t i = 0; i < g.members.size(); ++i) {
    const MemberResult& m = g.members[i];
    if (!m.ok || !m.level_ice) continue;
    const Json& axes = plan.members[i].axes;
    const std::string label = axes.contains(hkey) ? "h = " + value_text(axes[hkey]) + " m" : "level ice";
    const size_t k = std::find(groups.begin(), groups.end(), label) - groups.begin();
    if (k == groups.size()) groups.push_back(label), members.emplace_back();
    members[k].push_back(&m);
  }
  double to_unit = 1;
  const ForceUnit unit = plot_unit(g, &to_unit);
  std::ostringstream data, plot;
  for (size_t k = 0; k < groups.size(); ++k) {
    std::sort(members[k].begin(), members[k].end(),
              [](auto* a, auto* b) { return a->mean_speed_mps < b->mean_speed_mps; });
    if (k > 0) data << "\n\n";
    for (const MemberResult* m : members[k]) {
      const double hw = m->series.interval.half_width;
      data << fmt("%.10g", m->mean_speed_mps) << ' ' << fmt("%.10g", to_unit * m->mean_resistance_kN) << ' '
           << fmt("%.10g", to_unit * (m->mean_resistance_kN - hw)) << ' '
           << fmt("%.10g", to_unit * (m->mean_resistance_kN + hw)) << ' ' << fmt("%.10g", to_unit * m->lindqvist_kN)
           << ' ' << fmt("%.10g", to_unit * m->riska_kN) << '\n';
    }
    plot << (k == 0 ? "plot data" : ", \\\n  data") << " index " << k << " using 1:2:3:4 with yerrorlines lc rgb '"
         << colour(k) << "' lw 2 pt 7 ps 1.2 title " << gnuplot_quoted("simulated, " + groups[k])
         << ", \\\n  data index " << k << " using 1:5 with lines lc rgb '" << colour(k)
         << "' lw 1.5 dt 1 title 'Lindqvist', \\\n  data index " << k << " using 1:6 with lines lc rgb '"
         << colour(k) << "' lw 1.5 dt 2 title 'Riska'";
  }
  std::ostringstream body;
  body << "set title " << gnuplot_quoted(plan.name + ": level-ice resistance against Lindqvist and Riska")
       << " noenhanced font ',14'\n"
       << "set xlabel 'Mean speed (m/s)'\n"
       << "set ylabel 'Mean ice resistance (" << unit.name << "), 95 % interval (batch means)'\n"
       << "set xrange [0:*]\nset yrange [0:*]\n"
       << plot.str();
  f.draw(body.str(), data.str());
}

// A pure ensemble: each member's mean resistance, and the ensemble mean with its 95 % interval as a band.
void draw_ensemble_plot(const SweepPlan& plan, const GatherResult& g, PlotFiles& f) {
  const ConfidenceInterval& ci = g.grid_points.front().ci;
  double to_unit = 1;
  const ForceUnit unit = plot_unit(g, &to_unit);
  double x0 = 1e300, x1 = -1e300;
  std::ostringstream data;
  for (const MemberResult& m : g.members)
    if (m.ok) {
      const double x = static_cast<double>(m.ensemble_index);
      x0 = std::min(x0, x), x1 = std::max(x1, x);
      data << fmt("%.10g", x) << ' ' << fmt("%.10g", to_unit * m.mean_resistance_kN) << '\n';
    }
  const double hw = ci.n >= 2 ? ci.half_width : 0.0;
  data << "\n\n";
  for (double x : {x0 - 0.5, x1 + 0.5})
    data << fmt("%.10g", x) << ' ' << fmt("%.10g", to_unit * ci.mean) << ' ' << fmt("%.10g", to_unit * (ci.mean - hw)) << ' '
         << fmt("%.10g", to_unit * (ci.mean + hw)) << '\n';
  std::ostringstream body;
  body << "set title " << gnuplot_quoted(plan.name + ": mean ice resistance of each ensemble member")
       << " noenhanced font ',14'\n"
       << "set xlabel 'Ensemble member (index)'\n"
       << "set ylabel 'Mean ice resistance (" << unit.name << ")'\n"
       << "set xrange [" << fmt("%.10g", x0 - 0.7) << ":" << fmt("%.10g", x1 + 0.7) << "]\n"
       << (x1 - x0 <= 30 ? "set xtics 1\n" : "");
  body << "plot ";
  if (ci.n >= 2)
    body << "data index 1 using 1:3:4 with filledcurves lc rgb '#c6dbef' fs solid 0.6 noborder title "
         << gnuplot_quoted("95 % interval of the ensemble mean (Student t, " + std::to_string(ci.n) + " members)")
         << ", \\\n  ";
  body << "data index 1 using 1:2 with lines lc rgb '#d1232a' lw 2.5 dt (8,4) title "
       << gnuplot_quoted("ensemble mean: " + ci_text(ci, to_unit) + " " + unit.name) << " noenhanced, \\\n"
       << "  data index 0 using 1:2 with points lc rgb '#1f77b4' pt 7 ps 1.3 title 'members'";
  f.draw(body.str(), data.str());
}

// The running mean of one member from the steady start, with the final mean +- 2 batch-means standard errors:
// if the curve is still leaving the band near the end, the run was too short for its mean.
void draw_running_mean(const MemberResult& m, const SteadyResistance& s, PlotFiles& f) {
  // In the unit that suits the member's mean (N for a tank model, kN for a ship).
  const ForceUnit unit = force_unit_for(1000.0 * m.series.mean_kN);
  const double to_unit = 1000.0 / unit.newtons;
  std::vector<double> rm = running_mean(s.resistance_kN);
  for (double& v : rm) v *= to_unit;
  const size_t n = rm.size();
  const double mean = to_unit * m.series.mean_kN, se = to_unit * m.series.batch_means_se_kN;
  const bool band = std::isfinite(se);
  // For the drawing only: a few thousand points show a running mean (it is smooth once past its first samples).
  const size_t stride = std::max<size_t>(1, n / 4000);
  std::ostringstream data;
  for (size_t i = 0; i < n; i += stride) data << fmt("%.10g", s.time_s[i]) << ' ' << fmt("%.10g", rm[i]) << '\n';
  if ((n - 1) % stride != 0) data << fmt("%.10g", s.time_s[n - 1]) << ' ' << fmt("%.10g", rm[n - 1]) << '\n';
  data << "\n\n";
  const double lo = band ? mean - 2 * se : mean, hi = band ? mean + 2 * se : mean;
  for (double t : {s.time_s.front(), s.time_s.back()})
    data << fmt("%.10g", t) << ' ' << fmt("%.10g", mean) << ' ' << fmt("%.10g", lo) << ' ' << fmt("%.10g", hi)
         << '\n';
  // The first samples of a running mean swing widely (one spike is the whole mean at first): the y range covers
  // the curve from a tenth of the steady part on, and the band, so the end, which decides, stays readable.
  double y0 = lo, y1 = hi;
  for (size_t i = n / 10; i < n; ++i) y0 = std::min(y0, rm[i]), y1 = std::max(y1, rm[i]);
  const double pad = std::max(0.15 * (y1 - y0), 1e-3 * std::max(1.0, std::abs(mean)));
  bool clipped = false;
  for (size_t i = 0; i < n / 10; ++i) clipped = clipped || rm[i] < y0 - pad || rm[i] > y1 + pad;
  std::ostringstream body;
  body << "set title " << gnuplot_quoted("Running mean of the ice resistance: " + m.id) << " noenhanced font ',14'\n"
       << "set xlabel 'Time (s)'\n"
       << "set ylabel 'Running mean of the ice resistance −F_x (" << unit.name << ")'\n"
       << "set xrange [" << fmt("%.10g", s.time_s.front()) << ":"
       << fmt("%.10g", std::max(s.time_s.back(), s.time_s.front() + s.time_step_s)) << "]\n"
       << "set yrange [" << fmt("%.10g", y0 - pad) << ":" << fmt("%.10g", y1 + pad) << "]\n";
  if (clipped)
    body << "set label 1 'the first samples of the running mean are off the scale' at graph 0.99, graph 0.96 right "
            "boxed noenhanced font ',9' tc rgb '#505050' front\n";
  body << "plot ";
  if (band)
    body << "data index 1 using 1:3:4 with filledcurves lc rgb '#c6dbef' fs solid 0.6 noborder title "
         << gnuplot_quoted("final mean ± 2 standard errors (batch means, " + std::to_string(m.series.batches) +
                           " batches): " + fmt("%.4g", mean) + " ± " + fmt("%.3g", 2 * se) + " " + unit.name)
         << " noenhanced, \\\n  ";
  body << "data index 1 using 1:2 with lines lc rgb '#d1232a' lw 2 dt (8,4) title "
       << gnuplot_quoted("final mean: " + fmt("%.4g", mean) + " " + unit.name) << " noenhanced, \\\n"
       << "  data index 0 using 1:2 with lines lc rgb '#101010' lw 2 title "
       << gnuplot_quoted("running mean from the steady start, t ≥ " + fmt("%g", s.steady_start_s) + " s")
       << " noenhanced";
  f.draw(body.str(), data.str());
}

}  // namespace

GatherResult gather_sweep(const SweepPlan& plan, const fs::path& plan_file, const fs::path& out_dir) {
  // 1. The members and the statistics per grid point (pipeline/sweep/gather.h).
  GatherResult g = gather_members(plan);
  ensure_directory(out_dir);
  // 2. Plots (they need an ok member), each checked.
  std::vector<std::unique_ptr<PlotFiles>> plots;
  if (g.first_ok >= 0) {
    if (plan.axes.empty()) {
      plots.push_back(std::make_unique<PlotFiles>(out_dir, "ensemble"));
      draw_ensemble_plot(plan, g, *plots.back());
    }
    std::set<std::string> stems;
    for (size_t k = 0; k < plan.axes.size(); ++k) {
      std::string stem = "resistance_vs_" + file_part(plan.axes[k].key);
      if (!stems.insert(stem).second) stem += "_" + std::to_string(k);  // two keys that differ only in punctuation
      plots.push_back(std::make_unique<PlotFiles>(out_dir, stem));
      draw_axis_plot(plan, g, k, *plots.back());
    }
    if (g.level_ice) {
      plots.push_back(std::make_unique<PlotFiles>(out_dir, "level_ice_resistance"));
      draw_level_ice_plot(plan, g, *plots.back());
    }
    plots.push_back(std::make_unique<PlotFiles>(out_dir, "running_mean"));
    draw_running_mean(g.members[g.first_ok], g.first_series, *plots.back());
  }
  g.files = {"sweep.csv", "sweep.json"};
  for (const auto& p : plots) g.files.insert(g.files.end(), {p->stem + ".png", p->stem + ".svg"});

  // 3. The tables; then everything into place together.
  const SweepTables tables = sweep_tables(plan, plan_file, g);
  AtomicFile csv_file(out_dir / "sweep.csv"), json_file(out_dir / "sweep.json");
  PlotFiles::write_text_atomic_tmp(csv_file, tables.csv);
  PlotFiles::write_text_atomic_tmp(json_file, tables.json);
  csv_file.commit();
  json_file.commit();
  for (auto& p : plots) p->png.commit(), p->svg.commit();
  return g;
}


GatherResult gather_sweep(const fs::path& plan_file, const fs::path& out_dir) {
  return gather_sweep(read_sweep_plan(plan_file), plan_file, out_dir);
}

}  // namespace floesim::render
