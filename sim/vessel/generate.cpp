// The parametric icebreaker (generate_hull, write_generated_hull) and the OBJ writer (write_obj).
#include "sim/vessel/hull.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <Eigen/Geometry>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/provenance.h"
#include "pipeline/geometry2d.h"
#include "sim/vessel/hull_internal.h"

namespace floesim::sim {

namespace fs = std::filesystem;
using namespace detail;

namespace {

double deg(double d) { return d * kPi / 180.0; }

// 0 -> 0, 1 -> 1 with zero slope at both ends (for blending hull parameters along x without kinks).
double smooth(double s) {
  s = std::clamp(s, 0.0, 1.0);
  return 0.5 - 0.5 * std::cos(kPi * s);
}
double lerp(double a, double b, double s) { return a + (b - a) * s; }

// Coordinates of the generated hull lie on a 2^-10 m (~1 mm) grid. Such numbers are printed exactly in decimal and
// parsed exactly even by assimp's single-precision OBJ reader (integer part + a fraction of <= 10 binary digits fit
// a float's 24-bit mantissa for |x| < 16 km), so the hull read back is bit-identical to the one generated.
double grid(double v) { return std::round(v * 1024.0) / 1024.0; }

// ---- the parametric icebreaker ---------------------------------------------------------------------------------
//
// Each cross-section x = const is a convex polygon: a flat bottom at z_b(x), a bilge arc of radius r(x), a lower side
// flared outwards at beta_lo(x) from the vertical up to the waterline knuckle at half-breadth W(x), an upper side at
// the smaller flare beta_up(x) up to the deck. The flare decreasing upwards keeps the section convex.
// Along x:
// - bow: a spoon: the bottom is a plane rising at the stem angle from the forefoot to the stem head at the deck;
//   across, it is flat with large bilges, so the bow is broad and flat (Oden's signature);
// - reamers: the waterline widens from beam_m to reamer_beam_m at the forefoot, just behind the bow, and the bow
//   waterline closes from there as an ellipse onto a blunt stem;
// - parallel body with a flat bottom, a small flare and a moderate bilge;
// - stern: a run whose bottom rises quadratically to an immersed transom, with narrowing waterline and growing bilge.
// The shape constants below were chosen (not fitted per call) so that the default particulars displace
// ~13,000 t at rho_w = 1025 kg/m^3 (tests/sim/hull_test.cpp checks this within 5 %).
struct HullShape {
  // Fractions of the length.
  static constexpr double run_length = 0.38;      // stern run (bottom rising to the transom)
  static constexpr double stern_narrowing = 0.38;  // waterline narrowing aft, over this part of the length
  static constexpr double shoulder_length = 0.12;  // beam_m -> reamer_beam_m transition ahead of the reamers
  // Fractions of the draught / half-beam.
  static constexpr double transom_immersion = 0.15;  // transom bottom below the waterline, in draughts
  static constexpr double transom_half_beam = 0.78;  // waterline half-breadth at the transom, of beam_m / 2
  static constexpr double stem_half_beam = 0.30;     // half-breadth of the stem head, of reamer_beam_m / 2
  // Flare from the vertical (deg) below / above the waterline, midbody and bow. Above the waterline the sides are
  // nearly upright, so the extreme beam (at the reamers, on deck) stays within ~1 m of reamer_beam_m.
  static constexpr double flare_mid_lo_deg = 12.0, flare_mid_up_deg = 6.0;
  static constexpr double flare_bow_lo_deg = 35.0, flare_bow_up_deg = 4.0;
  // Bilge radii (m), midbody / bow / transom.
  static constexpr double bilge_mid_m = 4.0, bilge_bow_m = 5.0, bilge_transom_m = 5.0;
};

struct Station {
  double z_bottom, half_wl, flare_lo, flare_up, bilge;
};

class IcebreakerGeometry {
 public:
  explicit IcebreakerGeometry(const HullGeneratorOptions& o) : o_(o) {
    x_aft_ = -0.5 * o.length_m;
    x_fwd_ = 0.5 * o.length_m;
    z_keel_ = -o.draught_m;
    z_deck_ = o.depth_m - o.draught_m;
    tan_stem_ = std::tan(deg(o.stem_angle_deg));
    tan_entrance_ = std::tan(deg(o.entrance_angle_deg));
    // Forefoot: where the spoon meets the keel. Kept in the forward half, so a very low stem angle still leaves a
    // parallel body (the spoon then ends below the deck in a flat, vertical stem face).
    x_forefoot_ = std::max(x_fwd_ - o.depth_m / tan_stem_, 0.0);
    x_reamer_ = x_forefoot_;
    x_run_ = x_aft_ + HullShape::run_length * o.length_m;
    x_shoulder_ = std::max(x_reamer_ - HullShape::shoulder_length * o.length_m, x_run_);
  }

  double x_aft() const { return x_aft_; }
  double x_fwd() const { return x_fwd_; }
  double z_deck() const { return z_deck_; }
  double x_reamer() const { return x_reamer_; }
  bool wedge_bow() const { return o_.entrance_angle_deg < 90.0; }

  Station at(double x) const {
    const HullGeneratorOptions& o = o_;
    Station s;
    // Bottom: keel, the bow spoon plane, the stern run.
    const double spoon = z_keel_ + (x - x_forefoot_) * tan_stem_;
    double run = z_keel_;
    if (x < x_run_) {
      const double u = (x_run_ - x) / (x_run_ - x_aft_);
      run = z_keel_ + (1.0 - HullShape::transom_immersion) * o.draught_m * u * u;
    }
    s.z_bottom = std::min(std::max({z_keel_, spoon, run}), z_deck_);
    // Waterline half-breadth.
    const double b = 0.5 * o.beam_m, r = 0.5 * o.reamer_beam_m;
    if (x >= x_reamer_) {
      const double u = std::clamp((x - x_reamer_) / (x_fwd_ - x_reamer_), 0.0, 1.0);
      const double tip = HullShape::stem_half_beam * r;
      s.half_wl = tip + (r - tip) * std::sqrt(std::max(0.0, 1.0 - u * u));
    } else if (x >= x_shoulder_) {
      s.half_wl = lerp(b, r, smooth((x - x_shoulder_) / (x_reamer_ - x_shoulder_)));
    } else {
      const double x_narrow = x_aft_ + HullShape::stern_narrowing * o.length_m;
      const double u = x < x_narrow ? (x_narrow - x) / (x_narrow - x_aft_) : 0.0;
      s.half_wl = lerp(b, HullShape::transom_half_beam * b, smooth(u));
    }
    // Flare and bilge: midbody values, blended to the bow over the shoulder and to the stern over the run.
    const double to_bow = smooth((x - x_shoulder_) / (x_reamer_ - x_shoulder_));
    const double to_stern = x < x_run_ ? smooth((x_run_ - x) / (x_run_ - x_aft_)) : 0.0;
    s.flare_lo = deg(lerp(HullShape::flare_mid_lo_deg, HullShape::flare_bow_lo_deg, to_bow));
    s.flare_up = deg(lerp(HullShape::flare_mid_up_deg, HullShape::flare_bow_up_deg, to_bow));
    s.bilge = lerp(lerp(HullShape::bilge_mid_m, HullShape::bilge_bow_m, to_bow), HullShape::bilge_transom_m, to_stern);
    return s;
  }

  // Starboard half of the section at x (y >= 0), bottom to deck; the port half is its mirror.
  std::vector<Eigen::Vector2d> half_section(double x) const {
    Station s = at(x);
    std::vector<Eigen::Vector2d> pts;
    const double zb = s.z_bottom, zd = z_deck_;
    auto side_y = [&](double z) { return s.half_wl + z * std::tan(z <= 0 ? s.flare_lo : s.flare_up); };
    if (zd - zb < 1e-3) {  // the stem head: the section has shrunk to the deck edge
      pts.emplace_back(side_y(zd), zd);
      return pts;
    }
    if (zb < 0)  // keep at least a quarter of the waterline half-breadth at the bottom for extreme particulars
      s.flare_lo = std::min(s.flare_lo, std::atan(0.75 * s.half_wl / -zb));
    const double yc = side_y(zb);  // bottom corner before rounding
    const double beta = zb < 0 ? s.flare_lo : s.flare_up;
    const Eigen::Vector2d dir(std::sin(beta), std::cos(beta));  // up the side from the corner
    // Length of the straight side above the corner (to the knuckle at the waterline, or to the deck).
    const double side_len = zb < 0 ? -zb / std::cos(beta) : (zd - zb) / std::cos(beta);
    // Fillet tangent length for the corner angle 90 deg + beta, limited by the bottom and side available.
    const double k = std::tan(0.5 * (0.5 * kPi + beta));
    const double t = std::min({s.bilge / k, 0.95 * yc, 0.95 * side_len});
    const double rad = t * k;
    const Eigen::Vector2d corner(yc, zb);
    const Eigen::Vector2d t1 = corner - Eigen::Vector2d(t, 0);
    const Eigen::Vector2d centre = t1 + Eigen::Vector2d(0, rad);
    pts.push_back(t1);
    const int arc = 4;
    const double a0 = -0.5 * kPi, a1 = -beta;  // from straight down to the side's outward normal
    for (int i = 1; i < arc; ++i) {
      const double a = lerp(a0, a1, double(i) / arc);
      pts.push_back(centre + rad * Eigen::Vector2d(std::cos(a), std::sin(a)));
    }
    pts.push_back(corner + t * dir);
    if (zb < 0) pts.emplace_back(s.half_wl, 0.0);  // waterline knuckle
    pts.emplace_back(side_y(zd), zd);               // deck edge
    return pts;
  }

  // The whole section at x (both sides, a ring) of the wedge bow: the section above cut by the two planes
  //   |y| <= (x_s(z) - x) tan(alpha),  x_s(z) = x_forefoot + (z - z_keel) / tan(stem),
  // which contain the stem line x_s(z) (the spoon's centreline) and meet the waterline at alpha to the centreline.
  // A plane through a line rising at the stem angle phi whose waterline makes alpha with the centreline slopes at
  // arctan(tan(phi) / sin(alpha)) across its waterline: Lindqvist's normal flare psi, exactly. Where the planes cut,
  // the stem stays the spoon's line (they meet the centreline on it) and the sections become V-shaped.
  std::vector<Eigen::Vector2d> wedge_section(double x) const {
    const std::vector<Eigen::Vector2d> half = half_section(x);
    std::vector<Eigen::Vector2d> ring(half.begin(), half.end());
    for (auto it = half.rbegin(); it != half.rend(); ++it) ring.emplace_back(-it->x(), it->y());
    for (const double side : {1.0, -1.0}) {
      auto outside = [&](const Eigen::Vector2d& p) {  // > 0 beyond the plane on this side
        return side * p.x() - (x_forefoot_ + (p.y() - z_keel_) / tan_stem_ - x) * tan_entrance_;
      };
      std::vector<Eigen::Vector2d> in;
      in.swap(ring);
      for (size_t i = 0; i < in.size(); ++i) {  // Sutherland-Hodgman against one plane
        const Eigen::Vector2d &p = in[i], &q = in[(i + 1) % in.size()];
        const double fp = outside(p), fq = outside(q);
        if (fp <= 0) ring.push_back(p);
        if ((fp < 0 && fq > 0) || (fp > 0 && fq < 0)) ring.push_back(p + (fp / (fp - fq)) * (q - p));
      }
    }
    // Drop repeated and collinear points (a point on the centreline in the middle of the flat bottom or the deck
    // edge), so that the convex parts are built from the section's corners only.
    const double tol = 1e-9 * std::max(1.0, o_.length_m);
    std::vector<Eigen::Vector2d> out;
    for (const Eigen::Vector2d& p : ring)
      if (out.empty() || (p - out.back()).norm() > tol) out.push_back(p);
    while (out.size() > 1 && (out.front() - out.back()).norm() <= tol) out.pop_back();
    for (bool again = out.size() >= 3; again && out.size() >= 3;) {
      again = false;
      for (size_t i = 0; i < out.size(); ++i) {
        const Eigen::Vector2d &a = out[(i + out.size() - 1) % out.size()], &b = out[i], &c = out[(i + 1) % out.size()];
        const Eigen::Vector2d u = b - a, w = c - b;
        if (std::abs(u.x() * w.y() - u.y() * w.x()) <= tol * (u.norm() + w.norm())) {
          out.erase(out.begin() + static_cast<long>(i));
          again = true;
          break;
        }
      }
    }
    if (out.empty()) out.emplace_back(0.0, z_deck_);  // the stem head, lost to round-off: keep its point
    return out;
  }

 private:
  HullGeneratorOptions o_;
  double x_aft_, x_fwd_, z_keel_, z_deck_, tan_stem_, tan_entrance_, x_forefoot_, x_reamer_, x_shoulder_, x_run_;
};

}  // namespace

// ---- generation and OBJ ----------------------------------------------------------------------------------------

std::vector<TriMesh> generate_hull(const HullGeneratorOptions& o) {
  // The options' own checks, also when the struct was filled in code rather than read from JSON.
  check_options(o, "hull generator options");
  const IcebreakerGeometry g(o);
  const int n = o.sections;
  // Stations evenly spaced, except that the one nearest the reamers moves onto them, so the widest waterline is
  // a station and not cut off between two.
  std::vector<double> xs(n + 1);
  for (int i = 0; i <= n; ++i) xs[i] = g.x_aft() + (g.x_fwd() - g.x_aft()) * i / n;
  const int near = static_cast<int>(std::lround((g.x_reamer() - g.x_aft()) / (g.x_fwd() - g.x_aft()) * n));
  if (near > 0 && near < n) xs[near] = g.x_reamer();
  std::vector<std::vector<Vec3>> stations(n + 1);
  for (int i = 0; i <= n; ++i) {
    const double x = grid(xs[i]);
    if (g.wedge_bow()) {  // the whole section, cut by the wedge planes; its points on the centreline taken once
      for (const auto& p : g.wedge_section(x)) stations[i].emplace_back(x, grid(p.x()), grid(p.y()));
      auto less = [](const Vec3& a, const Vec3& b) {
        return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
      };
      std::sort(stations[i].begin(), stations[i].end(), less);
      stations[i].erase(std::unique(stations[i].begin(), stations[i].end()), stations[i].end());
      continue;
    }
    for (const auto& p : g.half_section(x)) {
      const double y = grid(p.x()), z = grid(p.y());
      stations[i].emplace_back(x, y, z);
      stations[i].emplace_back(x, -y, z);
    }
  }
  std::vector<TriMesh> parts;
  for (int i = 0; i < n; ++i) {
    std::vector<Vec3> pts = stations[i];
    pts.insert(pts.end(), stations[i + 1].begin(), stations[i + 1].end());
    parts.push_back(convex_hull(pts));
  }
  return parts;
}

void write_obj(const fs::path& file, const std::vector<TriMesh>& parts, const std::string& header) {
  AtomicFile f(file);
  {
    std::ostringstream out;
    std::istringstream h(header);
    for (std::string line; std::getline(h, line);) out << "# " << line << "\n";
    int base = 1;
    char buf[128];
    for (size_t k = 0; k < parts.size(); ++k) {
      out << "o part_" << k << "\n";
      for (const Vec3& v : parts[k].vertices) {
        // %.17g round-trips any double; for the generator's grid coordinates it prints them short and exact.
        std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g\n", v.x(), v.y(), v.z());
        out << buf;
      }
      for (const auto& t : parts[k].triangles) out << "f " << t[0] + base << " " << t[1] + base << " " << t[2] + base << "\n";
      base += static_cast<int>(parts[k].vertices.size());
    }
    write_file_checked(f.tmp(), out.str(), file);  // every write checked: a full disk is an error, named
  }
  f.commit();
}

namespace detail {

nlohmann::json generated_mesh_json(const std::vector<TriMesh>& parts, const Hydrostatics& h, double rho_w) {
  const Bounds b(merge(parts).vertices);
  size_t nv = 0, nt = 0;
  for (const TriMesh& p : parts) nv += p.vertices.size(), nt += p.triangles.size();
  return {{"parts", parts.size()},
          {"vertices", nv},
          {"triangles", nt},
          {"extent_m", {{"x", {b.lo.x(), b.hi.x()}}, {"y", {b.lo.y(), b.hi.y()}}, {"z", {b.lo.z(), b.hi.z()}}}},
          {"hydrostatics", hydrostatics_json(h, rho_w)}};
}

fs::path write_generated_files(const std::vector<TriMesh>& parts, const fs::path& out_obj, const std::string& header,
                               const nlohmann::json& side) {
  fs::path sidecar = out_obj;
  sidecar.replace_extension(".json");
  FLOESIM_REQUIRE(sidecar != out_obj, out_obj.string(), ": the hull file must not end in .json (the sidecar does)");
  ensure_directory(out_obj.parent_path());
  write_obj(out_obj, parts, header);
  write_text_atomic(sidecar, side.dump(2) + "\n");
  return sidecar;
}

}  // namespace detail

std::string write_generated_hull(const HullGeneratorOptions& o, const fs::path& out_obj, const fs::path& config_file) {
  const std::vector<TriMesh> parts = generate_hull(o);
  constexpr double rho_w = 1025.0;
  const Hydrostatics h = hydrostatics(parts, rho_w, 0.0);
  const Bounds b(merge(parts).vertices);
  size_t nv = 0, nt = 0;
  for (const TriMesh& p : parts) nv += p.vertices.size(), nt += p.triangles.size();

  std::ostringstream head;
  head << "floesim parametric icebreaker (Oden's main particulars), " << parts.size() << " convex parts\n"
       << "written by floesim-hull " << version() << "; frame: x forward, y to port, z up, metres; calm waterline"
       << " z = 0; origin midship on the centreline\n"
       << "length_m " << o.length_m << ", beam_m " << o.beam_m << ", reamer_beam_m " << o.reamer_beam_m
       << ", draught_m " << o.draught_m << ", depth_m " << o.depth_m << ", stem_angle_deg " << o.stem_angle_deg
       << ", entrance_angle_deg " << o.entrance_angle_deg << ", sections " << o.sections << "\n"
       << "volume below z = 0: " << fmt_num(h.volume_m3) << " m^3; displacement " << fmt_num(h.displacement_t)
       << " t at rho_w = " << rho_w << " kg/m^3\n"
       << "waterplane area " << fmt_num(h.waterplane_area_m2) << " m^2, LCB " << fmt_num(h.lcb_m) << " m, KB "
       << fmt_num(h.kb_m) << " m, wetted surface " << fmt_num(h.wetted_surface_m2) << " m^2\n";

  nlohmann::json side;
  side["provenance"] = make_provenance(
      "floesim-hull",
      config_file.empty() ? std::vector<NamedInput>{} : std::vector<NamedInput>{{"config", config_file}},
      options_to_json(o));
  side["hull_file"] = out_obj.filename().string();
  side["frame"] = "x forward, y to port, z up; calm waterline z = 0; origin midship on the centreline; metres";
  side.update(generated_mesh_json(parts, h, rho_w));
  std::ostringstream particulars_text;
  add_particulars(merge(parts), "the generated hull", side, particulars_text);
  const fs::path sidecar = write_generated_files(parts, out_obj, head.str(), side);

  std::ostringstream sum;
  sum << "hull: " << parts.size() << " convex parts, " << nv << " vertices, " << nt << " triangles -> "
      << out_obj.string() << " (+ " << sidecar.filename().string() << ")\n"
      << "  extent x " << fmt_num(b.lo.x()) << " .. " << fmt_num(b.hi.x()) << " m, y " << fmt_num(b.lo.y()) << " .. "
      << fmt_num(b.hi.y()) << " m, z " << fmt_num(b.lo.z()) << " .. " << fmt_num(b.hi.z()) << " m\n"
      << "  volume below z = 0   " << fmt_num(h.volume_m3) << " m^3\n"
      << "  displacement         " << fmt_num(h.displacement_t) << " t (rho_w " << rho_w << " kg/m^3)\n"
      << "  waterplane area      " << fmt_num(h.waterplane_area_m2) << " m^2\n"
      << "  waterline L x B      " << fmt_num(h.length_wl_m) << " x " << fmt_num(h.beam_wl_m) << " m\n"
      << "  block coefficient    " << fmt_num(h.block_coefficient, 3) << " (on the waterline length and beam)\n"
      << "  LCB                  " << fmt_num(h.lcb_m) << " m (x of the centre of buoyancy; + is forward of midship)\n"
      << "  KB                   " << fmt_num(h.kb_m) << " m\n"
      << "  wetted surface       " << fmt_num(h.wetted_surface_m2) << " m^2\n";
  sum << particulars_text.str();
  return sum.str();
}

}  // namespace floesim::sim
