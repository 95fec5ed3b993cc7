// floesim-render: results HDF5 -> H.264 MP4 of the transit (off-screen OSMesa), plus a JSON sidecar.
#include <iostream>

#include "pipeline/options_describe.h"
#include "pipeline/stage_main.h"
#include "render/video.h"

int main(int argc, char** argv) {
  CLI::App app{"Render a simulated transit (results HDF5) to an H.264 MP4, one video frame per results frame",
               "floesim-render"};
  std::string results, config, out;
  bool check_config = false;
  long still = -1;
  app.add_option("--results", results, "simulation results (HDF5, from floesim-simulate)");
  app.add_option("--config", config, "render options (JSON; see --help-config)")->required();
  app.add_flag("--check-config", check_config, "read and check --config (strictly, as a run would), write nothing");
  app.add_option("--out", out, "video to write (.mp4); with --still-frame an image (.png)");
  app.add_option("--still-frame", still, "write only this frame (0-based) as an image to --out")->check(CLI::NonNegativeNumber);
  app.add_flag_callback("--help-config", [] {
    std::cout << floesim::options_doc(floesim::render::RenderOptions{});
    throw CLI::Success();
  }, "print the render options (key, default, unit, meaning) and exit");
  floesim::add_describe_config(app, [] { return floesim::options_description(floesim::render::RenderOptions{}); });
  return floesim::run_stage(app, argc, argv, [&] {
    if (check_config) {
      floesim::render::read_render_options(config);
      return;
    }
    if (results.empty() || out.empty()) throw floesim::Error("--results and --out are required (see --help)");
    if (still >= 0) {
      floesim::render::render_still(results, config, static_cast<size_t>(still), out);
      std::cout << "wrote frame " << still << " to " << out << "\n";
      return;
    }
    const auto st = floesim::render::render_video(results, config, out, &std::cout);
    std::cout << "wrote " << out << ": " << st.frames << " frames; " << st.render_ms_per_frame
              << " ms/frame rendering + " << st.encode_ms_per_frame << " ms/frame encoding; "
              << st.floes_drawn_per_frame << " floes drawn, " << st.floes_culled_per_frame
              << " culled per frame (" << st.gl_renderer << ")\n";
  });
}
