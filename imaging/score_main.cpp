// floesim-score: a label image against a hand-labelled floe mask (or truth labels), with the protocol of score.h.
#include <iostream>

#include "imaging/score.h"
#include "pipeline/error.h"
#include "pipeline/stage_main.h"

int main(int argc, char** argv) {
  using namespace floesim;
  CLI::App app{
      "floesim-score: score a floe label image against a labelled mask (truth floes = 8-connected components; "
      "floes < --min-area-m2 left out of matching; floes touching the image edge or the no-data area dropped from "
      "both sides; one-to-one greedy IoU matching)"};
  app.name("floesim-score");
  imaging::ScoreRequest req;
  std::string labels, truth, photo, out;
  bool keep_edge = false;
  app.add_option("LABELS", labels, "predicted labels: 16-bit label PNG (0 = no floe, e.g. digitise's labels.png) or an 8-bit floe mask");
  app.add_option("--truth", truth, "truth: 8-bit floe mask (floes = 8-connected components) or 16-bit labels");
  app.add_option("--photo", photo, "the photograph (its pure-black pixels are the no-data area)");
  app.add_option("--metres-per-pixel", req.metres_per_pixel, "ground size of one pixel (m)");
  app.add_option("--out", out, "score.json to write (default: print only)");
  app.add_option("--min-area-m2", req.options.min_area_m2, "floes below this are left out of matching (default 1)");
  app.add_option("--min-iou", req.options.min_iou, "least IoU of a match (default 0.5)");
  app.add_flag("--keep-edge-floes", keep_edge, "do not drop floes touching the image edge or the no-data area");
  return run_stage(app, argc, argv, [&] {
    FLOESIM_REQUIRE(!labels.empty(), "LABELS is required (the label image to score)");
    FLOESIM_REQUIRE(!truth.empty(), "--truth is required (the labelled mask)");
    FLOESIM_REQUIRE(app.count("--metres-per-pixel") == 1,
                    "--metres-per-pixel is required (the ground size of one pixel in metres)");
    req.labels = labels;
    req.truth = truth;
    req.photo = photo;
    req.out = out;
    req.options.drop_edge_floes = !keep_edge;
    const imaging::ScoreResult r = imaging::run_score(req);
    std::cout << r.to_json().dump(1) << "\n";
  });
}
