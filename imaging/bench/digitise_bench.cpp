// Digitise benchmark on the hand-labelled passerotti images (issue #3): runs digitise with ONE settings file on
// every labelled image, scores each against its mask with the protocol of imaging/score.h, and prints the scores
// per image, their means and the wall time per image.
//
//   digitise_bench [--data DIR] [--config FILE] [--out DIR] [--only ID,...] [--set key=value ...]
//   digitise_bench --tune GRID.json [--threads N] [--tune-out F]  (two-fold cross-validated choice, see below)
//
//   --data    the shared data directory holding passerotti/ (default: the FLOESIM_SHARED_DATA_DIR of the build)
//   --config  digitise options (default: imaging/settings/close_range.json of the source tree)
//   --out     keep every image's artefacts in DIR/<id>/ (floes.geojson, labels.png, overlay.png, stats.json,
//             score.json) plus DIR/<id>/compare.png (half size: truth outlines blue; predicted outlines green when
//             matched, red when not, grey when dropped at the edge or under 1 m^2) and DIR/summary.json.
//             Without --out the artefacts go to a temporary directory that is removed.
//   --set     override one option of the config (repeatable), e.g. --set brash_cutoff_m2=0.5
//
// The time per image is the wall time of run_digitise: reading the PNG, segmenting, polygons, statistics and
// writing all artefacts, i.e. what `floesim-digitise` costs minus process start-up.
//
// Tuning (--tune GRID.json): GRID.json maps option names to lists of values; every combination is run on all
// images in memory (digitise + score, no artefacts), then the two folds (images 1,3,5,.. and 2,4,6,.. in sorted
// order) each choose the combination with the best objective on themselves and are scored with it on the other
// fold. Objective = mean F1 - 2 max(0, mean |concentration error| - 0.03) - 2 max(0, mean KS - 0.15) (F1, with
// the other two targets, 0.04 and 0.18, kept with a margin). Prints every combination's all-image means, the
// cross-validated means and the choice of each fold; --tune-out FILE keeps every per-image score as JSON.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "imaging/digitise.h"
#include "imaging/image_io.h"
#include "imaging/score.h"
#include "imaging/synth.h"
#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/options.h"

using namespace floesim;
using namespace floesim::imaging;
namespace fs = std::filesystem;

namespace {

constexpr double kScale = 0.05;  // passerotti: metres per pixel (data README)

struct Item {
  std::string id;
  fs::path image, mask;
};

std::vector<Item> find_items(const fs::path& data, const std::vector<std::string>& only) {
  const fs::path dir = data / "passerotti";
  FLOESIM_REQUIRE(fs::is_directory(dir / "images") && fs::is_directory(dir / "masks"), dir.string(),
                  " (with images/ and masks/) not found; pass --data DIR pointing at the shared data directory "
                  "(../shared/data next to the repository)");
  std::vector<Item> items;
  for (const auto& e : fs::directory_iterator(dir / "images")) {
    const std::string name = e.path().filename().string();
    const std::string suffix = "_ortho.png";
    if (name.size() <= suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    Item it;
    it.id = name.substr(0, name.size() - suffix.size());
    it.image = e.path();
    it.mask = dir / "masks" / (it.id + "_mask.png");
    FLOESIM_REQUIRE(fs::exists(it.mask), "no mask for ", it.image.string(), " (expected ",
                    it.mask.string(), ")");
    if (!only.empty() && std::none_of(only.begin(), only.end(),
                                      [&](const std::string& o) { return it.id.find(o) != std::string::npos; }))
      continue;
    items.push_back(it);
  }
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.id < b.id; });
  FLOESIM_REQUIRE(!items.empty(), "no labelled image found in ", dir.string());
  return items;
}

Json parse_value(const std::string& v) {
  try {
    return Json::parse(v);
  } catch (const std::exception&) {
    return Json(v);
  }
}

struct Row {
  std::string id;
  ScoreResult s;
  double seconds = 0;
  int floes = 0;
};

void print_header() {
  std::printf("%-18s %5s %5s %5s %6s %6s %6s %6s %6s %6s %6s %7s %6s %6s\n", "image", "truth", "pred", "match", "prec",
              "recall", "F1", "mIoU", "pxIoU", "c_pred", "c_true", "c_err", "KS", "time_s");
}
void print_row(const Row& r) {
  const ScoreResult& s = r.s;
  std::printf("%-18s %5d %5d %5d %6.3f %6.3f %6.3f %6.3f %6.3f %6.3f %6.3f %+7.3f %6.3f %6.2f\n", r.id.c_str(),
              s.truth, s.predicted, s.matched, s.precision, s.recall, s.f1, s.mean_iou, s.pixel_iou,
              s.concentration_predicted, s.concentration_truth, s.concentration_error, s.ks_log_area, r.seconds);
}

struct Means {
  double precision = 0, recall = 0, f1 = 0, mean_iou = 0, pixel_iou = 0, conc_err = 0, abs_conc_err = 0, ks = 0,
         seconds = 0, max_seconds = 0;
  int n = 0;
  // The targets are F1 >= 0.80 with |concentration error| <= 0.04 and KS <= 0.18: maximise F1, penalising the
  // other two only beyond margins below their targets (0.03, 0.15).
  double objective() const {
    return f1 - 2 * std::max(0.0, abs_conc_err - 0.03) - 2 * std::max(0.0, ks - 0.15);
  }
  Json to_json() const {
    return {{"images", n},         {"precision", precision},
            {"recall", recall},    {"f1", f1},
            {"mean_iou", mean_iou}, {"pixel_iou", pixel_iou},
            {"concentration_error", conc_err}, {"abs_concentration_error", abs_conc_err},
            {"ks_log_area", ks},   {"seconds", seconds},
            {"max_seconds", max_seconds}};
  }
};

Means means(const std::vector<Row>& rows, const std::vector<int>& which) {
  Means m;
  for (int i : which) {
    const Row& r = rows[i];
    m.precision += r.s.precision;
    m.recall += r.s.recall;
    m.f1 += r.s.f1;
    m.mean_iou += r.s.mean_iou;
    m.pixel_iou += r.s.pixel_iou;
    m.conc_err += r.s.concentration_error;
    m.abs_conc_err += std::abs(r.s.concentration_error);
    m.ks += r.s.ks_log_area;
    m.seconds += r.seconds;
    m.max_seconds = std::max(m.max_seconds, r.seconds);
    ++m.n;
  }
  if (m.n) {
    for (double* v : {&m.precision, &m.recall, &m.f1, &m.mean_iou, &m.pixel_iou, &m.conc_err, &m.abs_conc_err, &m.ks,
                      &m.seconds})
      *v /= m.n;
  }
  return m;
}

std::vector<int> all_of(size_t n) {
  std::vector<int> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = static_cast<int>(i);
  return v;
}

void print_means(const char* label, const Means& m) {
  std::printf("%-18s %17s %6.3f %6.3f %6.3f %6.3f %6.3f %13s %+7.3f %6.3f %6.2f\n", label, "", m.precision, m.recall,
              m.f1, m.mean_iou, m.pixel_iou, "", m.conc_err, m.ks, m.seconds);
  std::printf("%-18s mean |conc. error| %.3f, max time %.2f s, objective %.4f\n", "", m.abs_conc_err, m.max_seconds,
              m.objective());
}

// Half-size comparison picture: truth outlines blue; predicted green (matched), red (unmatched), grey (dropped).
cv::Mat compare_image(const cv::Mat& gray, const cv::Mat& pred, const cv::Mat& truth, const ScoreResult& s) {
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  double hp = 0;
  cv::minMaxLoc(pred, nullptr, &hp);
  std::vector<int> status(static_cast<size_t>(hp) + 1, 0);  // 0 unmatched-or-dropped, 1 matched
  for (const auto& [p, q] : s.matches) status[p] = 1;
  // Which predicted floes entered the matching: redo the protocol's classification cheaply via areas/edges.
  cv::Mat valid = gray > 0, forbidden;
  cv::dilate(valid == 0, forbidden, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
  forbidden.row(0).setTo(255);
  forbidden.row(forbidden.rows - 1).setTo(255);
  forbidden.col(0).setTo(255);
  forbidden.col(forbidden.cols - 1).setTo(255);
  std::vector<long long> area(status.size(), 0);
  std::vector<char> edge(status.size(), 0);
  for (int r = 0; r < pred.rows; ++r)
    for (int c = 0; c < pred.cols; ++c)
      if (const int l = pred.at<int>(r, c)) {
        ++area[l];
        if (forbidden.at<uint8_t>(r, c)) edge[l] = 1;
      }
  auto draw_boundaries = [&](const cv::Mat& lab, auto colour_of) {
    for (int r = 0; r < lab.rows; ++r)
      for (int c = 0; c < lab.cols; ++c) {
        const int l = lab.at<int>(r, c);
        if (l <= 0) continue;
        bool boundary = false;
        for (int k = 0; k < 4 && !boundary; ++k) {
          const int rr = r + (k == 0) - (k == 1), cc = c + (k == 2) - (k == 3);
          boundary = rr < 0 || cc < 0 || rr >= lab.rows || cc >= lab.cols || lab.at<int>(rr, cc) != l;
        }
        if (boundary) bgr.at<cv::Vec3b>(r, c) = colour_of(l);
      }
  };
  draw_boundaries(truth, [](int) { return cv::Vec3b(255, 80, 0); });
  draw_boundaries(pred, [&](int l) {
    if (status[l]) return cv::Vec3b(0, 220, 0);
    if (edge[l] || area[l] * kScale * kScale < 1.0) return cv::Vec3b(150, 150, 150);
    return cv::Vec3b(0, 0, 255);
  });
  cv::Mat half;
  cv::resize(bgr, half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  return half;
}

// In-memory evaluation of one option set on every image (tuning). Images and truths are loaded once.
struct Loaded {
  Item item;
  cv::Mat gray, truth;
};

std::vector<Row> evaluate(const std::vector<Loaded>& data, const DigitiseOptions& o, int threads) {
  std::vector<Row> rows(data.size());
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t i; (i = next++) < data.size();) {
      const auto t0 = std::chrono::steady_clock::now();
      const DigitiseResult res = digitise(data[i].gray, kScale, o, data[i].item.id);
      rows[i].seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      rows[i].s = score_labels(res.seg.labels, data[i].truth, kScale, res.seg.valid, ScoreOptions::labelled_mask());
      rows[i].id = data[i].item.id;
      rows[i].floes = res.seg.floes;
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  return rows;
}

void expand_grid(const Json& grid, std::vector<std::string> keys, size_t k, Json current, std::vector<Json>& out) {
  if (k == keys.size()) {
    out.push_back(current);
    return;
  }
  for (const Json& v : grid.at(keys[k])) {
    current[keys[k]] = v;
    expand_grid(grid, keys, k + 1, current, out);
  }
}

int tune(const std::vector<Item>& items, const Json& base, const Json& grid, int threads, const std::string& out) {
  FLOESIM_REQUIRE(grid.is_object(), "--tune: the grid must be a JSON object {\"option\": [values...], ...}");
  std::vector<std::string> keys;
  for (const auto& [k, v] : grid.items()) {
    FLOESIM_REQUIRE(v.is_array() && !v.empty(), "--tune: grid entry ", k, " must be a non-empty array of values");
    keys.push_back(k);
  }
  std::vector<Json> combos;
  expand_grid(grid, keys, 0, Json::object(), combos);
  std::vector<Loaded> data;
  for (const Item& it : items) {
    Loaded l;
    l.item = it;
    l.gray = load_grayscale_image(it.image, 1e9);
    l.truth = load_label_image(it.mask, "mask");
    data.push_back(l);
  }
  std::vector<int> fold[2];
  for (size_t i = 0; i < data.size(); ++i) fold[i % 2].push_back(static_cast<int>(i));
  std::vector<std::vector<Row>> results;
  std::printf("%4s %6s %6s %6s %6s %6s %7s %6s  %s\n", "#", "F1", "|cerr|", "KS", "obj_A", "obj_B", "s/img", "maxs",
              "settings");
  for (size_t c = 0; c < combos.size(); ++c) {
    Json cfg = base;
    for (const auto& [k, v] : combos[c].items()) cfg[k] = v;
    const DigitiseOptions o = read_options<DigitiseOptions>(cfg, "tuning grid");
    results.push_back(evaluate(data, o, threads));
    const Means all = means(results.back(), all_of(data.size()));
    std::printf("%4zu %6.3f %6.3f %6.3f %6.3f %6.3f %7.2f %6.2f  %s\n", c, all.f1, all.abs_conc_err, all.ks,
                means(results.back(), fold[0]).objective(), means(results.back(), fold[1]).objective(), all.seconds,
                all.max_seconds, combos[c].dump().c_str());
    std::fflush(stdout);
  }
  if (!out.empty()) {
    Json j = {{"base", base}, {"grid", grid}, {"combinations", Json::array()}};
    for (size_t c = 0; c < combos.size(); ++c) {
      Json imgs = Json::array();
      for (const Row& r : results[c]) {
        Json x = r.s.to_json();
        x.erase("protocol");
        x["id"] = r.id;
        x["seconds"] = r.seconds;
        imgs.push_back(x);
      }
      j["combinations"].push_back({{"settings", combos[c]}, {"images", imgs}});
    }
    write_text_atomic(out, j.dump(1) + "\n");
  }
  std::vector<Row> cv_rows(data.size());
  for (int f = 0; f < 2; ++f) {
    size_t best = 0;
    for (size_t c = 1; c < combos.size(); ++c)
      if (means(results[c], fold[f]).objective() > means(results[best], fold[f]).objective()) best = c;
    std::printf("fold %c (%zu images) chooses #%zu %s; on the other fold: ", f ? 'B' : 'A', fold[f].size(), best,
                combos[best].dump().c_str());
    const Means other = means(results[best], fold[1 - f]);
    std::printf("F1 %.3f, |conc err| %.3f, KS %.3f\n", other.f1, other.abs_conc_err, other.ks);
    for (int i : fold[1 - f]) cv_rows[i] = results[best][i];
  }
  print_header();
  for (const Row& r : cv_rows) print_row(r);
  print_means("cross-validated", means(cv_rows, all_of(cv_rows.size())));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"digitise_bench: digitise + score on the labelled passerotti images (issue #3)"};
  std::string data = FLOESIM_SHARED_DATA_DIR, config = FLOESIM_DEFAULT_BENCH_CONFIG, out, tune_grid, tune_out;
  std::vector<std::string> only, sets;
  int threads = 1;
  app.add_option("--data", data, "shared data directory holding passerotti/");
  app.add_option("--config", config, "digitise options JSON (one file for every image)");
  app.add_option("--out", out, "keep the artefacts and comparison pictures in DIR/<id>/");
  app.add_option("--only", only, "only images whose id contains one of these (comma separated)")->delimiter(',');
  app.add_option("--set", sets, "override an option: key=value (JSON value)");
  app.add_option("--tune", tune_grid, "grid JSON {option: [values]}: two-fold cross-validated choice");
  app.add_option("--threads", threads, "images evaluated in parallel in --tune mode");
  app.add_option("--tune-out", tune_out, "--tune: write every combination's per-image scores to this JSON file");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    Json cfg = load_json_file(config);
    for (const std::string& s : sets) {
      const auto eq = s.find('=');
      FLOESIM_REQUIRE(eq != std::string::npos, "--set ", s, ": expected key=value");
      cfg[s.substr(0, eq)] = parse_value(s.substr(eq + 1));
    }
    (void)read_options<DigitiseOptions>(cfg, config);  // fail early on a bad key
    const std::vector<Item> items = find_items(data, only);
    std::printf("digitise_bench: %zu labelled images from %s, config %s%s\n", items.size(), data.c_str(),
                config.c_str(), sets.empty() ? "" : " (with --set overrides)");
    if (!tune_grid.empty()) return tune(items, cfg, load_json_file(tune_grid), std::max(1, threads), tune_out);

    const bool keep = !out.empty();
    const fs::path root = keep ? fs::path(out) : fs::temp_directory_path() /
                                                     ("floesim_digitise_bench_" + std::to_string(::getpid()));
    std::vector<Row> rows;
    print_header();
    for (const Item& it : items) {
      DigitiseRequest req;
      req.image = it.image;
      req.metres_per_pixel = kScale;
      req.out_dir = root / it.id;
      req.config = cfg;
      req.config_file = config;
      req.truth_mask = it.mask;
      const auto t0 = std::chrono::steady_clock::now();
      const DigitiseResult res = run_digitise(req);
      Row r;
      r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      r.id = it.id;
      r.s = *res.score;
      r.floes = res.seg.floes;
      print_row(r);
      std::fflush(stdout);
      rows.push_back(r);
      if (keep) {
        const cv::Mat gray = cv::imread(it.image.string(), cv::IMREAD_GRAYSCALE);
        cv::imwrite((root / it.id / "compare.png").string(),
                    compare_image(gray, res.seg.labels, load_label_image(it.mask, "mask"), r.s));
      }
    }
    const Means m = means(rows, all_of(rows.size()));
    print_means("mean", m);
    Json synthetic;
    if (only.empty()) {
      // The helicopter-scale default case must keep working with the default settings (issue #3: F1 >= 0.95).
      const SynthOptions so;
      const SynthResult syn = synthesize(so);
      const auto t0 = std::chrono::steady_clock::now();
      const DigitiseResult res = digitise(syn.image, so.metres_per_pixel, DigitiseOptions{}, "synthetic");
      const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const ScoreResult sc = score_against_truth(res.seg.labels, syn.truth, so.metres_per_pixel, res.seg.valid);
      std::printf("synthetic default image (seed %llu, %d x %d px at %.4f m/px, default settings, all floes): F1 %.4f, "
                  "mean IoU %.3f, conc. error %+.4f, KS %.3f, %.2f s (segmentation and polygons)\n",
                  static_cast<unsigned long long>(so.seed), syn.image.cols, syn.image.rows, so.metres_per_pixel, sc.f1,
                  sc.mean_iou, sc.concentration_error, sc.ks_log_area, secs);
      synthetic = sc.to_json();
      synthetic["seconds"] = secs;
    }
    if (keep) {
      Json summary = {{"config", cfg}, {"data", data}, {"means", m.to_json()}, {"images", Json::array()},
                      {"synthetic_default", synthetic}};
      for (const Row& r : rows) {
        Json j = r.s.to_json();
        j["id"] = r.id;
        j["seconds"] = r.seconds;
        j["floes_written"] = r.floes;
        summary["images"].push_back(j);
      }
      write_text_atomic(root / "summary.json", summary.dump(1) + "\n");
    } else {
      std::error_code ec;
      fs::remove_all(root, ec);
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "digitise_bench: " << e.what() << "\n";
    return 1;
  }
}
