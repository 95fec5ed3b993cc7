// Digitise: helicopter (or ship-borne orthorectified) photograph + pixel scale -> floe polygons in metres.
//
// Artefacts in the output directory, each written atomically and only after every input was accepted:
//   floes.geojson  Polygon features in metres (x right, y up, origin bottom-left); properties id, area_m2,
//                  thickness_m; the field extent and provenance (program, version, input hashes, resolved config)
//   labels.png     16-bit labels on the input's pixel grid: 0 = no floe, k = feature id k
//   overlay.png    the photograph in colour with each floe's outline and id
//   labels.pgw, labels.prj, overlay.pgw, overlay.prj  world files and CRS placing the two rasters for a GIS: in
//                  the image's metres, or with a georeference on the map (georeference.h raster_world_file)
//   stats.json     count, concentration, size distribution table, power-law fits, diagnostics, warnings,
//                  provenance
//   fsd.png        the size distribution (number density against equivalent diameter, log-log) with the
//                  truncated power-law fit and its exponent; fsd.csv the same table
//   convex_parts.geojson  only with the option convex_parts: per floe (same id) a MultiPolygon of convex CCW
//                  pieces that tile its outline exactly (pipeline/geometry2d.h convex_decompose), for simulators
//                  that take convex bodies
//   score.json     only with a truth file (GeoJSON polygons, or a labelled mask): precision, recall, F1, mean
//                  IoU, pixel IoU, concentration error, KS distance of the log-area distributions (score.h)
//
// Bad input (each a floesim::Error naming the file, key or value, and nothing written): see image_io.h for the
// image; metres_per_pixel must be finite and > 0; unknown or invalid config keys. An image without ice, or
// without water, is not an error: the result is correct (no floes, or each connected valid area one floe) and
// a warning says so (stderr and stats.json).
#pragma once
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "imaging/digitise_options.h"
#include "imaging/polygons.h"
#include "imaging/score.h"
#include "imaging/segment.h"
#include "pipeline/floes_io.h"

namespace floesim::imaging {

struct DigitiseResult {
  FloeField floes;   // ids 1..N equal to the label values
  Segmentation seg;  // labels (CV_32S), valid mask, diagnostics
  PolygonizeReport polygons;
  nlohmann::json stats;  // stats.json without the provenance
  std::vector<std::string> warnings;
  std::optional<ScoreResult> score;
};

// The whole computation on an image in memory; `name` appears in messages.
DigitiseResult digitise(const cv::Mat& gray, double metres_per_pixel, const DigitiseOptions& o,
                        const std::string& name = "image");

struct DigitiseRequest {
  std::filesystem::path image;
  double metres_per_pixel = 0;
  std::filesystem::path out_dir;
  nlohmann::json config = nlohmann::json::object();  // DigitiseOptions as JSON (strict)
  std::filesystem::path config_file;                 // where `config` came from (messages, provenance); may be empty
  std::filesystem::path truth;                       // optional truth floes GeoJSON: writes score.json
  std::filesystem::path truth_mask;  // optional hand-labelled mask (or 16-bit truth labels): writes score.json
                                     // with the protocol of score.h (ScoreOptions::labelled_mask())
  ScoreOptions mask_score = ScoreOptions::labelled_mask();
};

// Reads and checks everything, digitises, writes the artefacts (see above).
DigitiseResult run_digitise(const DigitiseRequest& req);

// convex_parts.geojson's content: each floe as a MultiPolygon of its convex pieces (properties id, area_m2,
// thickness_m, parts), the field extent and provenance as in floes.geojson.
nlohmann::json convex_parts_geojson(const FloeField& floes);

// The photograph in colour with each floe's outline (a colour per id) and, where it fits, its id.
cv::Mat render_overlay(const cv::Mat& gray, const FloeField& floes, double metres_per_pixel);

}  // namespace floesim::imaging
