#include "sim/vessel/particulars.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"

namespace floesim::sim {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string num(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

double deg(double rad) { return rad * 180.0 / kPi; }

// A segment of a plane section, in the plane's two coordinates (for z = c: (x, y); for y = c: (x, z)).
struct Seg {
  Vec2 p, q;
};

// The section of a triangle mesh by the plane {coordinate `axis` = value}, as segments. Vertices lying on the plane
// are handled (the generated hull has its waterline knuckle exactly at z = 0): a triangle touching the plane along
// an edge gives that edge, one lying in it gives its three edges, one touching it at a single vertex nothing.
std::vector<Seg> section(const TriMesh& m, int axis, double value) {
  const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
  std::vector<Seg> out;
  for (const auto& t : m.triangles) {
    const Vec3* p[3] = {&m.vertices[t[0]], &m.vertices[t[1]], &m.vertices[t[2]]};
    double d[3];
    for (int k = 0; k < 3; ++k) d[k] = (*p[k])[axis] - value;
    if ((d[0] > 0 && d[1] > 0 && d[2] > 0) || (d[0] < 0 && d[1] < 0 && d[2] < 0)) continue;
    Vec2 pts[3];
    int n = 0;
    for (int k = 0; k < 3; ++k)
      if (d[k] == 0) pts[n++] = Vec2((*p[k])[u], (*p[k])[v]);
    for (int k = 0; k < 3 && n < 3; ++k) {
      int a = k, b = (k + 1) % 3;
      if (!((d[a] < 0 && d[b] > 0) || (d[a] > 0 && d[b] < 0))) continue;
      // From the lexicographically smaller end, so that the two triangles sharing an edge cut it into the same point
      // to the bit, and the section's pieces can be joined by their end points.
      if (std::lexicographical_compare(p[b]->data(), p[b]->data() + 3, p[a]->data(), p[a]->data() + 3))
        std::swap(a, b);
      const Vec3 x = *p[a] + (d[a] / (d[a] - d[b])) * (*p[b] - *p[a]);
      pts[n++] = Vec2(x[u], x[v]);
    }
    if (n == 2) out.push_back({pts[0], pts[1]});
    if (n == 3)
      for (int k = 0; k < 3; ++k) out.push_back({pts[k], pts[(k + 1) % 3]});
  }
  return out;
}

// The range [lo, hi] of the second coordinate over the section's points whose first coordinate is t (coordinate
// `by` = 0 or 1 is the one fixed); false if no segment reaches t.
bool range_at(const std::vector<Seg>& s, int by, double t, double& lo, double& hi) {
  const int other = 1 - by;
  lo = kInf, hi = -kInf;
  for (const Seg& g : s) {
    const double a = g.p[by], b = g.q[by];
    if (t < std::min(a, b) || t > std::max(a, b)) continue;
    if (a == b) {
      lo = std::min({lo, g.p[other], g.q[other]});
      hi = std::max({hi, g.p[other], g.q[other]});
    } else {
      const double w = g.p[other] + (t - a) / (b - a) * (g.q[other] - g.p[other]);
      lo = std::min(lo, w), hi = std::max(hi, w);
    }
  }
  return lo <= hi;
}

// Slope of the least-squares line through (s_k, f_k).
double ls_slope(const std::vector<double>& s, const std::vector<double>& f) {
  double sm = 0, fm = 0;
  for (size_t k = 0; k < s.size(); ++k) sm += s[k], fm += f[k];
  sm /= s.size(), fm /= f.size();
  double num = 0, den = 0;
  for (size_t k = 0; k < s.size(); ++k) num += (s[k] - sm) * (f[k] - fm), den += (s[k] - sm) * (s[k] - sm);
  return num / den;
}

constexpr int kFitSamples = 21;        // samples of a least-squares fit (the fitted lines are straight on the
                                       // generated hull; on a real one 21 points average its facets)
constexpr int kParallelSamples = 4000;  // half-breadth samples along L before the ends are bisected

// Angle (deg) between the waterline (+x) and the forward-most line of the section `s` (in (x, z)) over z in
// [-depth, 0]: 90 for a vertical stem, less for one raked forward.
double profile_angle_deg(const std::vector<Seg>& s, double depth, const std::string& where, const std::string& what) {
  std::vector<double> z(kFitSamples), x(kFitSamples);
  for (int k = 0; k < kFitSamples; ++k) {
    z[k] = -depth * k / (kFitSamples - 1);
    double lo, hi;
    FLOESIM_REQUIRE(range_at(s, 1, z[k], lo, hi), where, ": the hull has no surface on ", what, " at z = ",
                    num(z[k]), " m, where its bow angles are measured (over z in [-T/4, 0], T = ",
                    num(depth / ParticularsDefinition::kStemDepthDraught), " m)");
    x[k] = hi;
  }
  // x rises with z on a stem raked forward: dx/dz = 1/tan(phi).
  return deg(std::atan2(1.0, ls_slope(z, x)));
}

}  // namespace

double lowest_z_at(const TriMesh& m, double x) {
  double lo = kInf;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const Vec3 &a = m.vertices[t[k]], &b = m.vertices[t[(k + 1) % 3]];
      if ((a.x() - x) * (b.x() - x) > 0 || a.x() == b.x()) continue;
      lo = std::min(lo, a.z() + (b.z() - a.z()) * ((x - a.x()) / (b.x() - a.x())));
    }
  return lo;
}

HullParticulars measure_particulars(const TriMesh& surface, const std::string& where) {
  using D = ParticularsDefinition;
  HullParticulars r;
  for (const Vec3& v : surface.vertices)
    FLOESIM_REQUIRE(v.allFinite(), where, ": the hull has a vertex that is not a finite number");
  // 1. The waterline and its main part: the section's segments joined where they share an end point (exactly: see
  //    section()) into connected pieces; the piece of longest x extent is the hull's waterline. A rudder that pierces
  //    the water is a closed outline of its own even where it lies under the hull's counter (KCS).
  std::vector<Seg> wl = section(surface, 2, 0.0);
  FLOESIM_REQUIRE(!wl.empty(), where, ": the hull does not cross the waterline z = 0 (no waterline to measure)");
  std::map<std::pair<double, double>, int> point_id;
  std::vector<int> parent;
  auto id_of = [&](const Vec2& p) {
    const auto [it, fresh] = point_id.emplace(std::make_pair(p.x(), p.y()), static_cast<int>(parent.size()));
    if (fresh) parent.push_back(it->second);
    return it->second;
  };
  auto root = [&](int i) {  // union-find, iterative (a waterline may have many thousand points)
    int top = i;
    while (parent[top] != top) top = parent[top];
    while (parent[i] != top) i = std::exchange(parent[i], top);
    return top;
  };
  std::vector<std::pair<int, int>> ends;
  for (const Seg& g : wl) {
    ends.emplace_back(id_of(g.p), id_of(g.q));
    const int a = root(ends.back().first), b = root(ends.back().second);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  std::map<int, std::pair<double, double>> extent;  // root -> x range
  for (size_t i = 0; i < wl.size(); ++i) {
    const auto it = extent.emplace(root(ends[i].first), std::make_pair(kInf, -kInf)).first;
    it->second.first = std::min({it->second.first, wl[i].p.x(), wl[i].q.x()});
    it->second.second = std::max({it->second.second, wl[i].p.x(), wl[i].q.x()});
  }
  int main_piece = extent.begin()->first;
  for (const auto& [k, e] : extent)
    if (e.second - e.first > extent[main_piece].second - extent[main_piece].first) main_piece = k;
  std::vector<Seg> kept;
  for (size_t i = 0; i < wl.size(); ++i)
    if (root(ends[i].first) == main_piece) kept.push_back(wl[i]);
  wl.swap(kept);
  const double best_lo = extent[main_piece].first, best_hi = extent[main_piece].second;
  r.x_aft_m = best_lo, r.x_stem_m = best_hi;
  r.length_m = best_hi - best_lo;
  double y_lo = kInf, y_hi = -kInf;
  for (const Seg& g : wl) y_lo = std::min({y_lo, g.p.y(), g.q.y()}), y_hi = std::max({y_hi, g.p.y(), g.q.y()});
  r.beam_m = y_hi - y_lo;
  r.centreline_y_m = 0.5 * (y_lo + y_hi);
  FLOESIM_REQUIRE(r.length_m > 0 && r.beam_m > 0, where, ": the waterline z = 0 has no area (length ",
                  num(r.length_m), " m, beam ", num(r.beam_m), " m)");
  const double yc = r.centreline_y_m, B = r.beam_m;

  // 2. Draught at mid waterline length.
  r.draught_m = -lowest_z_at(surface, 0.5 * (r.x_aft_m + r.x_stem_m));
  FLOESIM_REQUIRE(std::isfinite(r.draught_m) && r.draught_m > 0, where,
                  ": no hull below the waterline at mid waterline length (x = ",
                  num(0.5 * (r.x_aft_m + r.x_stem_m)), " m)");
  const double depth = D::kStemDepthDraught * r.draught_m;

  // 3. Stem angle on the centreline, bow angle on the buttocks at B/4.
  r.stem_angle_deg = profile_angle_deg(section(surface, 1, yc), depth, where, "the centreline");
  const double b4 = D::kEntranceAtBeam * B;
  r.bow_angle_b4_deg = 0.5 * (profile_angle_deg(section(surface, 1, yc + b4), depth, where, "the buttock at +B/4") +
                              profile_angle_deg(section(surface, 1, yc - b4), depth, where, "the buttock at -B/4"));

  // 4. Entrance angle: the waterline's forward edge x(|y - y_c|) over B/4 +- B/40, both sides averaged.
  {
    std::vector<double> y(kFitSamples), x(kFitSamples);
    for (int k = 0; k < kFitSamples; ++k) {
      y[k] = b4 + D::kEntranceBandBeam * B * (2.0 * k / (kFitSamples - 1) - 1.0);
      double l0, h0, l1, h1;
      FLOESIM_REQUIRE(range_at(wl, 1, yc + y[k], l0, h0) && range_at(wl, 1, yc - y[k], l1, h1), where,
                      ": the waterline has no edge at |y - y_c| = ", num(y[k]), " m (where alpha is measured)");
      x[k] = 0.5 * (h0 + h1);
    }
    // The forward edge falls back (x decreases) going outboard on a normal bow: tan(alpha) = -dy/dx.
    r.entrance_angle_deg = deg(std::atan2(1.0, -ls_slope(y, x)));
  }
  // psi = arctan(tan phi / sin alpha), as atan2 so that a vertical stem gives 90 deg rather than a division by zero.
  const double sa = std::sin(r.entrance_angle_deg * kPi / 180.0);
  auto flare = [&](double phi_deg) {
    const double phi = phi_deg * kPi / 180.0;
    return deg(std::atan2(std::sin(phi), std::cos(phi) * sa));
  };
  r.normal_flare_deg = flare(r.stem_angle_deg);
  r.normal_flare_b4_deg = flare(r.bow_angle_b4_deg);

  // 5. Parallel midbody: the longest run of samples whose half-breadth is within the tolerance of B/2, its ends
  //    bisected to round-off (the half-breadth is piecewise linear in x, so the crossings are sharp).
  const double need = (1.0 - D::kParallelTolerance) * 0.5 * B;
  auto parallel = [&](double x) {
    double a, b;
    return range_at(wl, 0, x, a, b) && 0.5 * (b - a) >= need;
  };
  auto x_at = [&](int i) { return r.x_aft_m + r.length_m * i / (kParallelSamples - 1); };
  int run0 = -1, run1 = -1;
  for (int i = 0, start = -1; i < kParallelSamples; ++i) {
    if (parallel(x_at(i))) {
      if (start < 0) start = i;
      if (run0 < 0 || i - start > run1 - run0) run0 = start, run1 = i;
    } else {
      start = -1;
    }
  }
  auto bisect = [&](double in, double out) {  // parallel(in) holds, parallel(out) does not
    for (int k = 0; k < 60; ++k) {
      const double m = 0.5 * (in + out);
      (parallel(m) ? in : out) = m;
    }
    return in;
  };
  if (run0 < 0) {  // an asymmetric waterline whose half-breadth never nears B/2: no parallel midbody
    r.x_parallel_aft_m = r.x_parallel_fwd_m = r.x_stem_m;
  } else {
    r.x_parallel_aft_m = run0 > 0 ? bisect(x_at(run0), x_at(run0 - 1)) : x_at(run0);
    r.x_parallel_fwd_m = run1 < kParallelSamples - 1 ? bisect(x_at(run1), x_at(run1 + 1)) : x_at(run1);
  }
  r.parallel_midbody_m = r.x_parallel_fwd_m - r.x_parallel_aft_m;
  r.bow_length_m = r.x_stem_m - r.x_parallel_fwd_m;
  return r;
}

nlohmann::json particulars_json(const HullParticulars& p) {
  nlohmann::json j;
  j["length_m"] = p.length_m;
  j["beam_m"] = p.beam_m;
  j["draught_m"] = p.draught_m;
  j["stem_angle_deg"] = p.stem_angle_deg;
  j["entrance_angle_deg"] = p.entrance_angle_deg;
  j["normal_flare_deg"] = p.normal_flare_deg;
  j["bow_angle_b4_deg"] = p.bow_angle_b4_deg;
  j["normal_flare_b4_deg"] = p.normal_flare_b4_deg;
  j["parallel_midbody_m"] = p.parallel_midbody_m;
  j["bow_length_m"] = p.bow_length_m;
  j["x_waterline_m"] = {p.x_aft_m, p.x_stem_m};
  j["x_parallel_midbody_m"] = {p.x_parallel_aft_m, p.x_parallel_fwd_m};
  j["centreline_y_m"] = p.centreline_y_m;
  j["definitions"] = {
      {"waterline", "section z = 0; its longest continuous stretch in x (a rudder piercing the water apart from the "
                    "hull is left out)"},
      {"length_m", "L: x extent of the waterline (L_wl)"},
      {"beam_m", "B: y extent of the waterline; centreline_y_m is its middle"},
      {"draught_m", "T: depth of the keel at mid waterline length"},
      {"stem_angle_deg", "phi: angle of the stem to the waterline on the centreline, least-squares over z in "
                         "[-T/4, 0] (90: vertical)"},
      {"entrance_angle_deg", "alpha: angle of the waterline to the centreline at B/4, least-squares over B/4 +- B/40, "
                             "both sides (90: square across)"},
      {"normal_flare_deg", "psi = arctan(tan phi / sin alpha) (Lindqvist)"},
      {"bow_angle_b4_deg", "phi_B4: as phi, on the buttocks at +-B/4"},
      {"normal_flare_b4_deg", "psi_B4 = arctan(tan phi_B4 / sin alpha): slope of the bow surface across the "
                              "waterline at B/4"},
      {"parallel_midbody_m", "L_par: longest stretch where the waterline half-breadth is >= 99 % of B/2"},
      {"bow_length_m", "L_bow: from the forward end of the parallel midbody to the stem at the waterline"}};
  return j;
}

}  // namespace floesim::sim
