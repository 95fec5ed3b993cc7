// floesim-digitise: photograph + pixel scale -> floe polygons (GeoJSON), labels, overlay and statistics.
#include <chrono>
#include <iostream>

#include "imaging/digitise.h"
#include "pipeline/options_describe.h"
#include "pipeline/stage_main.h"

int main(int argc, char** argv) {
  using namespace floesim;
  CLI::App app{"floesim-digitise: segment the floes of an 8-bit grayscale photograph into polygons in metres"};
  app.name("floesim-digitise");
  imaging::DigitiseRequest req;
  std::string image, out, config, truth, truth_mask;
  double s = 0;
  bool check_config = false;
  app.add_option("IMAGE", image, "8-bit grayscale image (pure black = no data)");
  app.add_option("--metres-per-pixel", s, "ground size of one pixel (m)");
  app.add_option("--out", out, "output directory (floes.geojson, labels.png, overlay.png, stats.json)");
  app.add_option("--config", config, "JSON object of digitise options (see --help-config)");
  app.add_option("--truth", truth, "known floes (GeoJSON, e.g. floesim-synth's truth.geojson): writes score.json");
  app.add_option("--truth-mask", truth_mask,
                 "hand-labelled floe mask on the image's grid (floes = 8-connected components; or 16-bit truth "
                 "labels): writes score.json with the labelled-mask protocol (floes >= 1 m^2, edge floes dropped)");
  app.add_flag("--check-config", check_config, "read and check --config (strictly, as a run would), write nothing");
  app.add_flag_callback(
      "--help-config",
      [] {
        std::cout << options_doc(imaging::DigitiseOptions{});
        throw CLI::Success();
      },
      "print the options table and exit");
  add_describe_config(app, [] { return options_description(imaging::DigitiseOptions{}); });
  return run_stage(app, argc, argv, [&] {
    if (check_config) {
      FLOESIM_REQUIRE(!config.empty(), "--check-config needs --config FILE");
      read_options<imaging::DigitiseOptions>(load_json_file(config), config);
      return;
    }
    FLOESIM_REQUIRE(!image.empty(), "IMAGE is required (the photograph to digitise)");
    FLOESIM_REQUIRE(app.count("--metres-per-pixel") == 1,
                    "--metres-per-pixel is required (the ground size of one pixel in metres)");
    FLOESIM_REQUIRE(!out.empty(), "--out DIR is required (the directory that receives the floes)");
    req.image = image;
    req.metres_per_pixel = s;
    req.out_dir = out;
    req.truth = truth;
    req.truth_mask = truth_mask;
    if (!config.empty()) {
      req.config_file = config;
      req.config = load_json_file(config);
    }
    const auto t0 = std::chrono::steady_clock::now();
    const auto res = imaging::run_digitise(req);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (const auto& w : res.warnings) std::cerr << "floesim-digitise: warning: " << w << "\n";
    std::cout << "floesim-digitise: " << res.floes.floes.size() << " floes, ice concentration "
              << res.stats["ice_concentration"].get<double>() << " (" << secs << " s) -> " << out << "\n";
    if (res.score)
      std::cout << "floesim-digitise: against the truth: F1 " << res.score->f1 << ", precision " << res.score->precision
                << ", recall " << res.score->recall << ", mean IoU " << res.score->mean_iou << ", pixel IoU "
                << res.score->pixel_iou << ", concentration error " << res.score->concentration_error
                << ", KS(log area) " << res.score->ks_log_area << "\n";
  });
}
