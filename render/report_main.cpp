// floesim-report: a run folder (as `floesim run` writes it) -> one self-contained HTML page: the case, the input
// and digitised field, the hull, the load plot, mean loads against references, fracture statistics, the video and
// the settings.
#include <iostream>

#include "pipeline/options_describe.h"
#include "pipeline/stage_main.h"
#include "render/report.h"

int main(int argc, char** argv) {
  CLI::App app{"Write one self-contained HTML report (images and video inlined) for a run folder",
               "floesim-report"};
  std::string run, sweep, config, out;
  bool check_config = false;
  app.add_option("--run", run, "run folder (the --out of `floesim run`)");
  app.add_option("--sweep", sweep, "or a sweep folder (the --out of `floesim sweep`, gathered): the sweep's report");
  app.add_option("--config", config, "report options (JSON; see --help-config); default: no reference value");
  app.add_flag("--check-config", check_config, "read and check --config (strictly), write nothing");
  app.add_option("--out", out, "the HTML file to write");
  app.add_flag_callback("--help-config", [] {
    std::cout << floesim::options_doc(floesim::render::ReportOptions{});
    throw CLI::Success();
  }, "print the report options (key, default, unit, meaning) and exit");
  floesim::add_describe_config(app, [] { return floesim::options_description(floesim::render::ReportOptions{}); });
  return floesim::run_stage(app, argc, argv, [&] {
    if (check_config) {
      if (config.empty()) throw floesim::Error("--check-config needs --config FILE");
      floesim::render::read_report_options(config);
      return;
    }
    if (run.empty() == sweep.empty() || out.empty())
      throw floesim::Error("give --out and one of --run (a run folder) or --sweep (a sweep folder) (see --help)");
    if (!sweep.empty()) {
      const floesim::render::ReportOptions o =
          config.empty() ? floesim::render::ReportOptions{} : floesim::render::read_report_options(config);
      const auto s = floesim::render::write_sweep_report(sweep, o, out, floesim::options_to_json(o));
      std::cout << "wrote " << out << " (" << s.bytes / 1000 << " kB): " << s.grid_points << " grid point(s), "
                << s.members << " member(s), " << s.failed << " failed\n";
      for (const auto& m : s.missing) std::cout << "  missing: " << m << "\n";
      return;
    }
    const auto s = floesim::render::write_report(run, config, out);
    const double mean_kN = s.mean_kN == 0 ? 0.0 : s.mean_kN;  // -0 (no contact at all) prints as 0
    std::cout << "wrote " << out << " (" << s.bytes / 1000 << " kB): mean ice resistance " << mean_kN << " kN";
    for (const auto& r : s.references)
      std::cout << "; " << r.label << " " << r.reference_kN << " kN: error " << r.error_kN << " kN ("
                << r.error_percent << " %)";
    std::cout << "; video " << (s.video_embedded ? "embedded" : "not embedded") << "\n";
    if (!s.missing.empty()) {
      std::cout << "missing from the run (" << s.missing.size() << "):\n";
      for (const auto& m : s.missing) std::cout << "  " << m << "\n";
    }
  });
}
