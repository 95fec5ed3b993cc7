#include "imaging/synth.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "imaging/raster.h"
#include "imaging/shapes.h"
#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/provenance.h"
#include "pipeline/geometry2d.h"

namespace floesim::imaging {

namespace {

// Inverse-CDF sample of the truncated power law p(D) ~ D^-alpha on [dmin, dmax].
double sample_diameter(std::mt19937_64& rng, double alpha, double dmin, double dmax) {
  const double u = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
  if (std::abs(alpha - 1.0) < 1e-9) return dmin * std::pow(dmax / dmin, u);
  const double e = 1.0 - alpha;
  const double lo = std::pow(dmin, e), hi = std::pow(dmax, e);
  return std::pow(lo + u * (hi - lo), 1.0 / e);
}

// A floe outline around the origin with the given area: a perturbed ellipse sampled at n jittered, increasing
// angles (so it is star-shaped about the origin and simple), optionally replaced by its convex hull.
Polygon random_outline(std::mt19937_64& rng, int n, double aspect, double irregularity, bool convex, double area) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double rot = 2 * kPi * U(rng);
  const double a = std::sqrt(aspect), b = 1.0 / std::sqrt(aspect);
  const double cr = std::cos(rot), sr = std::sin(rot);
  Polygon p;
  p.reserve(n);
  for (int i = 0; i < n; ++i) {
    // Jitter below half the spacing keeps the angles increasing.
    const double th = 2 * kPi * (i + 0.7 * (U(rng) - 0.5)) / n;
    const double c = std::cos(th), s = std::sin(th);
    const double re = 1.0 / std::sqrt((c / a) * (c / a) + (s / b) * (s / b));
    const double r = re * (1.0 + irregularity * (2 * U(rng) - 1));
    const double x = r * c, y = r * s;
    p.emplace_back(cr * x - sr * y, sr * x + cr * y);
  }
  if (convex) p = convex_hull_2d(p);
  const double k = std::sqrt(area / signed_area(p));
  for (Vec2& v : p) v *= k;
  return p;
}

// Shapes already placed, bucketed on a uniform grid so a candidate is tested only against its neighbours.
class Occupancy {
 public:
  Occupancy(const BBox& domain, double cell) : domain_(domain), cell_(cell) {
    nx_ = std::max(1, static_cast<int>(std::ceil((domain.x1 - domain.x0) / cell)));
    ny_ = std::max(1, static_cast<int>(std::ceil((domain.y1 - domain.y0) / cell)));
    cells_.resize(static_cast<size_t>(nx_) * ny_);
  }

  bool fits(const Polygon& poly, const BBox& box, const Vec2& c, double radius, double gap) {
    ++stamp_;
    int i0, i1, j0, j1;
    range(box, gap, i0, i1, j0, j1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i)
        for (int id : cells_[static_cast<size_t>(j) * nx_ + i]) {
          if (seen_[id] == stamp_) continue;
          seen_[id] = stamp_;
          const Item& it = items_[id];
          if ((c - it.centre).norm() >= radius + it.radius + gap) continue;
          if (!box.overlaps(it.box, gap)) continue;
          if (polygons_within(poly, it.poly, gap)) return false;
        }
    return true;
  }

  void insert(Polygon poly, const BBox& box, const Vec2& c, double radius) {
    const int id = static_cast<int>(items_.size());
    items_.push_back({std::move(poly), box, c, radius});
    seen_.push_back(0);
    int i0, i1, j0, j1;
    range(box, 0, i0, i1, j0, j1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) cells_[static_cast<size_t>(j) * nx_ + i].push_back(id);
  }

 private:
  struct Item {
    Polygon poly;
    BBox box;
    Vec2 centre;
    double radius;
  };
  void range(const BBox& b, double margin, int& i0, int& i1, int& j0, int& j1) const {
    auto cx = [&](double x) { return std::clamp(static_cast<int>(std::floor((x - domain_.x0) / cell_)), 0, nx_ - 1); };
    auto cy = [&](double y) { return std::clamp(static_cast<int>(std::floor((y - domain_.y0) / cell_)), 0, ny_ - 1); };
    i0 = cx(b.x0 - margin);
    i1 = cx(b.x1 + margin);
    j0 = cy(b.y0 - margin);
    j1 = cy(b.y1 + margin);
  }
  BBox domain_;
  double cell_;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> cells_;
  std::vector<Item> items_;
  std::vector<unsigned> seen_;
  unsigned stamp_ = 0;
};

Polygon translated(const Polygon& p, const Vec2& c) {
  Polygon q = p;
  for (Vec2& v : q) v += c;
  return q;
}

double max_radius(const Polygon& p) {
  double r = 0;
  for (const Vec2& v : p) r = std::max(r, v.norm());
  return r;
}

double min_edge_distance(const Polygon& a, const Polygon& b) {
  double d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < b.size(); ++j)
      d = std::min(d, segment_distance(a[i], a[(i + 1) % a.size()], b[j], b[(j + 1) % b.size()]));
  return d;
}

struct Drawn {
  Polygon outline;  // metres, unclipped (the renderer clips)
  double grey;
};
}  // namespace

SynthResult synthesize(const SynthOptions& o) {
  SynthResult res;
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const PixelGrid g{o.width_px, o.height_px, o.metres_per_pixel};
  const double W = g.width_m(), H = g.height_m();
  const double min_floe_area = kPi / 4 * o.min_diameter_m * o.min_diameter_m;

  // 1. Draw the floe sizes for a generation domain that extends past the image, so floes cut by the border
  //    appear as often as in a crop of a larger photograph and the crop's concentration matches the target.
  const double margin = 0.75 * o.max_diameter_m;
  const BBox domain{-margin, -margin, W + margin, H + margin};
  const double domain_area = (W + 2 * margin) * (H + 2 * margin);
  // A floe centred near the domain's edge spills over it; each floe counts with its expected area inside the
  // domain, that of a disc of radius r centred uniformly in a Wd x Hd rectangle:
  // pi r^2 - 4/3 r^3 (Wd + Hd) / (Wd Hd) + r^4 / (2 Wd Hd).
  const double wd = W + 2 * margin, hd = H + 2 * margin;
  std::vector<double> diameters;
  for (double area = 0; area < o.concentration * domain_area;) {
    diameters.push_back(sample_diameter(rng, o.alpha, o.min_diameter_m, o.max_diameter_m));
    const double r = diameters.back() / 2;
    area += kPi * r * r - 4.0 / 3.0 * r * r * r * (wd + hd) / (wd * hd) + r * r * r * r / (2 * wd * hd);
  }
  std::sort(diameters.begin(), diameters.end(), std::greater<double>());

  // 2. Place largest first at uniformly random free positions (rejection sampling on the occupancy grid).
  Occupancy occ(domain, std::max(2 * o.min_diameter_m, (domain.x1 - domain.x0) / 4000));
  struct Placed {
    Polygon outline;
    double diameter;
  };
  std::vector<Placed> placed;
  for (double d : diameters) {
    const int n = std::uniform_int_distribution<int>(o.min_vertices, o.max_vertices)(rng);
    const double aspect = 1.0 + (o.max_aspect_ratio - 1.0) * U(rng);
    const bool convex = U(rng) < o.convex_fraction;
    const Polygon shape = random_outline(rng, n, aspect, o.irregularity, convex, kPi / 4 * d * d);
    // A non-convex floe cut by the border with its star centre outside the image could leave several pieces in
    // the image; there it takes its convex hull, scaled to the same area (rejecting the position instead would
    // leave the border band short of ice).
    Polygon hull = convex_hull_2d(shape);
    for (Vec2& v : hull) v *= std::sqrt(std::abs(signed_area(shape)) / signed_area(hull));
    bool ok = false;
    for (int attempt = 0; attempt < o.placement_attempts && !ok; ++attempt) {
      const Vec2 c(domain.x0 + U(rng) * (domain.x1 - domain.x0), domain.y0 + U(rng) * (domain.y1 - domain.y0));
      Polygon poly = translated(shape, c);
      BBox box = bounding_box(poly);
      const bool centre_inside = c.x() > 0 && c.x() < W && c.y() > 0 && c.y() < H;
      auto cut = [&](const BBox& b) {
        return b.overlaps({0, 0, W, H}) && (b.x0 < 0 || b.y0 < 0 || b.x1 > W || b.y1 > H);
      };
      if (!convex && !centre_inside && cut(box)) {
        poly = translated(hull, c);
        box = bounding_box(poly);
      }
      const double radius = max_radius(translated(poly, -c));
      if (!occ.fits(poly, box, c, radius, o.min_gap_m)) continue;
      occ.insert(poly, box, c, radius);
      placed.push_back({std::move(poly), d});
      ok = true;
    }
    if (!ok) ++res.rejected_floes;
  }

  // 3. The truth: placed floes clipped to the image. A floe left with less than a min_diameter_m disc inside the
  //    image is hidden (neither drawn nor listed): such a sliver is not a floe of the photograph.
  std::vector<Drawn> drawn;
  double ice_area = 0;
  for (const Placed& p : placed) {
    res.placed_diameters_m.push_back(p.diameter);
    Polygon clipped = clip_to_rect(p.outline, 0, 0, W, H);
    if (clipped.empty() || std::abs(signed_area(clipped)) < min_floe_area) {
      ++res.hidden_floes;
      continue;
    }
    make_ccw(clipped);
    Floe f;
    f.id = static_cast<int>(res.truth.floes.size()) + 1;
    f.outline = std::move(clipped);
    f.area_m2 = signed_area(f.outline);
    f.thickness_m = o.thickness_m;
    ice_area += f.area_m2;
    res.truth.floes.push_back(std::move(f));
    // Shade: most floes bright white, some darker (wet, thin or in shadow).
    double grey;
    if (U(rng) < o.grey_floe_fraction)
      grey = o.grey_floe_grey + 15 * (2 * U(rng) - 1);
    else
      grey = o.ice_grey + o.ice_grey_sigma * std::normal_distribution<double>(0.0, 1.0)(rng);
    drawn.push_back({p.outline, std::clamp(grey, o.water_grey + 60, 252.0)});
  }
  res.truth.width_m = W;
  res.truth.height_m = H;
  res.concentration = ice_area / (W * H);

  // 4. Melt ponds: dark patches well inside large floes (and inside the image). They are ice: the truth ignores them.
  const double pond_margin = std::max(2.0, 3 * o.metres_per_pixel);
  std::vector<Drawn> ponds;
  for (size_t k = 0; k < drawn.size(); ++k) {
    const double d = std::sqrt(4 * std::abs(signed_area(drawn[k].outline)) / kPi);
    if (d < o.pond_min_diameter_m || U(rng) >= o.pond_probability) continue;
    const Vec2 c0 = centroid(drawn[k].outline);
    for (int attempt = 0; attempt < 10; ++attempt) {
      const double dp = d * (0.12 + 0.18 * U(rng));
      const Polygon shape = random_outline(rng, 10, 1.0 + 0.8 * U(rng), 0.2, U(rng) < 0.5, kPi / 4 * dp * dp);
      const Vec2 c = c0 + d * 0.2 * Vec2(2 * U(rng) - 1, 2 * U(rng) - 1);
      Polygon pond = translated(shape, c);
      const BBox pb = bounding_box(pond);
      if (pb.x0 < pond_margin || pb.y0 < pond_margin || pb.x1 > W - pond_margin || pb.y1 > H - pond_margin) continue;
      bool inside = true;
      for (const Vec2& v : pond) inside = inside && point_in_polygon(v, drawn[k].outline);
      if (!inside || min_edge_distance(pond, drawn[k].outline) < pond_margin) continue;
      ponds.push_back({std::move(pond), o.pond_grey + 15 * (2 * U(rng) - 1)});
      break;
    }
  }
  res.ponds = static_cast<int>(ponds.size());

  // 5. Brash: small fragments in the water, kept apart from floes and each other so they stay below the
  //    digitise brash cut-off.
  std::vector<Drawn> brash;
  const int n_brash = static_cast<int>(std::lround(o.brash_per_km2 * W * H / 1e6));
  for (int b = 0; b < n_brash; ++b) {
    const double area = std::exp(std::log(o.brash_min_area_m2) +
                                 U(rng) * (std::log(o.brash_max_area_m2) - std::log(o.brash_min_area_m2)));
    const int n = std::uniform_int_distribution<int>(5, 8)(rng);
    const Polygon shape = random_outline(rng, n, 1.0 + U(rng), 0.3, true, area);
    const double radius = max_radius(shape);
    const double grey = 130 + 70 * U(rng);
    for (int attempt = 0; attempt < 20; ++attempt) {
      const Vec2 c(U(rng) * W, U(rng) * H);
      Polygon poly = translated(shape, c);
      const BBox box = bounding_box(poly);
      if (!occ.fits(poly, box, c, radius, o.brash_gap_m)) continue;
      occ.insert(poly, box, c, radius);
      brash.push_back({std::move(poly), grey});
      break;
    }
  }
  res.brash_fragments = static_cast<int>(brash.size());

  // 6. Render: supersampled scene (exact area coverage at the edges once box-filtered down), then water texture,
  //    illumination ramp, camera blur and sensor noise.
  const int ss = std::clamp(static_cast<int>(std::sqrt(64e6 / (double(g.width) * g.height))), 1, 4);
  const PixelGrid gs{g.width * ss, g.height * ss, g.metres_per_pixel / ss};
  cv::Mat scene(gs.height, gs.width, CV_8U, cv::Scalar(std::lround(o.water_grey)));
  auto fill = [&](const std::vector<Drawn>& items) {
    for (const Drawn& d : items) fill_polygon(scene, d.outline, gs, static_cast<int>(std::lround(d.grey)));
  };
  fill(drawn);
  fill(ponds);
  fill(brash);
  cv::Mat img;
  scene.convertTo(scene, CV_32F);
  cv::resize(scene, img, cv::Size(g.width, g.height), 0, 0, cv::INTER_AREA);
  scene.release();

  std::normal_distribution<double> N01(0.0, 1.0);
  if (o.water_texture_grey > 0) {
    cv::Mat coarse(g.height / 24 + 2, g.width / 24 + 2, CV_32F);
    for (int r = 0; r < coarse.rows; ++r)
      for (int c = 0; c < coarse.cols; ++c) coarse.at<float>(r, c) = static_cast<float>(N01(rng));
    cv::Mat texture;
    cv::resize(coarse, texture, img.size(), 0, 0, cv::INTER_CUBIC);
    img += texture * o.water_texture_grey;
  }
  const double phi = 2 * kPi * U(rng);
  const double cphi = std::cos(phi), sphi = std::sin(phi);
  const double half = 0.5 * (std::abs(g.width * cphi) + std::abs(g.height * sphi));
  for (int r = 0; r < img.rows; ++r) {
    float* row = img.ptr<float>(r);
    for (int c = 0; c < img.cols; ++c) {
      const double ramp = ((c + 0.5 - 0.5 * g.width) * cphi + (r + 0.5 - 0.5 * g.height) * sphi) / half;
      row[c] = static_cast<float>(row[c] * (1.0 + o.illumination_gradient * std::clamp(ramp, -1.0, 1.0)));
    }
  }
  if (o.blur_sigma_px > 0) cv::GaussianBlur(img, img, cv::Size(0, 0), o.blur_sigma_px);
  res.image.create(g.height, g.width, CV_8U);
  for (int r = 0; r < img.rows; ++r) {
    const float* in = img.ptr<float>(r);
    uint8_t* out = res.image.ptr<uint8_t>(r);
    for (int c = 0; c < img.cols; ++c) {
      const double v = in[c] + (o.noise_sigma > 0 ? o.noise_sigma * N01(rng) : 0.0);
      // Never 0: digitise reads pure black as "no data".
      out[c] = static_cast<uint8_t>(std::clamp(std::lround(v), 1L, 255L));
    }
  }
  res.truth_labels = rasterise_floes(res.truth, g);

  if (res.rejected_floes > 0)
    res.warnings.push_back(std::to_string(res.rejected_floes) + " of " + std::to_string(diameters.size()) +
                           " floes found no free position after " + std::to_string(o.placement_attempts) +
                           " attempts (lower concentration or min_gap_m, or raise placement_attempts)");
  if (std::abs(res.concentration - o.concentration) > 0.03)
    res.warnings.push_back("concentration in the image is " + std::to_string(res.concentration) + " for a target of " +
                           std::to_string(o.concentration));
  return res;
}

SynthResult run_synth(const SynthOptions& o, const std::filesystem::path& out_dir) {
  SynthResult res = synthesize(o);
  ensure_directory(out_dir);
  AtomicFile image(out_dir / "image.png"), labels(out_dir / "truth_labels.png");
  {
    // Encoded in memory, then written with every write checked: imwrite does not report a full disk.
    std::vector<uchar> png;
    FLOESIM_REQUIRE(cv::imencode(".png", res.image, png), image.path().string(), ": cannot encode the image as PNG");
    write_file_checked(image.tmp(), std::string(png.begin(), png.end()), image.path());
  }
  write_labels_png(labels.tmp(), res.truth_labels, labels.path().string());

  res.truth.provenance = make_provenance("floesim-synth", {}, options_to_json(o));
  res.truth.provenance["outputs"] = {{"image.png", sha256_file(image.tmp())},
                                     {"truth_labels.png", sha256_file(labels.tmp())}};
  res.truth.provenance["summary"] = {{"floes", res.truth.floes.size()},        {"concentration", res.concentration},
                                     {"rejected_floes", res.rejected_floes},   {"hidden_floes", res.hidden_floes},
                                     {"brash_fragments", res.brash_fragments}, {"ponds", res.ponds}};
  AtomicFile truth(out_dir / "truth.geojson");
  write_file_checked(truth.tmp(), floes_to_geojson(res.truth).dump(1) + "\n", truth.path());
  image.commit();
  labels.commit();
  truth.commit();
  return res;
}

}  // namespace floesim::imaging
