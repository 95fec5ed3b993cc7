#include "imaging/segment.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <numeric>
#include <opencv2/imgproc.hpp>

#include "pipeline/error.h"

namespace floesim::imaging {

namespace {

constexpr int kDr[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
constexpr int kDc[8] = {-1, 0, 1, -1, 1, -1, 0, 1};

// Otsu's threshold of a 256-bin histogram: the grey level t maximising the between-class variance of
// {<= t} and {> t}.
int otsu(const std::array<double, 256>& hist) {
  double total = 0, sum = 0;
  for (int i = 0; i < 256; ++i) {
    total += hist[i];
    sum += i * hist[i];
  }
  double w0 = 0, s0 = 0, best = -1;
  int t_best = 0;
  for (int t = 0; t < 255; ++t) {
    w0 += hist[t];
    s0 += t * hist[t];
    const double w1 = total - w0;
    if (w0 <= 0 || w1 <= 0) continue;
    const double m0 = s0 / w0, m1 = (sum - s0) / w1;
    const double between = w0 * w1 * (m0 - m1) * (m0 - m1);
    if (between > best) {
      best = between;
      t_best = t;
    }
  }
  return t_best;
}

// Smooth average of `gray` over the pixels of `mask` (Gaussian of sigma_px), computed on a coarse grid (the
// result is smooth by construction) and interpolated back. Where the mask has no support, `fallback`.
cv::Mat masked_smooth(const cv::Mat& gray, const cv::Mat& mask, double sigma_px, double fallback) {
  const int f = std::max(1, static_cast<int>(sigma_px / 4));
  const cv::Size small((gray.cols + f - 1) / f, (gray.rows + f - 1) / f);
  cv::Mat m, v;
  mask.convertTo(m, CV_32F, 1.0 / 255);
  gray.convertTo(v, CV_32F);
  v = v.mul(m);
  cv::Mat ms, vs;
  cv::resize(m, ms, small, 0, 0, cv::INTER_AREA);
  cv::resize(v, vs, small, 0, 0, cv::INTER_AREA);
  const double sigma_small = std::max(0.5, sigma_px / f);
  cv::GaussianBlur(ms, ms, cv::Size(0, 0), sigma_small, sigma_small, cv::BORDER_REFLECT);
  cv::GaussianBlur(vs, vs, cv::Size(0, 0), sigma_small, sigma_small, cv::BORDER_REFLECT);
  // Normalised convolution; the small constant lets regions without support fall back to the global level.
  const float eps = 1e-3f;
  cv::Mat est = (vs + eps * static_cast<float>(fallback)) / (ms + eps);
  cv::Mat out;
  cv::resize(est, out, gray.size(), 0, 0, cv::INTER_LINEAR);
  return out;
}

// Local water and ice brightness from Otsu's split of each block of block_px x block_px pixels: the two class
// means of a block, weighted by how clearly it holds both classes (contrast above min_contrast, and the share of
// the smaller class), are smoothed over the neighbouring blocks (normalised convolution, sigma one block) and
// interpolated between block centres. Unlike one global split, this follows a darker far field or a field of
// grey floes; a block of one class only (inside a large floe, open water) takes its neighbours' levels. Where no
// block has both classes, the global class means (fallback_water, fallback_ice) are used.
void local_otsu_levels(const cv::Mat& img, const cv::Mat& valid, int block_px, double min_contrast,
                       double fallback_water, double fallback_ice, cv::Mat& water, cv::Mat& ice) {
  const int bx = (img.cols + block_px - 1) / block_px, by = (img.rows + block_px - 1) / block_px;
  cv::Mat L(by, bx, CV_32F, cv::Scalar(0)), H(by, bx, CV_32F, cv::Scalar(0)), W(by, bx, CV_32F, cv::Scalar(0));
  double sum_l = 0, sum_h = 0, sum_w = 0;
  std::array<double, 256> hist;
  for (int j = 0; j < by; ++j)
    for (int i = 0; i < bx; ++i) {
      hist.fill(0);
      double n = 0;
      for (int r = j * block_px; r < std::min(img.rows, (j + 1) * block_px); ++r) {
        const float* p = img.ptr<float>(r);
        const uint8_t* v = valid.ptr<uint8_t>(r);
        for (int c = i * block_px; c < std::min(img.cols, (i + 1) * block_px); ++c)
          if (v[c]) {
            hist[std::clamp(static_cast<int>(p[c] + 0.5f), 0, 255)] += 1;
            n += 1;
          }
      }
      if (n < 0.2 * block_px * block_px) continue;  // mostly no data: too few pixels to judge
      const int t = otsu(hist);
      double n0 = 0, s0 = 0, s1 = 0;
      for (int k = 0; k < 256; ++k) (k <= t ? s0 : s1) += k * hist[k], n0 += k <= t ? hist[k] : 0;
      if (n0 <= 0 || n0 >= n) continue;
      const double m0 = s0 / n0, m1 = s1 / (n - n0);
      if (m1 - m0 <= min_contrast) continue;
      const double w = std::min(n0, n - n0);  // both classes present: the smaller class's pixel count
      L.at<float>(j, i) = static_cast<float>(m0 * w);
      H.at<float>(j, i) = static_cast<float>(m1 * w);
      W.at<float>(j, i) = static_cast<float>(w);
      sum_l += m0 * w;
      sum_h += m1 * w;
      sum_w += w;
    }
  const double gl = sum_w > 0 ? sum_l / sum_w : fallback_water, gh = sum_w > 0 ? sum_h / sum_w : fallback_ice;
  cv::GaussianBlur(W, W, cv::Size(0, 0), 1.0, 1.0, cv::BORDER_REFLECT);
  cv::GaussianBlur(L, L, cv::Size(0, 0), 1.0, 1.0, cv::BORDER_REFLECT);
  cv::GaussianBlur(H, H, cv::Size(0, 0), 1.0, 1.0, cv::BORDER_REFLECT);
  // A small prior weight pulls blocks without support to the image-wide levels.
  const float eps = static_cast<float>(1e-3 * (sum_w > 0 ? sum_w / (bx * by) : 1.0));
  L = (L + eps * static_cast<float>(gl)) / (W + eps);
  H = (H + eps * static_cast<float>(gh)) / (W + eps);
  // Bilinear between block centres (cv::resize maps block centres onto the pixel grid), then cropped.
  cv::Mat wl, il;
  cv::resize(L, wl, cv::Size(bx * block_px, by * block_px), 0, 0, cv::INTER_LINEAR);
  cv::resize(H, il, cv::Size(bx * block_px, by * block_px), 0, 0, cv::INTER_LINEAR);
  water = wl(cv::Rect(0, 0, img.cols, img.rows)).clone();
  ice = il(cv::Rect(0, 0, img.cols, img.rows)).clone();
}

// Fills the 8-connected non-ice components that touch neither the image border nor a no-data pixel and have
// at most max_px pixels (melt ponds and other water enclosed by ice).
void fill_small_holes(cv::Mat& ice, const cv::Mat& valid, double max_px) {
  const int R = ice.rows, C = ice.cols;
  cv::Mat comp, stats, cents;
  const int n = cv::connectedComponentsWithStats(~ice, comp, stats, cents, 8, CV_32S);
  std::vector<char> fill(n, 0);
  for (int k = 1; k < n; ++k) {
    const int x = stats.at<int>(k, cv::CC_STAT_LEFT), y = stats.at<int>(k, cv::CC_STAT_TOP);
    const int w = stats.at<int>(k, cv::CC_STAT_WIDTH), h = stats.at<int>(k, cv::CC_STAT_HEIGHT);
    fill[k] = x > 0 && y > 0 && x + w < C && y + h < R && stats.at<int>(k, cv::CC_STAT_AREA) <= max_px;
  }
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c)
      if (!valid.at<uint8_t>(r, c)) fill[comp.at<int>(r, c)] = 0;
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c)
      if (fill[comp.at<int>(r, c)]) ice.at<uint8_t>(r, c) = 255;
}

// Per-label bounding boxes (index = label) over labels 1..max_label.
std::vector<cv::Rect> label_boxes(const cv::Mat& lab, int max_label) {
  std::vector<int> r0(max_label + 1, INT32_MAX), r1(max_label + 1, -1), c0(max_label + 1, INT32_MAX),
      c1(max_label + 1, -1);
  for (int r = 0; r < lab.rows; ++r) {
    const int* p = lab.ptr<int>(r);
    for (int c = 0; c < lab.cols; ++c) {
      const int l = p[c];
      if (l <= 0) continue;
      r0[l] = std::min(r0[l], r);
      r1[l] = std::max(r1[l], r);
      c0[l] = std::min(c0[l], c);
      c1[l] = std::max(c1[l], c);
    }
  }
  std::vector<cv::Rect> boxes(max_label + 1);
  for (int l = 1; l <= max_label; ++l)
    if (r1[l] >= 0) boxes[l] = cv::Rect(c0[l], r0[l], c1[l] - c0[l] + 1, r1[l] - r0[l] + 1);
  return boxes;
}

// Mask of label l inside box, padded by one pixel of zeros all round.
cv::Mat padded_mask(const cv::Mat& lab, const cv::Rect& box, int l) {
  cv::Mat m(box.height + 2, box.width + 2, CV_8U, cv::Scalar(0));
  for (int r = 0; r < box.height; ++r) {
    const int* p = lab.ptr<int>(box.y + r) + box.x;
    uint8_t* q = m.ptr<uint8_t>(r + 1) + 1;
    for (int c = 0; c < box.width; ++c) q[c] = p[c] == l ? 255 : 0;
  }
  return m;
}

// Fills the holes of every region: the pixels of 8-connected non-region components enclosed by the region
// (not reaching the padding) join it, whatever they were (water, or another region it encloses). Holes that
// contain no-data pixels are left alone: no data is never ice.
void fill_region_holes(cv::Mat& lab, int max_label, const cv::Mat& valid) {
  const std::vector<cv::Rect> boxes = label_boxes(lab, max_label);
  for (int l = 1; l <= max_label; ++l) {
    const cv::Rect& box = boxes[l];
    if (box.width < 3 || box.height < 3) continue;  // too thin to enclose anything
    cv::Mat m = padded_mask(lab, box, l);
    cv::Mat comp;
    const int n = cv::connectedComponents(m == 0, comp, 8, CV_32S);
    if (n <= 2) continue;  // background is one component: no holes
    const int outside = comp.at<int>(0, 0);
    std::vector<char> hole(n, 1);
    hole[0] = 0;
    hole[outside] = 0;
    for (int r = 0; r < box.height; ++r)
      for (int c = 0; c < box.width; ++c)
        if (!valid.at<uint8_t>(box.y + r, box.x + c)) hole[comp.at<int>(r + 1, c + 1)] = 0;
    for (int r = 0; r < box.height; ++r)
      for (int c = 0; c < box.width; ++c)
        if (hole[comp.at<int>(r + 1, c + 1)]) lab.at<int>(box.y + r, box.x + c) = l;
  }
}

// Keeps the largest 4-connected part of every region; the rest becomes 0.
void keep_largest_part(cv::Mat& lab, int max_label) {
  const std::vector<cv::Rect> boxes = label_boxes(lab, max_label);
  for (int l = 1; l <= max_label; ++l) {
    const cv::Rect& box = boxes[l];
    if (box.width == 0) continue;
    cv::Mat m = padded_mask(lab, box, l);
    cv::Mat comp, stats, cents;
    const int n = cv::connectedComponentsWithStats(m, comp, stats, cents, 4, CV_32S);
    if (n <= 2) continue;
    int best = 1;
    for (int k = 2; k < n; ++k)
      if (stats.at<int>(k, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) best = k;
    for (int r = 0; r < box.height; ++r)
      for (int c = 0; c < box.width; ++c) {
        const int k = comp.at<int>(r + 1, c + 1);
        if (k > 0 && k != best) lab.at<int>(box.y + r, box.x + c) = 0;
      }
  }
}

// Removes every pixel of a region that is 8-adjacent to a region with a smaller label, so no two regions touch
// even diagonally (their outlines then stay at least a pixel apart and cannot overlap after simplification).
void separate_regions(cv::Mat& lab) {
  std::vector<cv::Point> drop;
  for (int r = 0; r < lab.rows; ++r)
    for (int c = 0; c < lab.cols; ++c) {
      const int l = lab.at<int>(r, c);
      if (l <= 0) continue;
      for (int k = 0; k < 8; ++k) {
        const int rr = r + kDr[k], cc = c + kDc[k];
        if (rr < 0 || cc < 0 || rr >= lab.rows || cc >= lab.cols) continue;
        const int m = lab.at<int>(rr, cc);
        if (m > 0 && m < l) {
          drop.emplace_back(c, r);
          break;
        }
      }
    }
  for (const cv::Point& p : drop) lab.at<int>(p) = 0;
}

// Union-find over seed labels (deterministic: the smaller label is the root).
struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  bool unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (b < a) std::swap(a, b);
    parent[b] = a;
    return true;
  }
};

}  // namespace

void reconstruct_by_dilation(cv::Mat& marker, const cv::Mat& mask, const cv::Mat& domain) {
  const int R = marker.rows, C = marker.cols, W = C + 2;
  // Flat copies with a one-pixel frame outside the domain, so the neighbours need no bounds checks.
  const size_t N = static_cast<size_t>(R + 2) * W;
  std::vector<float> f(N, 0.0f), g(N, 0.0f);
  std::vector<uint8_t> in(N, 0);
  for (int r = 0; r < R; ++r) {
    const float* pm = marker.ptr<float>(r);
    const float* pg = mask.ptr<float>(r);
    const uint8_t* pd = domain.ptr<uint8_t>(r);
    const size_t o = static_cast<size_t>(r + 1) * W + 1;
    for (int c = 0; c < C; ++c) {
      f[o + c] = pm[c];
      g[o + c] = pg[c];
      in[o + c] = pd[c] ? 1 : 0;
    }
  }
  // Causal (forward) and anti-causal halves of the 8-neighbourhood.
  const long fw[4] = {-W - 1, -W, -W + 1, -1}, bw[4] = {W + 1, W, W - 1, 1};
  for (int r = 0; r < R; ++r)
    for (size_t p = static_cast<size_t>(r + 1) * W + 1, e = p + C; p < e; ++p) {
      if (!in[p]) continue;
      float v = f[p];
      for (long d : fw)
        if (in[p + d]) v = std::max(v, f[p + d]);
      f[p] = std::min(v, g[p]);
    }
  std::deque<size_t> fifo;
  for (int r = R - 1; r >= 0; --r)
    for (size_t e = static_cast<size_t>(r + 1) * W + 1, p = e + C; p-- > e;) {
      if (!in[p]) continue;
      float v = f[p];
      for (long d : bw)
        if (in[p + d]) v = std::max(v, f[p + d]);
      v = std::min(v, g[p]);
      f[p] = v;
      for (long d : bw) {
        const size_t q = p + d;
        if (in[q] && f[q] < v && f[q] < g[q]) {
          fifo.push_back(p);
          break;
        }
      }
    }
  // Propagate what the two scans could not reach.
  const long all[8] = {-W - 1, -W, -W + 1, -1, 1, W - 1, W, W + 1};
  while (!fifo.empty()) {
    const size_t p = fifo.front();
    fifo.pop_front();
    const float v = f[p];
    for (long d : all) {
      const size_t q = p + d;
      if (!in[q]) continue;
      if (f[q] < v && f[q] != g[q]) {
        f[q] = std::min(v, g[q]);
        fifo.push_back(q);
      }
    }
  }
  for (int r = 0; r < R; ++r) {
    float* pm = marker.ptr<float>(r);
    const float* pd = &f[static_cast<size_t>(r + 1) * W + 1];
    for (int c = 0; c < C; ++c)
      if (domain.ptr<uint8_t>(r)[c]) pm[c] = pd[c];
  }
}

cv::Mat watershed_distance(const cv::Mat& markers, const cv::Mat& relief, const cv::Mat& domain) {
  const int R = markers.rows, C = markers.cols, W = C + 2;
  // Flat arrays with a one-pixel frame outside the domain, so the 8 neighbours need no bounds checks.
  std::vector<int> lab(static_cast<size_t>(R + 2) * W, 0), level(lab.size(), 0);
  std::vector<uint8_t> open(lab.size(), 0);  // in the domain and not yet queued
  // Hierarchical queue: the relief quantised to 1/16 (of a pixel of distance), one FIFO per level, highest level
  // first; FIFO order makes plateaus flood evenly and the result deterministic.
  constexpr double kLevelsPerUnit = 16;
  double lo = 0, hi = 0;
  cv::minMaxLoc(relief, &lo, &hi, nullptr, nullptr, domain);
  for (int r = 0; r < R; ++r) {
    const int* m = markers.ptr<int>(r);
    const float* f = relief.ptr<float>(r);
    const uint8_t* d = domain.ptr<uint8_t>(r);
    for (int c = 0; c < C; ++c) {
      const size_t p = static_cast<size_t>(r + 1) * W + c + 1;
      lab[p] = m[c];
      open[p] = d[c] && m[c] == 0;
      if (d[c]) level[p] = static_cast<int>((f[c] - lo) * kLevelsPerUnit);
    }
  }
  const int off[8] = {-W - 1, -W, -W + 1, -1, 1, W - 1, W, W + 1};
  const int n_levels = static_cast<int>((hi - lo) * kLevelsPerUnit) + 2;
  std::vector<std::vector<int>> fifo(n_levels);
  int current = n_levels - 1;
  auto push_neighbours = [&](int p) {
    for (int k = 0; k < 8; ++k) {
      const int q = p + off[k];
      if (!open[q]) continue;
      open[q] = 0;
      // A neighbour above the flood level is reached over the current level (it has no seed of its own).
      fifo[std::min(level[q], current)].push_back(q);
    }
  };
  for (int p = 0; p < static_cast<int>(lab.size()); ++p)
    if (lab[p] > 0) push_neighbours(p);
  for (; current >= 0; --current) {
    std::vector<int>& q = fifo[current];
    for (size_t i = 0; i < q.size(); ++i) {
      const int p = q[i];
      int label = 0;
      bool conflict = false;
      for (int k = 0; k < 8; ++k) {
        const int l = lab[p + off[k]];
        if (l <= 0) continue;
        if (label == 0)
          label = l;
        else if (l != label)
          conflict = true;
      }
      if (conflict || label == 0) {
        lab[p] = -1;  // on the line between two floods
        continue;
      }
      lab[p] = label;
      push_neighbours(p);
    }
    std::vector<int>().swap(q);
  }
  cv::Mat out(R, C, CV_32S);
  for (int r = 0; r < R; ++r) std::copy_n(&lab[static_cast<size_t>(r + 1) * W + 1], C, out.ptr<int>(r));
  return out;
}

namespace {

// 1. The valid (non-zero) pixels; an image with none is refused: it is no photograph of the ice.
void mark_valid(const cv::Mat& gray, const std::string& name, Segmentation& seg) {
  seg.valid = gray > 0;
  seg.valid_pixels = cv::countNonZero(seg.valid);
  FLOESIM_REQUIRE(seg.valid_pixels > 0, name,
                  ": every pixel is 0, which digitise reads as \"no data\" (outside the camera footprint); "
                  "is this the right image?");
}

// 1. The image as CV_32F, pre-smoothed against sensor noise and surface texture when smooth_px >= 0.3, normalised
// inside the footprint so no-data does not darken the pixels next to it.
cv::Mat presmoothed(const cv::Mat& gray, const cv::Mat& valid, double smooth_px) {
  cv::Mat g32;
  gray.convertTo(g32, CV_32F);
  if (smooth_px >= 0.3) {
    cv::Mat v32, num, den;
    valid.convertTo(v32, CV_32F, 1.0 / 255);
    cv::GaussianBlur(g32, num, cv::Size(0, 0), smooth_px, smooth_px, cv::BORDER_REFLECT);
    cv::GaussianBlur(v32, den, cv::Size(0, 0), smooth_px, smooth_px, cv::BORDER_REFLECT);
    g32 = num / cv::max(den, 1e-3f);
    g32.setTo(0, ~valid);
  }
  return g32;
}

// 2. Histogram of the valid pixels' grey levels; bin 0 (no data) emptied, so Otsu sees only the data.
std::array<double, 256> valid_histogram(const cv::Mat& g32, const cv::Mat& valid) {
  std::array<double, 256> hist{};
  for (int r = 0; r < g32.rows; ++r) {
    const float* p = g32.ptr<float>(r);
    const uint8_t* v = valid.ptr<uint8_t>(r);
    for (int c = 0; c < g32.cols; ++c)
      if (v[c]) hist[std::clamp(static_cast<int>(p[c] + 0.5f), 0, 255)] += 1;
  }
  hist[0] = 0;
  return hist;
}

// The first, global ice/water split.
struct GlobalSplit {
  int threshold = 0;      // Otsu's grey level
  double contrast = 0.0;  // ice minus water class mean; 0 if a class is empty
};

// 2. Otsu's global split and its two class means (recorded in seg): decides whether the image holds two classes.
GlobalSplit global_split(const std::array<double, 256>& hist, Segmentation& seg) {
  const int t = otsu(hist);
  double n0 = 0, s0 = 0, n1 = 0, s1 = 0;
  for (int i = 1; i < 256; ++i) {
    if (i <= t) {
      n0 += hist[i];
      s0 += i * hist[i];
    } else {
      n1 += hist[i];
      s1 += i * hist[i];
    }
  }
  seg.otsu_threshold = t;
  seg.water_grey = n0 > 0 ? s0 / n0 : 0;
  seg.ice_grey = n1 > 0 ? s1 / n1 : 0;
  return {t, (n0 > 0 && n1 > 0) ? seg.ice_grey - seg.water_grey : 0.0};
}

// 2. One class: its mean brightness decides which (the middle of the 8-bit range: water photographs dark, ice
// bright), with a warning; an error unless digitise.allow_one_class (a blank or wrongly exposed image would
// otherwise run on as one huge floe). Sets seg.classes; for "no_ice" also the empty labels. Returns true if all ice.
bool one_class_is_ice(const std::array<double, 256>& hist, double contrast, const DigitiseOptions& o,
                      const std::string& name, Segmentation& seg) {
  double sum = 0;
  for (int i = 1; i < 256; ++i) sum += i * hist[i];
  const double mean = sum / static_cast<double>(seg.valid_pixels);
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "ice-water contrast %.1f grey levels < min_contrast %.1f, mean grey %.1f: ", contrast, o.min_contrast,
                mean);
  FLOESIM_REQUIRE(o.allow_one_class, name, ": ", buf, mean < 128 ? "no ice found" : "no water found",
                  ": the image is one class (a uniform, blank or wrongly exposed image?), refused; if it is what you "
                  "meant, set digitise.allow_one_class to true (",
                  mean < 128 ? "no floes" : "each connected valid area one floe, concentration 1",
                  "), or lower digitise.min_contrast for an image of faint contrast");
  if (mean < 128) {
    seg.classes = "no_ice";
    seg.warnings.push_back(name + ": " + buf + "no ice found; the result has no floes");
    seg.labels = cv::Mat(seg.valid.rows, seg.valid.cols, CV_32S, cv::Scalar(0));
    return false;
  }
  seg.classes = "all_ice";
  seg.warnings.push_back(name + ": " + buf +
                         "no water found; floes cannot be separated without water between them, so each "
                         "connected valid area is one floe (concentration 1)");
  return true;
}

// The two-class split of step 2.
struct IceLevels {
  cv::Mat ice;    // CV_8U, 255 on ice
  cv::Mat norm;   // CV_32F normalised brightness (0 = local water level, 1 = local ice level)
  cv::Mat water;  // CV_32F local water level
  cv::Mat den;    // CV_32F local contrast, floored at half min_contrast
};

// 2. Two classes: the local water and ice levels ("local_otsu" blocks, or "two_class" masked averages refined
// twice) normalise the image, and ice is where the normalised brightness exceeds threshold_fraction.
IceLevels split_two_classes(const cv::Mat& g32, int t, double s, const DigitiseOptions& o, const Segmentation& seg) {
  IceLevels lv;
  lv.ice = seg.valid & (g32 > t);
  if (o.illumination == "local_otsu") {
    cv::Mat il;
    const int block_px = std::max(8, static_cast<int>(std::lround(o.local_block_m / s)));
    local_otsu_levels(g32, seg.valid, block_px, o.min_contrast, seg.water_grey, seg.ice_grey, lv.water, il);
    lv.den = cv::max(il - lv.water, 0.5 * o.min_contrast);
    lv.norm = (g32 - lv.water) / lv.den;
    lv.ice = seg.valid & (lv.norm > o.threshold_fraction);
  } else {
    const double sigma_px = o.illumination_scale_m / s;
    for (int pass = 0; pass < 2; ++pass) {
      const cv::Mat water = seg.valid & ~lv.ice;
      lv.water = masked_smooth(g32, water, sigma_px, seg.water_grey);
      const cv::Mat il = masked_smooth(g32, lv.ice, sigma_px, seg.ice_grey);
      // Local contrast floored at half the least contrast, so a patch with one class does not blow up.
      lv.den = cv::max(il - lv.water, 0.5 * o.min_contrast);
      lv.norm = (g32 - lv.water) / lv.den;
      lv.ice = seg.valid & (lv.norm > o.threshold_fraction);
    }
  }
  return lv;
}

// 2. Cracks: a dark line narrower than crack_width_m (the black top-hat: closing minus image) that is deeper than
// crack_depth of the local contrast separates two floes even where the threshold bridged it. No-data is set to
// the water level first, so the footprint's edge is not a crack.
void cut_cracks(const cv::Mat& g32, const IceLevels& lv, const cv::Mat& valid, double s, const DigitiseOptions& o,
                cv::Mat& ice) {
  const int crack_r = static_cast<int>(std::lround(o.crack_width_m / (2 * s)));
  if (o.crack_width_m > 0 && crack_r >= 1) {
    cv::Mat img = g32.clone(), closed;
    lv.water.copyTo(img, ~valid);
    const cv::Mat k = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * crack_r + 1, 2 * crack_r + 1));
    cv::morphologyEx(img, closed, cv::MORPH_CLOSE, k, cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
    const cv::Mat depth = (closed - img) / lv.den;
    ice.setTo(0, depth > o.crack_depth);
  }
}

// 3. Cleanup of a two-class ice mask: melt ponds filled, then an opening that removes thin bridges and specks.
void fill_ponds_and_open(cv::Mat& ice, const cv::Mat& valid, double s, double px_area, const DigitiseOptions& o) {
  fill_small_holes(ice, valid, o.max_hole_area_m2 / px_area);
  const int rad = static_cast<int>(std::lround(o.opening_radius_m / s));
  if (rad >= 1) {
    const cv::Mat k = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * rad + 1, 2 * rad + 1));
    cv::morphologyEx(ice, ice, cv::MORPH_OPEN, k);
  }
}

// 3. Brash: connected ice pieces below brash_cutoff_m2 are dropped (too small to be floes of their own).
void drop_brash(cv::Mat& ice, double px_area, const DigitiseOptions& o) {
  cv::Mat comp, stats, cents;
  const int n = cv::connectedComponentsWithStats(ice, comp, stats, cents, 4, CV_32S);
  std::vector<char> keep(n, 0);
  for (int k = 1; k < n; ++k) keep[k] = stats.at<int>(k, cv::CC_STAT_AREA) * px_area >= o.brash_cutoff_m2;
  for (int r = 0; r < ice.rows; ++r)
    for (int c = 0; c < ice.cols; ++c) ice.at<uint8_t>(r, c) = keep[comp.at<int>(r, c)] ? 255 : 0;
}

// The floe cores of step 4, per 4-connected ice piece.
struct Cores {
  cv::Mat norm_s;    // CV_32F normalised brightness, lightly smoothed
  cv::Mat piece;     // CV_32S ice pieces (0 = no ice)
  int n_pieces = 0;  // pieces + 1 (label 0 included)
  cv::Mat core;      // CV_8U, 255 on a core
};

// 4. The cores: smoothed normalised brightness above core_fraction of its ice piece's bright level (95th
// percentile, at most 1), so the dark line between floes leaves them even where blur bridged the gap, and a darker
// floe has a core too. core_fraction 0: the whole ice (its holes are filled already).
Cores find_cores(const cv::Mat& ice, const cv::Mat& norm, const cv::Mat& valid, double px_area,
                 const DigitiseOptions& o) {
  const int R = ice.rows, C = ice.cols;
  Cores k;
  cv::GaussianBlur(norm, k.norm_s, cv::Size(0, 0), 1.0);
  k.n_pieces = cv::connectedComponents(ice, k.piece, 4, CV_32S);
  std::vector<float> bright(k.n_pieces, 1.0f);
  if (o.core_fraction > 0) {
    std::vector<std::vector<float>> values(k.n_pieces);
    for (int r = 0; r < R; ++r)
      for (int c = 0; c < C; ++c)
        if (const int p = k.piece.at<int>(r, c)) values[p].push_back(k.norm_s.at<float>(r, c));
    for (int p = 1; p < k.n_pieces; ++p) {
      auto& v = values[p];
      auto q = v.begin() + static_cast<long>(0.95 * (v.size() - 1));
      std::nth_element(v.begin(), q, v.end());
      bright[p] = std::min(1.0f, *q);  // never above the local ice level: a bright piece keeps the plain rule
    }
  }
  k.core = cv::Mat(R, C, CV_8U, cv::Scalar(0));
  if (o.core_fraction > 0) {
    for (int r = 0; r < R; ++r)
      for (int c = 0; c < C; ++c)
        if (const int p = k.piece.at<int>(r, c))
          k.core.at<uint8_t>(r, c) = k.norm_s.at<float>(r, c) > o.core_fraction * bright[p] ? 255 : 0;
    fill_small_holes(k.core, valid, o.max_hole_area_m2 / px_area);
  } else {
    k.core = ice.clone();  // the shape alone splits (its holes are filled already)
  }
  return k;
}

// 4. The seeds: regional maxima of the h-maxima transform (h = marker_dynamic_m) of the core distance `dist`, so a
// bump must rise that much to be a floe of its own; an ice piece without one (a small floe) is seeded at its
// deepest pixel.
cv::Mat find_seeds(const cv::Mat& ice, const Cores& k, const cv::Mat& dist, double s, const DigitiseOptions& o) {
  const float h = static_cast<float>(o.marker_dynamic_m / s);
  cv::Mat rec = dist - h;
  reconstruct_by_dilation(rec, dist, k.core);
  // Regional maxima of the h-maxima transform (its plateaus with no higher neighbour): reconstruct it lowered
  // by a small epsilon; the regional maxima are where it stays lowered.
  const float eps = 1e-3f;
  cv::Mat rec2 = rec - eps;
  reconstruct_by_dilation(rec2, rec, k.core);
  cv::Mat seeds = k.core & ((rec - rec2) > 0.5f * eps);
  // An ice piece without core (a small floe) is seeded at its deepest pixel.
  cv::Mat ice_dist;
  if (o.core_fraction > 0)
    cv::distanceTransform(ice, ice_dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  else
    ice_dist = dist;
  std::vector<char> has_seed(k.n_pieces, 0);
  std::vector<float> best(k.n_pieces, -1);
  std::vector<cv::Point> where(k.n_pieces);
  for (int r = 0; r < ice.rows; ++r)
    for (int c = 0; c < ice.cols; ++c) {
      const int p = k.piece.at<int>(r, c);
      if (p == 0) continue;
      if (seeds.at<uint8_t>(r, c)) has_seed[p] = 1;
      if (ice_dist.at<float>(r, c) > best[p]) best[p] = ice_dist.at<float>(r, c), where[p] = cv::Point(c, r);
    }
  for (int p = 1; p < k.n_pieces; ++p)
    if (!has_seed[p]) seeds.at<uint8_t>(where[p]) = 255;
  return seeds;
}

// 4. The flooding relief: the core distance inside the core and the normalised brightness below it (every core
// pixel is >= 1 above it), so boundaries run along the darkest pixels between cores.
cv::Mat flooding_relief(const cv::Mat& ice, const Cores& k, const cv::Mat& dist) {
  cv::Mat relief = dist.clone();
  for (int r = 0; r < ice.rows; ++r)
    for (int c = 0; c < ice.cols; ++c)
      if (ice.at<uint8_t>(r, c) && !k.core.at<uint8_t>(r, c))
        relief.at<float>(r, c) = k.norm_s.at<float>(r, c) - 2.0f;  // below every core pixel (>= 1)
  return relief;
}

// 4. Seeds closer than sep_px within one ice piece are one floe: united in the returned union-find (over the
// seed labels 0..n_seeds; pairs found by a sweep over the seeds' deepest pixels sorted by x).
UnionFind merge_close_seeds(const cv::Mat& seed_lab, int n_seeds, const cv::Mat& dist, const cv::Mat& piece,
                            double sep_px) {
  std::vector<cv::Point> top(n_seeds + 1, cv::Point(-1, -1));
  std::vector<float> top_d(n_seeds + 1, -1);
  for (int r = 0; r < seed_lab.rows; ++r)
    for (int c = 0; c < seed_lab.cols; ++c) {
      const int l = seed_lab.at<int>(r, c);
      if (l > 0 && dist.at<float>(r, c) > top_d[l]) top_d[l] = dist.at<float>(r, c), top[l] = cv::Point(c, r);
    }
  UnionFind uf(n_seeds + 1);
  if (sep_px > 0) {
    std::vector<int> order(n_seeds);
    std::iota(order.begin(), order.end(), 1);
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return top[a].x < top[b].x || (top[a].x == top[b].x && a < b); });
    for (size_t i = 0; i < order.size(); ++i)
      for (size_t j = i + 1; j < order.size() && top[order[j]].x - top[order[i]].x < sep_px; ++j) {
        const cv::Point d = top[order[j]] - top[order[i]];
        if (std::hypot(d.x, d.y) < sep_px && piece.at<int>(top[order[i]]) == piece.at<int>(top[order[j]]))
          uf.unite(order[i], order[j]);
      }
  }
  return uf;
}

// 4. The first flooding: watershed of the relief inside the ice from the seeds, each labelled by its root.
cv::Mat flood_from_seeds(const cv::Mat& seed_lab, UnionFind& uf, const cv::Mat& relief, const cv::Mat& ice) {
  cv::Mat markers(seed_lab.rows, seed_lab.cols, CV_32S, cv::Scalar(0));
  for (int r = 0; r < seed_lab.rows; ++r)
    for (int c = 0; c < seed_lab.cols; ++c) {
      const int l = seed_lab.at<int>(r, c);
      if (l > 0) markers.at<int>(r, c) = uf.find(l);
    }
  return watershed_distance(markers, relief, ice);
}

// 4. Instead of flooding again: the merged pieces take their root's label, and the lines between pieces of one
// floe become floe: nearly what flooding again from the merged seeds gives (a boundary may differ by a pixel
// where three floods met), at a fraction of the cost.
void relabel_merged(cv::Mat& lab, UnionFind& uf) {
  const int R = lab.rows, C = lab.cols;
  for (int r = 0; r < R; ++r) {
    int* p = lab.ptr<int>(r);
    for (int c = 0; c < C; ++c)
      if (p[c] > 0) p[c] = uf.find(p[c]);
  }
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c) {
      if (lab.at<int>(r, c) != -1) continue;
      int u = 0;
      bool one = true;
      for (int k = 0; k < 8 && one; ++k) {
        const int rr = r + kDr[k], cc = c + kDc[k];
        if (rr < 0 || cc < 0 || rr >= R || cc >= C) continue;
        const int m = lab.at<int>(rr, cc);
        if (m <= 0) continue;
        if (u == 0) u = m;
        else if (m != u) one = false;
      }
      if (one && u > 0) lab.at<int>(r, c) = u;
    }
}

// The boundary between two floods.
struct Shared {
  int pixels = 0;
  float saddle = 0;  // its highest core distance
};

// The pieces of a flooding and the boundaries between them.
struct Pieces {
  std::vector<long long> area;                    // pixels per label
  std::vector<float> depth;                       // deepest core distance per label
  std::map<std::pair<int, int>, Shared> shared;  // boundary pixels between two floods (smaller label first)
};

// 4. Measures the pieces of the flooding `lab` (labels 1..n_seeds, -1 on the boundaries): area, depth, and the
// length and saddle of every boundary, which decide the rejoining.
Pieces measure_pieces(const cv::Mat& lab, const cv::Mat& dist, int n_seeds) {
  const int R = lab.rows, C = lab.cols;
  Pieces pc{std::vector<long long>(n_seeds + 1, 0), std::vector<float>(n_seeds + 1, 0.0f), {}};
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c) {
      const int l = lab.at<int>(r, c);
      if (l > 0) {
        ++pc.area[l];
        pc.depth[l] = std::max(pc.depth[l], dist.at<float>(r, c));
      }
      if (l != -1) continue;
      int found[8], nf = 0;
      for (int k = 0; k < 8; ++k) {
        const int rr = r + kDr[k], cc = c + kDc[k];
        if (rr < 0 || cc < 0 || rr >= R || cc >= C) continue;
        const int m = lab.at<int>(rr, cc);
        if (m > 0 && std::find(found, found + nf, m) == found + nf) found[nf++] = m;
      }
      for (int a = 0; a < nf; ++a)
        for (int b = a + 1; b < nf; ++b) {
          Shared& sh = pc.shared[{std::min(found[a], found[b]), std::max(found[a], found[b])}];
          ++sh.pixels;
          sh.saddle = std::max(sh.saddle, dist.at<float>(r, c));
        }
    }
  return pc;
}

// 4. Rejoins pieces in `uf`: two whose shared boundary is not a neck (its saddle reaches neck_ratio of the smaller
// piece's depth) are one floe with a dent; a piece below min_px joins the neighbour it shares the longest boundary
// with. A boundary through the dark band between cores has saddle 0 and stays. Returns the merges made.
int rejoin_pieces(const Pieces& pc, int n_seeds, double min_px, double neck_ratio, UnionFind& uf) {
  std::vector<std::pair<int, int>> best(n_seeds + 1, {0, 0});  // (shared pixels, neighbour)
  int merged = 0;
  for (const auto& [pair, sh] : pc.shared) {
    const auto [a, b] = pair;
    if (sh.pixels > best[a].first || (sh.pixels == best[a].first && b < best[a].second)) best[a] = {sh.pixels, b};
    if (sh.pixels > best[b].first || (sh.pixels == best[b].first && a < best[b].second)) best[b] = {sh.pixels, a};
    if (sh.saddle > 0 && sh.saddle >= neck_ratio * std::min(pc.depth[a], pc.depth[b])) merged += uf.unite(a, b);
  }
  for (int l = 1; l <= n_seeds; ++l)
    if (pc.area[l] > 0 && pc.area[l] < min_px && best[l].second > 0) merged += uf.unite(l, best[l].second);
  return merged;
}

// 4. Outline refinement: the ice threshold sits below the half-contrast level (to keep dark floes), so the
// outlines of bright floes run a pixel or so outside their edge. Within band_px of its outline, a floe keeps only
// the pixels brighter than edge_fraction of its own median brightness: each floe's edge at its own half level.
void refine_outlines(cv::Mat& lab, int max_label, const cv::Mat& norm, float band_px, double edge_fraction) {
  const int R = lab.rows, C = lab.cols;
  std::vector<std::vector<float>> values(max_label + 1);
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c)
      if (const int l = lab.at<int>(r, c); l > 0) values[l].push_back(norm.at<float>(r, c));
  std::vector<float> median(max_label + 1, 0.0f);
  for (int l = 1; l <= max_label; ++l)
    if (auto& v = values[l]; !v.empty()) {
      std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
      median[l] = v[v.size() / 2];
    }
  cv::Mat not_edge(R, C, CV_8U, cv::Scalar(255));  // 0 on pixels with a 4-neighbour of another label
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c) {
      const int l = lab.at<int>(r, c);
      if (l <= 0) continue;
      if ((r > 0 && lab.at<int>(r - 1, c) != l) || (r + 1 < R && lab.at<int>(r + 1, c) != l) ||
          (c > 0 && lab.at<int>(r, c - 1) != l) || (c + 1 < C && lab.at<int>(r, c + 1) != l))
        not_edge.at<uint8_t>(r, c) = 0;
    }
  cv::Mat to_edge;
  cv::distanceTransform(not_edge, to_edge, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c) {
      int& l = lab.at<int>(r, c);
      if (l > 0 && to_edge.at<float>(r, c) < band_px && norm.at<float>(r, c) < edge_fraction * median[l]) l = 0;
    }
}

// 4. Splitting touching floes of a two-class image, by the dark line between floes (the cores) and the neck of
// the outline (h-maxima of the core distance): seeds, watershed, rejoining (at most 8 rounds), outline
// refinement. Counts seeds and merges in seg; returns the labels (0 = no floe, 1..max_label) in `lab` and
// max_label (the number of seeds).
int split_touching_floes(const cv::Mat& ice, const cv::Mat& norm, double s, double px_area,
                         const DigitiseOptions& o, Segmentation& seg, cv::Mat& lab) {
  const Cores k = find_cores(ice, norm, seg.valid, px_area, o);
  cv::Mat dist;
  cv::distanceTransform(k.core, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  const cv::Mat seeds = find_seeds(ice, k, dist, s, o);
  const cv::Mat relief = flooding_relief(ice, k, dist);
  cv::Mat seed_lab;
  const int n_seeds = cv::connectedComponents(seeds, seed_lab, 8, CV_32S) - 1;
  UnionFind uf = merge_close_seeds(seed_lab, n_seeds, dist, k.piece, o.min_marker_separation_m / s);

  const double min_px = o.min_floe_area_m2 / px_area;
  lab = flood_from_seeds(seed_lab, uf, relief, ice);
  for (int iter = 0; iter < 8; ++iter) {
    if (iter > 0) relabel_merged(lab, uf);
    const int merged = rejoin_pieces(measure_pieces(lab, dist, n_seeds), n_seeds, min_px, o.neck_ratio, uf);
    seg.merged_pieces += merged;
    if (merged == 0) break;
  }
  lab.setTo(0, lab < 0);
  for (int l = 1; l <= n_seeds; ++l) seg.seeds += uf.find(l) == l;

  if (o.edge_fraction > 0 && o.edge_band_m > 0)
    refine_outlines(lab, n_seeds, norm, static_cast<float>(o.edge_band_m / s), o.edge_fraction);
  return n_seeds;
}

// 5. Regions: holes filled (a region enclosed by another joins it), never 8-adjacent, each its largest
// 4-connected part, holes filled again.
void clean_regions(cv::Mat& lab, int max_label, const cv::Mat& valid) {
  fill_region_holes(lab, max_label, valid);
  separate_regions(lab);
  keep_largest_part(lab, max_label);
  fill_region_holes(lab, max_label, valid);
}

// 5. Drops the regions below min_px and numbers the rest 1..N in raster order of their first pixel; returns N.
int number_regions(cv::Mat& lab, int max_label, double min_px) {
  std::vector<long long> area(max_label + 1, 0);
  for (int r = 0; r < lab.rows; ++r)
    for (int c = 0; c < lab.cols; ++c)
      if (lab.at<int>(r, c) > 0) ++area[lab.at<int>(r, c)];
  std::vector<int> renum(max_label + 1, 0);
  int next = 0;
  for (int r = 0; r < lab.rows; ++r) {
    int* p = lab.ptr<int>(r);
    for (int c = 0; c < lab.cols; ++c) {
      const int l = p[c];
      if (l <= 0) continue;
      if (area[l] < min_px) {
        p[c] = 0;
        continue;
      }
      if (renum[l] == 0) renum[l] = ++next;
      p[c] = renum[l];
    }
  }
  return next;
}

}  // namespace

Segmentation segment_floes(const cv::Mat& gray, double s, const DigitiseOptions& o, const std::string& name) {
  CV_Assert(gray.type() == CV_8UC1);
  Segmentation seg;
  const double px_area = s * s;

  // 1. No data; pre-smoothing.
  mark_valid(gray, name, seg);
  const cv::Mat g32 = presmoothed(gray, seg.valid, o.smoothing_m / s);

  // 2. Ice / water: a global split; one class is all ice or no ice, two are split by their local levels.
  const std::array<double, 256> hist = valid_histogram(g32, seg.valid);
  const GlobalSplit split = global_split(hist, seg);
  cv::Mat ice, norm;
  if (split.contrast < o.min_contrast) {
    if (!one_class_is_ice(hist, split.contrast, o, name, seg)) return seg;
    ice = seg.valid.clone();
  } else {
    seg.classes = "mixed";
    const IceLevels lv = split_two_classes(g32, split.threshold, s, o, seg);
    ice = lv.ice;
    norm = lv.norm;
    cut_cracks(g32, lv, seg.valid, s, o, ice);
    // 3. Cleanup: melt ponds, opening (brash below, for every image with ice).
    fill_ponds_and_open(ice, seg.valid, s, px_area, o);
  }
  drop_brash(ice, px_area, o);

  // 4. Splitting touching floes (all ice: each connected valid area is one floe).
  cv::Mat lab;
  int max_label = 0;
  if (seg.classes == "all_ice")
    max_label = cv::connectedComponents(ice, lab, 4, CV_32S) - 1;
  else
    max_label = split_touching_floes(ice, norm, s, px_area, o, seg, lab);

  // 5. Regions.
  clean_regions(lab, max_label, seg.valid);
  const int next = number_regions(lab, max_label, o.min_floe_area_m2 / px_area);
  seg.labels = lab;
  seg.norm = norm;
  seg.floes = next;
  if (seg.classes == "mixed" && next == 0)
    seg.warnings.push_back(name + ": no floe larger than min_floe_area_m2 = " + std::to_string(o.min_floe_area_m2) +
                           " m^2 was found; the result has no floes");
  return seg;
}

}  // namespace floesim::imaging
