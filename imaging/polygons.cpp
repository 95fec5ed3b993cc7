#include "imaging/polygons.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>

#include "imaging/shapes.h"

namespace floesim::imaging {

std::vector<cv::Point2d> trace_region_boundary(const cv::Mat& mask) {
  CV_Assert(mask.type() == CV_8UC1);
  auto inside = [&](int c, int r) {
    return r >= 0 && c >= 0 && r < mask.rows && c < mask.cols && mask.at<uint8_t>(r, c);
  };
  int c0 = -1, r0 = -1;
  for (int r = 0; r < mask.rows && c0 < 0; ++r)
    for (int c = 0; c < mask.cols; ++c)
      if (mask.at<uint8_t>(r, c)) {
        c0 = c;
        r0 = r;
        break;
      }
  if (c0 < 0) return {};
  // Directions in corner coordinates (y down): 0 = +x, 1 = +y, 2 = -x, 3 = -y; (d + 1) % 4 is a right turn.
  static const int dx[4] = {1, 0, -1, 0}, dy[4] = {0, 1, 0, -1};
  // Start on the top edge of the first pixel, heading +x, with the region on the right.
  int x = c0, y = r0, d = 0;
  const int x0 = x, y0 = y, d0 = d;
  std::vector<cv::Point2d> pts;
  do {
    pts.emplace_back(x + 0.5 * dx[d], y + 0.5 * dy[d]);
    x += dx[d];
    y += dy[d];
    const int rd = (d + 1) % 4, ld = (d + 3) % 4;
    // The two pixels ahead of the vertex, right and left of the heading ((s - 1) / 2 maps -1, 1 to -1, 0).
    const int ar_c = x + (dx[d] + dx[rd] - 1) / 2, ar_r = y + (dy[d] + dy[rd] - 1) / 2;
    const int al_c = x + (dx[d] + dx[ld] - 1) / 2, al_r = y + (dy[d] + dy[ld] - 1) / 2;
    if (!inside(ar_c, ar_r))
      d = rd;  // convex corner, or a diagonal contact: stay with the pixel we are following
    else if (inside(al_c, al_r))
      d = ld;  // concave corner
  } while (!(x == x0 && y == y0 && d == d0));
  return pts;
}

namespace {

struct Region {
  cv::Rect box;
  std::vector<cv::Point2f> ring;  // traced ring, corner coordinates relative to box.tl()
  int level = 0;                  // 0: requested tolerance, 1: fine tolerance, 2: traced ring
};

bool valid_outline(const Polygon& p) {
  return p.size() >= 3 && std::abs(signed_area(p)) > 0 && find_self_intersection(p).first < 0;
}

Polygon to_metres(const std::vector<cv::Point2f>& pts, const cv::Rect& box, const PixelGrid& g) {
  Polygon p;
  p.reserve(pts.size());
  for (const cv::Point2f& q : pts) p.push_back(g.corner_to_metres(box.x + double(q.x), box.y + double(q.y)));
  p = clean_polygon(p, 1e-9 * g.metres_per_pixel);
  make_ccw(p);
  return p;
}

// Douglas-Peucker at tol_px with the fallbacks described in the header; `fallbacks` counts the retreats.
Polygon simplify(const Region& reg, double tol_px, const PixelGrid& g, int* fallbacks) {
  for (double t = tol_px; t > 0.05; t *= 0.5) {
    std::vector<cv::Point2f> out;
    cv::approxPolyDP(reg.ring, out, t, true);
    Polygon p = to_metres(out, reg.box, g);
    if (valid_outline(p)) return p;
    if (fallbacks) ++*fallbacks;
  }
  return to_metres(reg.ring, reg.box, g);
}

}  // namespace

std::vector<Polygon> polygonize_labels(const cv::Mat& labels, int n, const PixelGrid& g, double tolerance_m,
                                       PolygonizeReport* report) {
  PolygonizeReport rep;
  std::vector<Region> regs(n + 1);
  {
    std::vector<int> r0(n + 1, INT32_MAX), r1(n + 1, -1), c0(n + 1, INT32_MAX), c1(n + 1, -1);
    for (int r = 0; r < labels.rows; ++r) {
      const int* p = labels.ptr<int>(r);
      for (int c = 0; c < labels.cols; ++c) {
        const int l = p[c];
        if (l <= 0 || l > n) continue;
        r0[l] = std::min(r0[l], r);
        r1[l] = std::max(r1[l], r);
        c0[l] = std::min(c0[l], c);
        c1[l] = std::max(c1[l], c);
      }
    }
    for (int l = 1; l <= n; ++l) {
      CV_Assert(r1[l] >= 0);  // labels are 1..n without gaps
      // One pixel of margin all round, so the traced ring (which may reach the margin) stays inside the mask.
      regs[l].box = cv::Rect(c0[l] - 1, r0[l] - 1, c1[l] - c0[l] + 3, r1[l] - r0[l] + 3);
    }
  }
  const double tol_px = tolerance_m / g.metres_per_pixel;
  const double fine_px = std::min(tol_px, 0.3);
  std::vector<Polygon> out(n + 1);
  for (int l = 1; l <= n; ++l) {
    Region& reg = regs[l];
    cv::Mat m(reg.box.height, reg.box.width, CV_8U, cv::Scalar(0));
    for (int r = 1; r < m.rows - 1; ++r) {
      const int* p = labels.ptr<int>(reg.box.y + r) + reg.box.x;
      uint8_t* q = m.ptr<uint8_t>(r);
      for (int c = 1; c < m.cols - 1; ++c) q[c] = p[c] == l ? 255 : 0;
    }
    const std::vector<cv::Point2d> ring = trace_region_boundary(m);
    reg.ring.reserve(ring.size());
    for (const cv::Point2d& q : ring) reg.ring.emplace_back(static_cast<float>(q.x), static_cast<float>(q.y));
    out[l] = simplify(reg, tol_px, g, &rep.simplify_fallbacks);
  }

  // Neighbours whose simplified outlines overlap or touch are redone finer (both), until none do.
  for (int round = 0;; ++round) {
    std::vector<BBox> boxes(n + 1);
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 1);
    for (int l = 1; l <= n; ++l) boxes[l] = bounding_box(out[l]);
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return boxes[a].x0 < boxes[b].x0 || (boxes[a].x0 == boxes[b].x0 && a < b); });
    std::vector<char> redo(n + 1, 0);
    int overlaps = 0;
    for (size_t i = 0; i < order.size(); ++i)
      for (size_t j = i + 1; j < order.size() && boxes[order[j]].x0 <= boxes[order[i]].x1; ++j) {
        const int a = order[i], b = order[j];
        if (!boxes[a].overlaps(boxes[b]) || !polygons_within(out[a], out[b], 0)) continue;
        ++overlaps;
        redo[a] = redo[b] = 1;
      }
    rep.overlaps_remaining = overlaps;
    if (overlaps == 0 || round == 3) break;  // every outline is at the traced ring after two redos
    for (int l = 1; l <= n; ++l) {
      if (!redo[l] || regs[l].level >= 2) continue;
      ++regs[l].level;
      ++rep.overlap_fallbacks;
      out[l] = regs[l].level == 1 ? simplify(regs[l], fine_px, g, &rep.simplify_fallbacks)
                                  : to_metres(regs[l].ring, regs[l].box, g);
    }
  }
  if (report) *report = rep;
  out.erase(out.begin());
  return out;
}

}  // namespace floesim::imaging
