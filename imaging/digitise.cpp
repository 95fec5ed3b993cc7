#include "imaging/digitise.h"

#include <cmath>
#include <fstream>
#include <optional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "imaging/georeference.h"
#include "imaging/image_io.h"
#include "imaging/stats.h"
#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/geometry2d.h"
#include "pipeline/provenance.h"

namespace floesim::imaging {

DigitiseResult digitise(const cv::Mat& gray, double s, const DigitiseOptions& o, const std::string& name) {
  FLOESIM_REQUIRE(std::isfinite(s) && s > 0, name,
                  ": metres_per_pixel must be a finite number > 0 (the ground size of one pixel), got ", s);
  DigitiseResult res;
  res.seg = segment_floes(gray, s, o, name);
  const PixelGrid g{gray.cols, gray.rows, s};
  const std::vector<Polygon> outlines =
      polygonize_labels(res.seg.labels, res.seg.floes, g, o.simplify_tolerance_m, &res.polygons);
  res.floes.width_m = g.width_m();
  res.floes.height_m = g.height_m();
  std::vector<double> areas;
  for (int k = 0; k < res.seg.floes; ++k) {
    Floe f;
    f.id = k + 1;
    f.outline = outlines[k];
    f.area_m2 = signed_area(f.outline);
    f.thickness_m = o.thickness_m;
    areas.push_back(f.area_m2);
    res.floes.floes.push_back(std::move(f));
  }
  const double ice_area = cv::countNonZero(res.seg.labels > 0) * s * s;
  res.stats =
      floe_statistics(areas, ice_area, res.seg.valid_pixels * s * s, o.size_bins_per_decade, o.fit_min_diameter_m);
  res.stats["image"] = {{"width_px", gray.cols},
                        {"height_px", gray.rows},
                        {"metres_per_pixel", s},
                        {"valid_pixels", res.seg.valid_pixels}};
  res.stats["segmentation"] = {{"classes", res.seg.classes},
                               {"otsu_threshold", res.seg.otsu_threshold},
                               {"water_grey", res.seg.water_grey},
                               {"ice_grey", res.seg.ice_grey},
                               {"seeds", res.seg.seeds},
                               {"merged_pieces", res.seg.merged_pieces},
                               {"simplify_fallbacks", res.polygons.simplify_fallbacks},
                               {"overlap_fallbacks", res.polygons.overlap_fallbacks},
                               {"overlaps_remaining", res.polygons.overlaps_remaining}};
  res.warnings = res.seg.warnings;
  return res;
}

nlohmann::json convex_parts_geojson(const FloeField& field) {
  nlohmann::json fc = floes_to_geojson(FloeField{{}, field.width_m, field.height_m, field.provenance});
  fc["floesim"]["format"] = "floesim-convex-parts/1";
  nlohmann::json feats = nlohmann::json::array();
  for (const Floe& f : field.floes) {
    nlohmann::json polys = nlohmann::json::array();
    const std::vector<Polygon> parts = convex_decompose(f.outline);
    for (const Polygon& p : parts) {
      nlohmann::json ring = nlohmann::json::array();
      for (const Vec2& v : p) ring.push_back({v.x(), v.y()});
      ring.push_back({p[0].x(), p[0].y()});  // GeoJSON rings are closed
      // Json::array, not `{ring}`: a one-element brace list is the ring itself under clang (a MultiPolygon of bare
      // rings; found by the clang sanitizer build of the tests), a list of it under gcc.
      polys.push_back(nlohmann::json::array({ring}));
    }
    feats.push_back({{"type", "Feature"},
                     {"id", f.id},
                     {"properties",
                      {{"id", f.id}, {"area_m2", f.area_m2}, {"thickness_m", f.thickness_m}, {"parts", parts.size()}}},
                     {"geometry", {{"type", "MultiPolygon"}, {"coordinates", polys}}}});
  }
  fc["features"] = feats;
  return fc;
}

cv::Mat render_overlay(const cv::Mat& gray, const FloeField& floes, double s) {
  const PixelGrid g{gray.cols, gray.rows, s};
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  const double font = std::max(0.3, gray.cols / 3000.0);
  const int thick = std::max(1, gray.cols / 1500);
  for (const Floe& f : floes.floes) {
    // Hues spread by the golden ratio so neighbours differ.
    const double hue = std::fmod(f.id * 0.618033988749895, 1.0) * 180.0;
    cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue, 255, 255)), col;
    cv::cvtColor(hsv, col, cv::COLOR_HSV2BGR);
    const cv::Vec3b c = col.at<cv::Vec3b>(0, 0);
    std::vector<std::vector<cv::Point>> polys{to_fixed_point(f.outline, g)};
    cv::polylines(bgr, polys, true, cv::Scalar(c[0], c[1], c[2]), thick, cv::LINE_AA, kRasterShift);
    const std::string id = std::to_string(f.id);
    int base = 0;
    const cv::Size ts = cv::getTextSize(id, cv::FONT_HERSHEY_SIMPLEX, font, 1, &base);
    const double d_px = std::sqrt(4 * f.area_m2 / 3.14159265358979) / s;
    if (d_px < 1.2 * ts.width) continue;  // the id would cover the floe
    const cv::Point2d ctr = g.metres_to_corner(centroid(f.outline));
    const cv::Point org(static_cast<int>(ctr.x - ts.width / 2.0), static_cast<int>(ctr.y + ts.height / 2.0));
    cv::putText(bgr, id, org, cv::FONT_HERSHEY_SIMPLEX, font, cv::Scalar(0, 0, 0), 3 * thick, cv::LINE_AA);
    cv::putText(bgr, id, org, cv::FONT_HERSHEY_SIMPLEX, font, cv::Scalar(c[0], c[1], c[2]), thick, cv::LINE_AA);
  }
  return bgr;
}

namespace {
void write_json_tmp(const AtomicFile& f, const nlohmann::json& j) {
  write_file_checked(f.tmp(), j.dump(1) + "\n", f.path());
}
void write_png_tmp(const AtomicFile& f, const cv::Mat& img) {
  // Encoded in memory, then written with every write checked: imwrite does not report a full disk.
  std::vector<uchar> png;
  bool ok = false;
  try {
    ok = cv::imencode(".png", img, png);
  } catch (const cv::Exception& e) {
    throw Error(f.path().string() + ": cannot encode the image: " + e.what());
  }
  FLOESIM_REQUIRE(ok, f.path().string(), ": cannot encode the image as PNG");
  write_file_checked(f.tmp(), std::string(png.begin(), png.end()), f.path());
}
}  // namespace

DigitiseResult run_digitise(const DigitiseRequest& req) {
  // 1. Every input is checked before anything is written.
  const std::string cfg_name = req.config_file.empty() ? "digitise config" : req.config_file.string();
  const DigitiseOptions o = read_options<DigitiseOptions>(req.config, cfg_name);
  FLOESIM_REQUIRE(std::isfinite(req.metres_per_pixel) && req.metres_per_pixel > 0,
                  "--metres-per-pixel must be a finite number > 0 (the ground size of one pixel in metres), got ",
                  req.metres_per_pixel);
  FLOESIM_REQUIRE(!req.out_dir.empty(), "--out: an output directory is required");
  std::vector<std::string> load_notes;
  const cv::Mat gray = load_grayscale_image(req.image, o.max_pixels, &load_notes);
  FLOESIM_REQUIRE(req.truth.empty() || req.truth_mask.empty(),
                  "--truth and --truth-mask: give one truth, the polygons or the mask");
  std::optional<FloeField> truth;
  if (!req.truth.empty()) truth = read_floes(req.truth);
  cv::Mat truth_labels;
  if (!req.truth_mask.empty()) {
    truth_labels = load_label_image(req.truth_mask, "truth mask");
    FLOESIM_REQUIRE(truth_labels.size() == gray.size(), req.truth_mask.string(), ": the mask is ", truth_labels.cols,
                    " x ", truth_labels.rows, " px but the image is ", gray.cols, " x ", gray.rows,
                    " px; a mask must be on the photograph's pixel grid");
  }

  // 2. The computation.
  DigitiseResult res = digitise(gray, req.metres_per_pixel, o, req.image.string());
  res.warnings.insert(res.warnings.begin(), load_notes.begin(), load_notes.end());
  if (truth) {
    const double tw = truth->width_m, th = truth->height_m;
    if (tw > 0 && th > 0 &&
        (std::abs(tw - res.floes.width_m) > 1e-6 * tw || std::abs(th - res.floes.height_m) > 1e-6 * th))
      throw Error(req.truth.string() + ": the truth covers " + std::to_string(tw) + " x " + std::to_string(th) +
                  " m but the image covers " + std::to_string(res.floes.width_m) + " x " +
                  std::to_string(res.floes.height_m) + " m; wrong truth file or wrong --metres-per-pixel?");
    res.score = score_against_truth(res.seg.labels, *truth, req.metres_per_pixel, res.seg.valid);
  }
  if (!truth_labels.empty())
    res.score = score_labels(res.seg.labels, truth_labels, req.metres_per_pixel, res.seg.valid, req.mask_score);

  // 3. Artefacts: all written to temporary names, then moved into place together.
  nlohmann::json config = {{"metres_per_pixel", req.metres_per_pixel}, {"options", options_to_json(o)}};
  std::vector<NamedInput> inputs{{"image", req.image}};
  if (!req.config_file.empty() && std::filesystem::exists(req.config_file))
    inputs.push_back({"config", req.config_file});
  if (!req.truth.empty()) inputs.push_back({"truth", req.truth});
  if (!req.truth_mask.empty()) inputs.push_back({"truth_mask", req.truth_mask});
  const nlohmann::json prov = make_provenance("floesim-digitise", inputs, config);
  res.floes.provenance = prov;
  res.floes.warnings = res.warnings;
  res.stats["warnings"] = res.warnings;
  nlohmann::json stats = res.stats;
  stats["provenance"] = prov;

  ensure_directory(req.out_dir);
  AtomicFile geo(req.out_dir / "floes.geojson"), labels(req.out_dir / "labels.png"),
      overlay(req.out_dir / "overlay.png"), stats_f(req.out_dir / "stats.json"), fsd_png(req.out_dir / "fsd.png"),
      fsd_csv(req.out_dir / "fsd.csv"), score_f(req.out_dir / "score.json"),
      parts_f(req.out_dir / "convex_parts.geojson"), wgs84_f(req.out_dir / "floes_wgs84.geojson"),
      labels_pgw(req.out_dir / "labels.pgw"), labels_prj(req.out_dir / "labels.prj"),
      overlay_pgw(req.out_dir / "overlay.pgw"), overlay_prj(req.out_dir / "overlay.prj");
  std::optional<GeoReference> where;  // digitise.georeference, if the case gives one
  if (!o.georeference.empty()) where = georeference_from(o.georeference);
  const WorldFile world = raster_world_file(res.floes.width_m, res.floes.height_m, req.metres_per_pixel,
                                            where ? &*where : nullptr);
  for (const AtomicFile* f : {&labels_pgw, &overlay_pgw}) write_file_checked(f->tmp(), world.pgw, f->path());
  for (const AtomicFile* f : {&labels_prj, &overlay_prj}) write_file_checked(f->tmp(), world.prj, f->path());
  write_json_tmp(geo, floes_to_geojson(res.floes));
  write_labels_png(labels.tmp(), res.seg.labels, labels.path().string());
  write_png_tmp(overlay, render_overlay(gray, res.floes, req.metres_per_pixel));
  write_json_tmp(stats_f, stats);
  write_png_tmp(fsd_png, plot_size_distribution(res.stats, "floe size distribution of " +
                                                               req.image.filename().string() + ": " +
                                                               std::to_string(res.floes.floes.size()) + " floes"));
  write_file_checked(fsd_csv.tmp(), size_distribution_csv(res.stats), fsd_csv.path());
  if (res.score) {
    nlohmann::json sj = res.score->to_json();
    sj["provenance"] = prov;
    write_json_tmp(score_f, sj);
  }
  if (o.convex_parts) write_json_tmp(parts_f, convex_parts_geojson(res.floes));
  if (where) write_json_tmp(wgs84_f, floes_to_wgs84_geojson(res.floes, *where));
  geo.commit();
  labels.commit();
  overlay.commit();
  for (AtomicFile* f : {&labels_pgw, &labels_prj, &overlay_pgw, &overlay_prj}) f->commit();
  stats_f.commit();
  fsd_png.commit();
  fsd_csv.commit();
  if (res.score) score_f.commit();
  if (o.convex_parts) parts_f.commit();
  if (where) wgs84_f.commit();
  return res;
}

}  // namespace floesim::imaging
