#include "sim/engine/collision.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>

#include "pipeline/error.h"
#include "sim/geometry/polygon3d.h"
#include "sim/engine/parallel.h"

namespace floesim::sim {

namespace {

// FCL's CollisionObject boxes a rotated object by its bounding sphere, which for flat slabs is a cube that overlaps
// many neighbours. We set the exact box of the transformed vertices instead.
class PartObject : public fcl::CollisionObjectd {
 public:
  PartObject(const std::shared_ptr<fcl::CollisionGeometryd>& g, int part) : fcl::CollisionObjectd(g), part(part) {}
  void set_aabb(const Vec3& lo, const Vec3& hi) {
    aabb.min_ = lo;
    aabb.max_ = hi;
  }
  int part;
};

// A part in world coordinates (refreshed when its body moves): its arrays in PartArrays.
struct PartWorld {
  Vec3* v = nullptr;          // vertices (nv)
  Vec3* n = nullptr;          // face normals (nf)
  double* d = nullptr;        // face plane offsets n.x (nf)
  int nv = 0, nf = 0;
  Vec3 lo, hi;                // exact box
};

// The parts' geometry as placing them reads and writes it: local vertices, face normals and each face's first
// vertex, and the world vertices, normals and plane offsets, in arrays shared by the parts added together (all of the
// model's at the start, then each fracture's pieces), part after part. Placing the awake parts (every one, every
// step) then reads and writes memory in order instead of chasing each part's own vectors (and a face's vertex list
// for its first vertex). A batch's arrays are never moved or regrown once made (growing them at every fracture left
// the old copies in the process's memory), so the parts' pointers into them stay valid.
struct PartGeometry {
  const Vec3* v;       // local vertices (nv)
  const Vec3* n;       // local face normals (nf)
  const int* anchor;   // per face: its first vertex
};
class PartArrays {
 public:
  // Appends `parts` as one batch, and their world geometry's views to `views` (one per part, in the same order).
  void add(const std::vector<const ConvexPart*>& parts, std::vector<PartWorld>& views) {
    size_t nv = 0, nf = 0;
    for (const ConvexPart* cp : parts) nv += cp->vertices.size(), nf += cp->faces.size();
    Batch& b = *batches_.emplace_back(std::make_unique<Batch>());
    b.live = static_cast<int>(parts.size());
    batch_of_.insert(batch_of_.end(), parts.size(), static_cast<int>(batches_.size()) - 1);
    // Reserved exactly, so that the pointers taken while they are filled stay valid.
    b.local_v.reserve(nv), b.local_n.reserve(nf), b.anchor.reserve(nf);
    b.v.resize(nv), b.n.resize(nf), b.d.resize(nf);
    for (const ConvexPart* cp : parts) {
      const size_t iv = b.local_v.size(), jf = b.local_n.size();
      local_.push_back({b.local_v.data() + iv, b.local_n.data() + jf, b.anchor.data() + jf});
      views.push_back({b.v.data() + iv, b.n.data() + jf, b.d.data() + jf, static_cast<int>(cp->vertices.size()),
                       static_cast<int>(cp->faces.size()), Vec3::Zero(), Vec3::Zero()});
      b.local_v.insert(b.local_v.end(), cp->vertices.begin(), cp->vertices.end());
      b.local_n.insert(b.local_n.end(), cp->face_normal.begin(), cp->face_normal.end());
      for (const auto& f : cp->faces) b.anchor.push_back(f[0]);
    }
  }
  const PartGeometry& local(int p) const { return local_[p]; }
  // Part p is gone for good (its body broke): once every part of its batch is, the batch's arrays are freed (the
  // views into them are never read again).
  void release(int p) {
    std::unique_ptr<Batch>& b = batches_[batch_of_[p]];
    if (b && --b->live == 0) b.reset();
  }

 private:
  struct Batch {
    std::vector<Vec3> local_v, local_n, v, n;
    std::vector<int> anchor;
    std::vector<double> d;
    int live = 0;  // its parts not yet released
  };
  std::vector<std::unique_ptr<Batch>> batches_;
  std::vector<int> batch_of_;  // per part: its batch
  std::vector<PartGeometry> local_;
};

// Places a part (its local geometry g) at (x, R) into its view w: world vertices, face normals and plane offsets,
// exact box. Every awake part is placed every step, most of them to be boxed by the broad phase only: what the
// narrow phase alone needs (each face's box) is computed where it is used.
void transform_part(const PartGeometry& g, const Vec3& x, const Mat3& R, PartWorld& w) {
  const int nv = w.nv, nf = w.nf;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (int i = 0; i < nv; ++i) {
    w.v[i] = x + R * g.v[i];
    lo = lo.cwiseMin(w.v[i]);
    hi = hi.cwiseMax(w.v[i]);
  }
  for (int f = 0; f < nf; ++f) {
    w.n[f] = R * g.n[f];
    w.d[f] = w.n[f].dot(w.v[g.anchor[f]]);
  }
  w.lo = lo;
  w.hi = hi;
}

// The clipped contact-surface faces of a patch (local origin), one polygon after another, with their face normals and
// sides: split into the patch's rows after the patch's centroid and normal are known.
struct SurfacePolygons {
  std::vector<Vec3> v;        // vertices
  std::vector<int> end;       // end of each polygon in v
  std::vector<Vec3> n;        // face normal of each polygon
  std::vector<uint8_t> side;  // 0: a face of a, 1: a face of b
  void clear() {
    v.clear();
    end.clear();
    n.clear();
    side.clear();
  }
};

// Sums over the faces of one part clipped by the other part (one side of the overlap's boundary), in coordinates
// relative to a local origin near the overlap (so that the volume does not cancel large world offsets).
struct SideSums {
  Vec3 vec_area = Vec3::Zero();  // sum of area x outward normal over contact-surface faces
  Vec3 moment = Vec3::Zero();    // sum of area x centroid over contact-surface faces
  double area = 0;               // sum of the areas of contact-surface faces
  double volume = 0;             // divergence theorem over all faces: (1/3) sum of area x (n . centroid)
  SurfacePolygons* surface = nullptr;   // if set: the clipped contact-surface faces themselves (local origin)
  uint8_t side = 0;                     // 0: faces of a, 1: faces of b (tag of the faces put into `surface`)
};

// Points up to this far outside a plane count as inside (1 nm): a face lying in the other part's face plane (the
// tops of two floes of equal thickness) is then reliably on the boundary of the overlap, not flickering in and out.
constexpr double kClipTolerance = 1e-9;

// Scratch buffers of clip_faces.
struct ClipScratch {
  std::vector<Vec3> poly, tmp;
  std::vector<double> dist;  // signed distances of poly's vertices to the plane being clipped by
  std::vector<int> planes;   // Q's planes that can cut P
};

// The faces of P (translated by tp) clipped by the half-spaces n.x <= d of Q (translated by tq): Sutherland-Hodgman
// per face, a face leaving nothing as soon as one plane has it all outside. second_side: P's faces lying in the
// plane of a face of Q with the same orientation are skipped, because Q's side (clipped first) already holds that
// piece of the overlap's boundary; counting both would double it (e.g. the volume of two floes' common top).
void clip_faces(const ConvexPart& P, const PartWorld& pw, const Vec3& tp, const ConvexPart& Q, const PartWorld& qw,
                const Vec3& tq, const Vec3& origin, bool second_side, ClipScratch& cs, SideSums& out) {
  std::vector<Vec3>& poly = cs.poly;
  std::vector<Vec3>& tmp = cs.tmp;
  std::vector<double>& dist = cs.dist;
  const size_t nq = Q.faces.size();
  const Vec3 shift_p = tp - origin, shift_q = tq - origin;
  // Q's planes that can cut P: a plane with P's whole box inside it (by far more than the round-off of a clipped
  // vertex) leaves every face of P whole, so it is left out of the clipping (a floe piece against a hull section
  // of 28 faces is cut by the few facing it). The same polygons result, to the bit.
  constexpr double kPlaneMargin = 1e-6;
  const Vec3 pc = 0.5 * (pw.lo + pw.hi) + shift_p, ph = 0.5 * (pw.hi - pw.lo);
  cs.planes.clear();
  for (size_t g = 0; g < nq; ++g) {
    const Vec3& qn = qw.n[g];
    const double support = qn.dot(pc) + qn.cwiseAbs().dot(ph);
    if (support - (qw.d[g] + qn.dot(shift_q) + kClipTolerance) > -kPlaneMargin)
      cs.planes.push_back(static_cast<int>(g));
  }
  // Q's box, widened: a face of P entirely outside it is entirely outside Q and clips to nothing, so it is skipped
  // before the clipping (most faces of two floes touching at a corner). The margin keeps every face the tolerance
  // of the half-spaces could let in (1e-9 m, more at a sharp corner of Q: up to 1e-9 / sin(half its angle)).
  constexpr double kBoxMargin = 1e-6;
  // Q's box in P's placement (P's faces' boxes are where P is, shifted by tp).
  const Vec3 qlo = qw.lo + tq - tp - Vec3::Constant(kBoxMargin), qhi = qw.hi + tq - tp + Vec3::Constant(kBoxMargin);
  for (size_t f = 0; f < P.faces.size(); ++f) {
    Vec3 flo = Vec3::Constant(1e300), fhi = Vec3::Constant(-1e300);
    for (int i : P.faces[f]) {
      flo = flo.cwiseMin(pw.v[i]);
      fhi = fhi.cwiseMax(pw.v[i]);
    }
    if ((flo.array() > qhi.array()).any() || (fhi.array() < qlo.array()).any()) continue;
    if (second_side) {
      const double df = pw.d[f] + pw.n[f].dot(shift_p);
      bool coplanar = false;
      for (size_t g = 0; g < nq && !coplanar; ++g)
        coplanar = pw.n[f].dot(qw.n[g]) > 1 - 1e-12 &&
                   std::abs(df - (qw.d[g] + qw.n[g].dot(shift_q))) <= kClipTolerance;
      if (coplanar) continue;
    }
    poly.resize(P.faces[f].size());
    for (size_t i = 0; i < poly.size(); ++i) poly[i] = pw.v[P.faces[f][i]] + shift_p;
    for (size_t j = 0; j < cs.planes.size() && poly.size() >= 3; ++j) {
      const int g = cs.planes[j];
      const Vec3& qn = qw.n[g];
      const double qd = qw.d[g] + qn.dot(shift_q) + kClipTolerance;
      // Signed distances first: most planes of Q leave the face whole (nothing to copy) or remove it entirely.
      const size_t k = poly.size();
      dist.resize(k);
      size_t inside = 0;
      for (size_t i = 0; i < k; ++i) inside += (dist[i] = qn.dot(poly[i]) - qd) <= 0;
      if (inside == k) continue;
      if (inside == 0) {
        poly.clear();
        break;
      }
      // Each edge gives at most two vertices: sized once and written by index (no push_back in the innermost loop).
      tmp.swap(poly);
      poly.resize(2 * k);
      size_t m = 0;
      double sp = dist[k - 1];  // previous vertex (edge tmp[k-1] -> tmp[0] first)
      for (size_t i = 0; i < k; ++i) {
        const Vec3& p = tmp[i == 0 ? k - 1 : i - 1];
        const Vec3& q = tmp[i];
        const double sq = dist[i];
        if ((sp <= 0) != (sq <= 0)) poly[m++] = p + (sp / (sp - sq)) * (q - p);
        if (sq <= 0) poly[m++] = q;
        sp = sq;
      }
      poly.resize(m);
    }
    if (poly.size() < 3) continue;
    // Area (signed about the face normal: clipping keeps the winding) and centroid of the clipped face.
    const Vec3& nf = pw.n[f];
    double a2 = 0;
    Vec3 c = Vec3::Zero();
    for (size_t i = 1; i + 1 < poly.size(); ++i) {
      const double w = (poly[i] - poly[0]).cross(poly[i + 1] - poly[0]).dot(nf);
      a2 += w;
      c += w * (poly[0] + poly[i] + poly[i + 1]);
    }
    if (!(a2 > 0)) continue;
    const double area = 0.5 * a2;
    const Vec3 centroid = c / (3 * a2);
    out.volume += area * nf.dot(centroid) / 3;
    if (P.face_internal[f]) continue;  // bounds the overlap, but is no surface of the body
    if (out.surface) {
      out.surface->v.insert(out.surface->v.end(), poly.begin(), poly.end());
      out.surface->end.push_back(static_cast<int>(out.surface->v.size()));
      out.surface->n.push_back(nf);
      out.surface->side.push_back(out.side);
    }
    out.vec_area += area * nf;
    out.moment += area * centroid;
    out.area += area;
  }
}

// Areas below this (1 mm^2; 2 N at 2 MPa) are no contact: the parts merely graze.
constexpr double kMinPatchArea = 1e-6;

// The rows of a crushing contact: the contact surface cut in two halves by the plane through its centroid normal
// to the horizontal tangent u = z x n (x when n is vertical). Each half is a row at its own centroid carrying its
// own share of the area, so that the contact resists a rotation about the vertical (a floe turning into the hull):
// the half turning into the ice crushes and the half turning away unloads (one row at the centroid carries no
// moment). No second cut across the thickness: on floes ~1 m thick its rows are a quarter metre apart on bodies
// metres across, nearly redundant, and Gauss-Seidel does not converge on them within its sweeps (tried: residuals
// of 5e-3 m/s at impacts and floes leaving a pushing face at 0.1 % of its speed). Sums per half (1: u.(x - c) >= 0);
// side_weight is the weight of a's and b's faces in the vector area (as for the whole patch), and point_side which
// sides' faces place the points.
constexpr int kRows = 2;
struct RowSums {
  std::array<Vec3, kRows> vec_area, moment;
  std::array<double, kRows> area;
  RowSums() {
    vec_area.fill(Vec3::Zero());
    moment.fill(Vec3::Zero());
    area.fill(0.0);
  }
};

// Where polygon k's vertices begin in s.v (they end where polygon k + 1's begin).
inline int vertex_begin(const SurfacePolygons& s, int k) { return k > 0 ? s.end[k - 1] : 0; }

// Adds the polygons [first, last) of s to `out`.
void row_sums(const SurfacePolygons& s, int first, int last, const Vec3& c, const Vec3& u, const double side_weight[2],
              const bool point_side[2], std::array<std::vector<Vec3>, kRows>& half, RowSums& out) {
  int begin = vertex_begin(s, first);
  for (int k = first; k < last; ++k) {
    const Vec3* p = s.v.data() + begin;
    const int n = s.end[k] - begin;
    begin = s.end[k];
    if (side_weight[s.side[k]] == 0 && !point_side[s.side[k]]) continue;  // a side the patch does not use
    const Vec3& nf = s.n[k];
    split_polygon_plane(p, n, u, u.dot(c), half[0], half[1]);  // half 1: u.(x - c) >= 0
    for (int h = 0; h < kRows; ++h) {
      const AreaCentroid ac = polygon_area_centroid(half[h].data(), static_cast<int>(half[h].size()));
      if (!(ac.area > 0)) continue;
      out.vec_area[h] += side_weight[s.side[k]] * ac.area * nf;
      if (point_side[s.side[k]]) {
        out.moment[h] += ac.area * ac.centroid;
        out.area[h] += ac.area;
      }
    }
  }
}

// One part pair of a contact: its two parts where they are, which sides of its overlap carry the contact surface,
// and the sums of its clipped overlap (about the contact's local origin). A contact is the part pairs of one body
// pair that press in about one direction (crushing_contacts): its area, normal, point, rows and secant are sums
// over its members, so that how the bodies are cut into convex parts does not change it.
struct PatchMember {
  const ConvexPart* A = nullptr;
  const PartWorld* wa = nullptr;
  const ConvexPart* B = nullptr;
  const PartWorld* wb = nullptr;
  int pair = -1;                     // the collision stage's part pair (its index in the sorted candidates)
  double side_weight[2] = {0, 0};    // weight of a's and b's faces in the vector area
  bool point_side[2] = {false, false};  // whose faces place the point
  Vec3 vec_area = Vec3::Zero();      // the patch's vector area: the overlap projected on the plane normal to it
  Vec3 moment = Vec3::Zero();        // sum of area x centroid over the faces that place the point
  double area = 0;                   // sum of their areas
  double volume = 0;                 // overlap volume
  int poly_first = 0, poly_end = 0;  // its contact-surface faces in the SurfacePolygons it was clipped into
};

// a's faces clipped by b (if side_a) and b's by a (if side_b), b translated by shift_b, about `origin`, into sa and
// sb; their contact-surface faces are appended to `surface` and become the member's.
void clip_sides(PatchMember& m, const Vec3& shift_b, const Vec3& origin, bool side_a, bool side_b, ClipScratch& cs,
                SurfacePolygons& surface, SideSums& sa, SideSums& sb) {
  const Vec3 zero = Vec3::Zero();
  sa.surface = sb.surface = &surface;
  sb.side = 1;
  m.poly_first = static_cast<int>(surface.end.size());
  if (side_a) clip_faces(*m.A, *m.wa, zero, *m.B, *m.wb, shift_b, origin, false, cs, sa);
  if (side_b) clip_faces(*m.B, *m.wb, shift_b, *m.A, *m.wa, zero, origin, true, cs, sb);
  m.poly_end = static_cast<int>(surface.end.size());
}

// Clips the member's parts, b translated by shift_b, about `origin`: both sides, their contact-surface faces appended
// to `surface`. Sets which sides carry the contact (PatchSide), the vector area, the point's sums and the volume.
// Returns whether the parts press on each other (a vector area of at least kMinPatchArea).
bool clip_member(PatchMember& m, const Vec3& shift_b, const Vec3& origin, PatchSide side, ClipScratch& cs,
                 SurfacePolygons& surface) {
  SideSums sa, sb;
  clip_sides(m, shift_b, origin, true, true, cs, surface, sa, sb);
  m.volume = sa.volume + sb.volume;
  // The boundary of the overlap is closed, so sa.vec_area = -sb.vec_area up to the internal faces left out: the
  // vector area of one side is the overlap projected on the plane normal to it, which is the nominal contact area
  // (a wedge of half-angle phi pushed delta into a wall: 2 h delta tan(phi); a flat edge: h w). A structure's side
  // carries the contact; it is empty only when b reaches through a's internal faces, and then b's side does.
  const bool from_b = side == PatchSide::a_is_structure && sa.vec_area.norm() < kMinPatchArea;
  if (side == PatchSide::symmetric) {
    m.side_weight[0] = 0.5, m.side_weight[1] = -0.5;
    m.point_side[0] = m.point_side[1] = true;
    m.vec_area = 0.5 * (sa.vec_area - sb.vec_area);
    m.moment = sa.moment + sb.moment;
    m.area = sa.area + sb.area;
  } else {
    m.side_weight[0] = from_b ? 0.0 : 1.0, m.side_weight[1] = from_b ? -1.0 : 0.0;
    m.point_side[0] = !from_b, m.point_side[1] = from_b;
    m.vec_area = from_b ? Vec3(-sb.vec_area) : sa.vec_area;
    m.moment = from_b ? sb.moment : sa.moment;
    m.area = from_b ? sb.area : sa.area;
  }
  return m.vec_area.norm() >= kMinPatchArea && m.area > 0;
}

// The sides the member uses, b translated by shift_b, their faces appended to `surface` (the secant's re-clip).
// Returns their weighted vector area.
Vec3 reclip_member(PatchMember& m, const Vec3& shift_b, const Vec3& origin, ClipScratch& cs, SurfacePolygons& surface) {
  SideSums sa, sb;
  clip_sides(m, shift_b, origin, m.side_weight[0] != 0 || m.point_side[0], m.side_weight[1] != 0 || m.point_side[1],
             cs, surface, sa, sb);
  return m.side_weight[0] * sa.vec_area + m.side_weight[1] * sb.vec_area;
}

// Scratch buffers of the patch computation: the clipped faces of the members as they are (surface), at a crushed
// depth (shifted), after the secant's step (secant), and the members of the contact being built.
struct PatchScratch {
  ClipScratch clip;
  std::array<std::vector<Vec3>, kRows> half;  // a surface polygon's two row halves
  SurfacePolygons surface, shifted, secant;
  std::vector<PatchMember> members, contact;
  struct Group {
    Vec3 dir, lo, hi;  // the sum of its members' vector areas; the box of their contact surfaces (local origin)
  };
  std::vector<Group> groups;    // per contact of a body pair
  std::vector<int> contact_of;  // per member: its contact
};

// The area, normal, point and volume of the contact of members ms[0, n), sums over them; `centre` gets the point
// about the local origin.
ContactPatch patch_sums(const PatchMember* ms, int n, const Vec3& origin, Vec3& centre) {
  ContactPatch r;
  Vec3 S = Vec3::Zero(), moment = Vec3::Zero();
  double point_area = 0, volume = 0;
  for (int k = 0; k < n; ++k) {
    S += ms[k].vec_area;
    moment += ms[k].moment;
    point_area += ms[k].area;
    volume += ms[k].volume;
  }
  const double area = S.norm();
  if (!(area >= kMinPatchArea) || !(point_area > 0)) return r;
  r.valid = true;
  r.area_m2 = area;
  r.normal = S / area;
  r.volume_m3 = std::max(0.0, volume);
  centre = moment / point_area;
  r.point = centre + origin;
  return r;
}

// The span, rows and secant of patch r of members ms[0, n), clipped with b at shift_b into `surface`.
// step_of(point, normal) gives the penetration step of the area's secant (see ContactPatch::area_step_m).
template <class StepFn>
void complete_patch(ContactPatch& r, const Vec3& centre, PatchMember* ms, int n, const SurfacePolygons& surface,
                    const Vec3& shift_b, const Vec3& origin, StepFn step_of, PatchScratch& ps) {
  // Horizontal extent of the contact surface across the normal (the contact width of PHYSICS.md §2.1). A normal
  // close to vertical (a floe under a flat bottom) has no horizontal tangent: the span is then taken along x.
  Vec3 u1 = Vec3::UnitZ().cross(r.normal);
  u1 = u1.norm() > 1e-6 ? Vec3(u1.normalized()) : Vec3::UnitX();
  double lo = 1e300, hi = -1e300;
  r.span_lo = r.span_hi = r.point;
  for (int k = 0; k < n; ++k) {
    for (int i = vertex_begin(surface, ms[k].poly_first); i < vertex_begin(surface, ms[k].poly_end); ++i) {
      const Vec3& p = surface.v[i];
      const double s = u1.dot(p);
      if (s < lo) lo = s, r.span_lo = p + origin;
      if (s > hi) hi = s, r.span_hi = p + origin;
    }
  }
  // The rows: the same sides as the patch, cut in halves across u1 through its centroid.
  RowSums rows;
  for (int k = 0; k < n; ++k)
    row_sums(surface, ms[k].poly_first, ms[k].poly_end, centre, u1, ms[k].side_weight, ms[k].point_side, ps.half,
             rows);
  // dA/d(delta): b moved by the step towards a along the normal, the same sides re-clipped, projected on this normal
  // (in total and per half, with the same cutting plane).
  const double eps = step_of(r.point, r.normal);
  const Vec3 t = shift_b - eps * r.normal;
  ps.secant.clear();
  Vec3 S_eps = Vec3::Zero();
  RowSums rows_end;
  for (int k = 0; k < n; ++k) {
    PatchMember m = ms[k];
    S_eps += reclip_member(m, t, origin, ps.clip, ps.secant);
    row_sums(ps.secant, m.poly_first, m.poly_end, centre, u1, m.side_weight, m.point_side, ps.half, rows_end);
  }
  const double area = r.area_m2, area_eps = S_eps.dot(r.normal);
  // A shrinking area (a corner passing through a thin part) would soften the implicit row and could make it
  // unstable; the hardening is kept >= 0 (constant-force crushing in that case).
  r.area_step_m = eps;
  r.area_end_m2 = std::max(area, area_eps);
  r.area_slope_m = (r.area_end_m2 - area) / eps;
  // Halves with a measurable area become rows (their areas add up to the patch's, to a dropped sliver below
  // kMinPatchArea).
  for (int q = 0; q < kRows; ++q) {
    const double aq = rows.vec_area[q].dot(r.normal);
    if (!(aq >= kMinPatchArea) || !(rows.area[q] > 0)) continue;
    PatchRow& row = r.rows[r.row_count++];
    row.half = q;
    row.point = rows.moment[q] / rows.area[q] + origin;
    row.area_m2 = aq;
    row.area_end_m2 = std::max(aq, rows_end.vec_area[q].dot(r.normal));
  }
}

// The local origin of the overlaps of two placed parts: the centre of the intersection of their boxes, so that the
// sums do not cancel large world offsets.
Vec3 overlap_origin(const PartWorld& wa, const PartWorld& wb) {
  return 0.5 * (wa.lo.cwiseMax(wb.lo) + wa.hi.cwiseMin(wb.hi));
}

// A candidate part pair, ordered by body pair first: a body pair's part pairs are adjacent (one crushing contact
// per direction is made of them).
struct PairCandidate {
  int body_a, part_a, body_b, part_b;
  bool operator<(const PairCandidate& o) const {
    if (body_a != o.body_a) return body_a < o.body_a;
    if (body_b != o.body_b) return body_b < o.body_b;
    if (part_a != o.part_a) return part_a < o.part_a;
    return part_b < o.part_b;
  }
};

// Where the contacts of one chunk of body pairs went: contacts[first, end) of the scratch of the worker that ran it.
struct ChunkRange {
  int worker, first, end;
};

// Scratch of one worker.
struct Scratch {
  std::vector<Vec3> poly, tmp;
  PatchScratch patch;
  std::vector<Contact> contacts;      // contacts of this worker's chunks, each chunk's in pair order
  std::vector<PairCandidate> candidates;  // awake part pairs this worker found in the grid
  long hits = 0, edges = 0, crushing = 0;
};

}  // namespace

struct CollisionWorld::Impl {
  const Model& model;
  std::vector<std::shared_ptr<fcl::Convexd>> shapes;
  std::vector<std::unique_ptr<PartObject>> objects;
  PartArrays part_arrays;
  std::vector<PartWorld> world;  // per part: its world geometry (in part_arrays)
  // Two trees (Box2D's static/dynamic split): parts of sleeping bodies do not move and are never paired with each
  // other, so the per-step cost scales with the awake bodies. The trees give the awake x sleeping pairs; the awake
  // x awake pairs come from a grid rebuilt every step (awake_pairs_in_grid).
  fcl::DynamicAABBTreeCollisionManagerd awake_tree, sleeping_tree;
  // Per body: which tree holds its parts (the body table grows with fracture; removed bodies are in neither).
  static constexpr uint8_t kSleepingTree = 0, kAwakeTree = 1, kRemoved = 2;
  std::vector<uint8_t> tree_of;
  std::vector<fcl::CollisionObjectd*> moved_awake, moved_sleeping;
  std::vector<uint8_t> box_changed;    // per part, written by update_bodies
  std::vector<PairCandidate> pairs;
  std::vector<int> group_start;  // the body pairs: pairs[group_start[g], group_start[g + 1]) share one
  const State* state = nullptr;  // during find_contacts (the broad-phase callback reads the awake flags)
  ThreadPool& pool;
  std::vector<Scratch> scratch;
  std::vector<ChunkRange> chunk_ranges;  // per chunk of the narrow phase (written by the thread that ran it)

  bool compliant_structure, compliant_ice;  // options.contact, per pair of body classes
  int hull_count;                           // the vessel's and the structures' bodies, the model's first

  Impl(const Model& m, ThreadPool& p)
      : model(m),
        pool(p),
        scratch(p.threads()),
        compliant_structure(m.settings.contact.ice_structure == "compliant"),
        compliant_ice(m.settings.contact.ice_ice == "compliant"),
        hull_count(m.hull_count()) {}

  // A hull body's pair with ice: the hull bodies are the model's first, so the hull is always a.
  bool is_structure_pair(const PairCandidate& pc) const { return pc.body_a < hull_count; }
  // Between two bodies of ice (or ice and a wall): ice.mu_ice_ice, or none between two that pack (Body::frictionless).
  double ice_ice_mu(int a, int b) const {
    return model.bodies[a].frictionless && model.bodies[b].frictionless ? 0.0 : model.settings.ice.mu_ice_ice;
  }
  bool is_compliant(const PairCandidate& pc) const {
    // Domain walls are boundaries, not ice or a structure under test: always rigid.
    if (model.bodies[pc.body_a].kind == BodyKind::wall || model.bodies[pc.body_b].kind == BodyKind::wall)
      return false;
    // Brash is a block, not a plate: rigid contacts, cheap (one manifold, no crushing rows; PHYSICS.md §1.7).
    if (model.bodies[pc.body_a].brash || model.bodies[pc.body_b].brash) return false;
    return is_structure_pair(pc) ? compliant_structure : compliant_ice;
  }

  // The crushed state kept from the previous step for a contact of bodies (a, b) with this normal and point: a
  // cached crushing row of the pair whose remembered normal is within kSameDirection of the normal and whose
  // remembered point is within kSameSpot of the point (in a's frame: a floe that slides or turns meets fresh ice),
  // the nearest; or null.
  static constexpr double kSameDirection = 0.9994;  // cos 2 deg
  static constexpr double kSameSpot = 0.1;          // m
  const CachedContact* crushed_state(int a, int b, const Vec3& normal, const Vec3& point) const {
    const State& s = *state;
    const std::vector<CachedContact>& cache = s.contact_cache;
    auto it = std::lower_bound(cache.begin(), cache.end(), std::make_pair(a, b),
                               [](const CachedContact& c, const std::pair<int, int>& k) {
                                 return std::make_pair(c.body_a, c.body_b) < k;
                               });
    const Quat& qa = s.orientation[a];
    const CachedContact* best = nullptr;
    double best_d = 0;
    for (; it != cache.end() && it->body_a == a && it->body_b == b; ++it) {
      if (it->type != ContactType::crushing || (qa * it->crush_normal_a).dot(normal) < kSameDirection) continue;
      const double d = (qa * it->crush_point_a + s.position[a] - point).norm();
      if (d <= kSameSpot && (!best || d < best_d)) best_d = d, best = &*it;
    }
    return best;
  }

  // The crushing contacts of a compliant body pair, whose candidate part pairs are pairs[first, last), into out;
  // returns how many. `touching` counts the part pairs that press.
  //
  // One contact per direction and place, not per part pair. The part pairs of a body pair that press in about one
  // direction at one place (their normals within kSameContactCos of the contact's and their surfaces within
  // load_join_distance_m of it: a floe against one flank of the bow, across however many hull sections and floe
  // parts) make one contact: one normal, one point, two rows over their surfaces together,
  // one crushed state. A floe wedged in a notch, pressed on two faces at an angle, gets one contact per face. Per
  // part pair, a light piece pressed into its parent floe or the hull had 4-12 nearly dependent rows across part
  // seams; the force is the same sum (p A per member: their vector areas add up), on two rows.
  //
  // Crushed state: the ice crushed so far is gone. A contact remembers where it crushed last: its point as a
  // material point of a and of b (where the crushed face of b met a) and its normal, in a's frame. How far b's
  // point has moved away from a's along that normal is how far the pair has backed off from its crushed depth, g
  // (local to the contact: a floe tilting about it does not back off). A contact with g > 0 is measured at the
  // crushed depth (b moved back by g along the normal: the crushed face, not a fresh overlap), and its rows let it
  // approach over g without force. A contact pressing at or beyond its crushed depth is measured as it is and
  // remembers its current point and normal. The state lives as long as the parts overlap and the contact keeps its
  // place and direction (in the cache, like the warm start): a pair that backs off beyond its crushed depth
  // separates and forgets it.
  int crushing_contacts(int first, int last, Scratch& sc, std::vector<Contact>& out, long& touching) {
    const PairCandidate& pc0 = pairs[first];
    const int a = pc0.body_a, b = pc0.body_b;
    const bool structure = is_structure_pair(pc0);
    const PatchSide side = structure ? PatchSide::a_is_structure : PatchSide::symmetric;
    PatchScratch& ps = sc.patch;
    // 1. Each part pair's overlap as it is, about one local origin for the body pair. The hull bodies are the
    // model's first, so in a hull-floe pair the hull is always a (the structure side of the patch).
    const Vec3 origin = overlap_origin(world[pc0.part_a], world[pc0.part_b]);
    ps.surface.clear();
    ps.members.clear();
    for (int i = first; i < last; ++i) {
      const PairCandidate& pc = pairs[i];
      // A separating face axis proves the parts apart: most box-overlapping neighbours end here.
      if (separated(pc)) continue;
      PatchMember m;
      m.A = &model.parts[pc.part_a], m.wa = &world[pc.part_a];
      m.B = &model.parts[pc.part_b], m.wb = &world[pc.part_b];
      m.pair = i;
      if (clip_member(m, Vec3::Zero(), origin, side, ps.clip, ps.surface)) ps.members.push_back(m);
    }
    const int n = static_cast<int>(ps.members.size());
    touching += n;
    // 2. The members into contacts by direction and place (in pair order: deterministic). A member joins a contact
    // whose direction is within kSameContactCos of its own and whose surface's box comes within the join distance
    // of its surface's box: max(2 h, 1 m), the distance at which the fracture stage takes two contacts of a level
    // ice tile as one load (load_join_distance_m). So a contact never bridges a gap along the waterline (two hull
    // sections metres apart pressing in one direction stay two loads, each with its own width).
    // The ice's thickness: b's against a hull (always a), the thinner floe's between two floes.
    const double h = structure ? model.bodies[b].thickness_m
                               : std::min(model.bodies[a].thickness_m, model.bodies[b].thickness_m);
    const double join = load_join_distance_m(h);
    ps.groups.clear();
    ps.contact_of.resize(n);
    for (int k = 0; k < n; ++k) {
      const PatchMember& m = ps.members[k];
      Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
      for (int v = vertex_begin(ps.surface, m.poly_first); v < vertex_begin(ps.surface, m.poly_end); ++v)
        lo = lo.cwiseMin(ps.surface.v[v]), hi = hi.cwiseMax(ps.surface.v[v]);
      const Vec3 dir = m.vec_area.normalized();
      int c = 0;
      for (; c < static_cast<int>(ps.groups.size()); ++c) {
        const PatchScratch::Group& g = ps.groups[c];
        const Vec3 gap = (lo - g.hi).cwiseMax(g.lo - hi).cwiseMax(0.0);
        if (g.dir.normalized().dot(dir) >= kSameContactCos && gap.norm() <= join) break;
      }
      if (c == static_cast<int>(ps.groups.size())) ps.groups.push_back({Vec3::Zero(), lo, hi});
      PatchScratch::Group& g = ps.groups[c];
      g.dir += m.vec_area;
      g.lo = g.lo.cwiseMin(lo);
      g.hi = g.hi.cwiseMax(hi);
      ps.contact_of[k] = c;
    }
    // 3. Each contact.
    int made = 0;
    for (int c = 0; c < static_cast<int>(ps.groups.size()); ++c) {
      ps.contact.clear();
      for (int k = 0; k < n; ++k)
        if (ps.contact_of[k] == c) ps.contact.push_back(ps.members[k]);
      made += crushing_contact(a, b, structure, side, origin, ps, out);
    }
    return made;
  }

  // One crushing contact, of the members in ps.contact (clipped as they are into ps.surface), into out: its rows.
  // Returns false if it has none.
  bool crushing_contact(int a, int b, bool structure, PatchSide side, const Vec3& origin, PatchScratch& ps,
                        std::vector<Contact>& out) {
    const State& s = *state;
    // The area's secant spans the penetration this step is about to add at the current approach speed (at least
    // the finite-difference step): the implicit force F_0 + K_t dt (-v) then follows the clipped geometry up to
    // the end-of-step penetration instead of extrapolating a tangent taken over a few millimetres (a hull face
    // meeting a floe edge almost flat gets all its area within millimetres: the tangent would overshoot it many
    // times over), and the crushing force is capped at p_c A at the end of that step.
    const double dt = model.settings.time_step_s, eps = model.settings.contact.area_gradient_step_m;
    auto step_of = [&](const Vec3& p, const Vec3& nrm) {
      const Vec3 va = s.velocity[a] + s.angular_velocity[a].cross(p - s.position[a]);
      const Vec3 vb = s.velocity[b] + s.angular_velocity[b].cross(p - s.position[b]);
      return std::max(eps, dt * std::max(0.0, -nrm.dot(vb - va)));
    };
    std::vector<PatchMember>& ms = ps.contact;
    const PairCandidate key = pairs[ms.front().pair];  // the cache's key of the contact: its first part pair
    Vec3 centre;
    ContactPatch patch = patch_sums(ms.data(), static_cast<int>(ms.size()), origin, centre);
    if (!patch.valid) return false;
    const Vec3 xa = s.position[a], xb = s.position[b];
    const Quat &qa = s.orientation[a], &qb = s.orientation[b];
    const CachedContact* mem = crushed_state(a, b, patch.normal, patch.point);
    double gap = 0;
    Vec3 n = patch.normal;
    if (mem) {
      n = qa * mem->crush_normal_a;
      gap = std::max(0.0, n.dot((xb + qb * mem->crush_point_b) - (xa + qa * mem->crush_point_a)));
    }
    // With a gap: the crushed face (b moved back to the crushed depth); else the overlap as it is.
    const SurfacePolygons* surface = &ps.surface;
    Vec3 shift = Vec3::Zero();
    if (gap > 0) {
      shift = -gap * n;
      ps.shifted.clear();
      size_t kept = 0;
      for (PatchMember& m : ms)
        if (clip_member(m, shift, origin, side, ps.clip, ps.shifted)) ms[kept++] = m;
      ms.resize(kept);
      patch = patch_sums(ms.data(), static_cast<int>(ms.size()), origin, centre);
      if (!patch.valid) return false;
      surface = &ps.shifted;
    }
    complete_patch(patch, centre, ms.data(), static_cast<int>(ms.size()), *surface, shift, origin, step_of, ps);
    if (patch.row_count == 0) return false;
    // At or beyond the crushed depth: the current contact point and normal are the new crushed state.
    const Vec3 normal_a = gap > 0 ? mem->crush_normal_a : Vec3(qa.conjugate() * patch.normal);
    const Vec3 point_a = gap > 0 ? mem->crush_point_a : Vec3(qa.conjugate() * (patch.point - xa));
    const Vec3 point_b = gap > 0 ? mem->crush_point_b : Vec3(qb.conjugate() * (patch.point - xb));
    for (int k = 0; k < patch.row_count; ++k) {
      const PatchRow& pr = patch.rows[k];
      Contact c;
      c.body_a = a;
      c.part_a = key.part_a;
      c.body_b = b;
      c.part_b = key.part_b;
      c.row = pr.half;
      c.point = pr.point;  // with a gap: on the crushed face (where the force acts once the gap is closed)
      c.normal = patch.normal;
      // Mean depth of the crushed overlap (diagnostics only: no bias), or the gap back to the crushed depth.
      c.gap = gap > 0 ? gap : -patch.volume_m3 / patch.area_m2;
      c.type = ContactType::crushing;
      c.mu = structure ? model.settings.ice.mu_ice_structure : ice_ice_mu(a, b);
      c.area_m2 = pr.area_m2;
      c.area_end_m2 = pr.area_end_m2;
      c.area_step_m = patch.area_step_m;
      c.area_slope_m = (pr.area_end_m2 - pr.area_m2) / patch.area_step_m;
      c.crush_normal_a = normal_a;
      c.crush_point_a = point_a;
      c.crush_point_b = point_b;
      c.crush_gap_m = gap;
      c.span_lo = patch.span_lo;
      c.span_hi = patch.span_hi;
      out.push_back(c);
    }
    return true;
  }

  static constexpr double kTreeMargin = 0.1;  // m, see place_part
  // FCL shapes, objects and world data for the parts from `first` on (new parts of a grown table), placed at their
  // bodies' poses in `state`; not yet in a tree.
  void add_parts(const State& state, int first) {
    const size_t np = model.parts.size();
    shapes.resize(np);
    objects.resize(np);
    box_changed.resize(np, 0);
    FLOESIM_REQUIRE(static_cast<size_t>(first) == world.size(), "internal: parts from index ", first,
                    " added to a collision world of ", world.size(), " parts (parts are only appended)");
    std::vector<const ConvexPart*> added;
    for (size_t p = first; p < np; ++p) added.push_back(&model.parts[p]);
    part_arrays.add(added, world);
    for (size_t p = first; p < np; ++p) {
      const ConvexPart& cp = model.parts[p];
      auto verts = std::make_shared<std::vector<Vec3>>(cp.vertices);
      auto faces = std::make_shared<std::vector<int>>();
      for (const auto& f : cp.faces) {
        faces->push_back(static_cast<int>(f.size()));
        faces->insert(faces->end(), f.begin(), f.end());
      }
      shapes[p] = std::make_shared<fcl::Convexd>(verts, static_cast<int>(cp.faces.size()), faces);
      shapes[p]->computeLocalAABB();
      objects[p] = std::make_unique<PartObject>(shapes[p], static_cast<int>(p));
      place_part(static_cast<int>(p), state.position[cp.body], state.orientation[cp.body].toRotationMatrix());
      // The object's first box is FCL's, of the part at the origin: always replace it with the placed fat box.
      objects[p]->set_aabb(world[p].lo - Vec3::Constant(kTreeMargin), world[p].hi + Vec3::Constant(kTreeMargin));
    }
  }

  // Moves part p to the pose (x, R). Returns true when its box in the tree must change: the tree holds a box
  // enlarged by kTreeMargin (Box2D's fat boxes), so that small motions do not re-insert the leaf every step.
  bool place_part(int p, const Vec3& x, const Mat3& R) {
    PartWorld& w = world[p];
    transform_part(part_arrays.local(p), x, R, w);
    const Vec3 lo = w.lo, hi = w.hi;
    objects[p]->setTransform(R, x);
    const fcl::AABBd& fat = objects[p]->getAABB();
    if ((lo.array() >= fat.min_.array()).all() && (hi.array() <= fat.max_.array()).all()) return false;
    objects[p]->set_aabb(lo - Vec3::Constant(kTreeMargin), hi + Vec3::Constant(kTreeMargin));
    return true;
  }

  // The awake parts' pairs whose exact boxes overlap (those the tree of awake parts would give the callback), from a
  // uniform grid in x and y rebuilt every step. FCL's tree collided with itself cost 1.5 ms per step on a field with
  // every floe awake (5,500 parts), a third of the step and serial; the grid (one pass to count the parts per cell,
  // one to fill the cells, and the pairs within each cell) takes that step from 4.34 to 3.9-4.05 ms. A pair sharing
  // several cells is taken in one of them, the cell holding the corner (max lo.x, max lo.y) of the two boxes'
  // overlap, which both boxes cover. The cells' pairs are found on the pool's threads, rows of cells shared out in
  // chunks, each thread's pairs into its own list, the lists then appended to `pairs`: they hold each pair once,
  // and find_contacts sorts them, so neither the thread count nor the schedule shows in the result.
  struct GridItem {
    int part, body, i0, j0;  // the part, its body, and the cell of its box's low corner
    Vec3 lo, hi;             // the part's exact box (a copy: the pairs loop reads nothing else)
  };
  std::vector<int> grid_parts, grid_start, grid_fill;
  std::vector<GridItem> grid_items;
  void awake_pairs_in_grid() {
    grid_parts.clear();
    for (size_t b = 0; b < model.bodies.size(); ++b) {
      if (tree_of[b] != kAwakeTree) continue;
      const Body& body = model.bodies[b];
      for (int p = body.first_part; p < body.first_part + body.part_count; ++p) grid_parts.push_back(p);
    }
    const size_t n = grid_parts.size();
    if (n < 2) return;
    // Cells as large as a part is on average (so a part covers a few cells), over the parts' extent; fewer cells
    // than ~4 per part whatever the spread.
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300, size = 0;
    for (int p : grid_parts) {
      const PartWorld& w = world[p];
      x0 = std::min(x0, w.lo.x()), y0 = std::min(y0, w.lo.y());
      x1 = std::max(x1, w.hi.x()), y1 = std::max(y1, w.hi.y());
      size += std::max(w.hi.x() - w.lo.x(), w.hi.y() - w.lo.y());
    }
    double cell = std::max(size / static_cast<double>(n), 0.5);
    const double max_cells = 4.0 * static_cast<double>(n) + 1024;
    while (((x1 - x0) / cell + 1) * ((y1 - y0) / cell + 1) > max_cells) cell *= 1.5;
    const int nx = static_cast<int>((x1 - x0) / cell) + 1, ny = static_cast<int>((y1 - y0) / cell) + 1;
    auto ix = [&](double x) { return std::clamp(static_cast<int>((x - x0) / cell), 0, nx - 1); };
    auto iy = [&](double y) { return std::clamp(static_cast<int>((y - y0) / cell), 0, ny - 1); };
    grid_start.assign(static_cast<size_t>(nx) * ny + 1, 0);
    for (int p : grid_parts) {
      const PartWorld& w = world[p];
      for (int j = iy(w.lo.y()); j <= iy(w.hi.y()); ++j)
        for (int i = ix(w.lo.x()); i <= ix(w.hi.x()); ++i) ++grid_start[static_cast<size_t>(j) * nx + i + 1];
    }
    for (size_t c = 1; c < grid_start.size(); ++c) grid_start[c] += grid_start[c - 1];
    grid_items.resize(grid_start.back());
    grid_fill.assign(grid_start.begin(), grid_start.end() - 1);
    for (int p : grid_parts) {
      const PartWorld& w = world[p];
      const int i0 = ix(w.lo.x()), j0 = iy(w.lo.y());
      const GridItem item{p, model.parts[p].body, i0, j0, w.lo, w.hi};
      for (int j = j0; j <= iy(w.hi.y()); ++j)
        for (int i = i0; i <= ix(w.hi.x()); ++i) grid_items[grid_fill[static_cast<size_t>(j) * nx + i]++] = item;
    }
    // The cell of the overlap's corner is (max of the two i0, max of the two j0): ix and iy never decrease.
    constexpr int kRowsPerChunk = 4;
    for (auto& sc : scratch) sc.candidates.clear();
    pool.parallel_chunks(ny, kRowsPerChunk, [&](int row_begin, int row_end, int w, int) {
      std::vector<PairCandidate>& found = scratch[w].candidates;
      for (int j = row_begin; j < row_end; ++j)
        for (int i = 0; i < nx; ++i) {
          const size_t c = static_cast<size_t>(j) * nx + i;
          for (int a = grid_start[c]; a < grid_start[c + 1]; ++a)
            for (int b = a + 1; b < grid_start[c + 1]; ++b) {
              const GridItem& g1 = grid_items[a];
              const GridItem& g2 = grid_items[b];
              if (std::max(g1.i0, g2.i0) != i || std::max(g1.j0, g2.j0) != j) continue;
              if (keeps(g1.body, g1.lo, g1.hi, g2.body, g2.lo, g2.hi))
                found.push_back(ordered(g1.body, g1.part, g2.body, g2.part));
            }
        }
    });
    for (const auto& sc : scratch) pairs.insert(pairs.end(), sc.candidates.begin(), sc.candidates.end());
  }

  // A part pair of the broad phase is kept if the parts are of two bodies, one of them awake, not both hull bodies
  // (a ship and the structures do not touch one another: the loads recorded are the ice's), with overlapping exact
  // boxes (the tree's boxes are enlarged and depend on the history of the leaf; the exact boxes make the candidate
  // set a function of the current poses only).
  bool keeps(int b1, const Vec3& lo1, const Vec3& hi1, int b2, const Vec3& lo2, const Vec3& hi2) const {
    if (b1 == b2 || (!state->awake[b1] && !state->awake[b2])) return false;
    if (b1 < hull_count && b2 < hull_count) return false;
    return !((lo1.array() > hi2.array()).any() || (lo2.array() > hi1.array()).any());
  }
  // Part p1 of body b1 and part p2 of body b2 as a candidate, the lower body first.
  static PairCandidate ordered(int b1, int p1, int b2, int p2) {
    return b1 < b2 ? PairCandidate{b1, p1, b2, p2} : PairCandidate{b2, p2, b1, p1};
  }

  // A pair of the tree of awake parts against the tree of sleeping ones.
  void add_candidate(int p1, int p2) {
    const int b1 = model.parts[p1].body, b2 = model.parts[p2].body;
    if (keeps(b1, world[p1].lo, world[p1].hi, b2, world[p2].lo, world[p2].hi)) pairs.push_back(ordered(b1, p1, b2, p2));
  }

  static bool broadphase_callback(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
    auto* self = static_cast<Impl*>(data);
    self->add_candidate(static_cast<PartObject*>(o1)->part, static_cast<PartObject*>(o2)->part);
    return false;  // keep going
  }

  // Separation of the deepest vertex of `other` below each face of `ref`; returns the face of largest separation.
  // A face whose deepest vertex so far is already no better than the best face is left at once.
  static int best_face(const ConvexPart& ref, const PartWorld& rw, const PartWorld& other, double& sep) {
    int best = -1;
    sep = -1e300;
    for (size_t f = 0; f < ref.faces.size(); ++f) {
      if (ref.face_internal[f]) continue;  // not a surface of the body
      double s = 1e300;
      for (int i = 0; i < other.nv && s > sep; ++i) s = std::min(s, rw.n[f].dot(other.v[i]) - rw.d[f]);
      if (s > sep) {
        sep = s;
        best = static_cast<int>(f);
      }
    }
    return best;
  }

  // Builds the contacts of one touching pair (a < b by body) into out. Returns true for an edge contact.
  // Face axes of least overlap on both parts (SAT over the face normals): separation sa, sb (> 0: apart).
  struct FaceAxes {
    int fa, fb;
    double sa, sb;
  };
  // Whether a face of one part has the whole other part in front of it (the parts are apart): face_axes's
  // sa > 0 || sb > 0, without finding the best axes (a compliant pair needs only this).
  static bool face_separates(const ConvexPart& ref, const PartWorld& rw, const PartWorld& other) {
    for (size_t f = 0; f < ref.faces.size(); ++f) {
      if (ref.face_internal[f]) continue;
      bool all_in_front = true;
      for (int i = 0; i < other.nv && all_in_front; ++i) all_in_front = rw.n[f].dot(other.v[i]) - rw.d[f] > 0;
      if (all_in_front) return true;
    }
    return false;
  }
  bool separated(const PairCandidate& pc) const {
    return face_separates(model.parts[pc.part_a], world[pc.part_a], world[pc.part_b]) ||
           face_separates(model.parts[pc.part_b], world[pc.part_b], world[pc.part_a]);
  }
  FaceAxes face_axes(const PairCandidate& pc) const {
    FaceAxes f;
    f.fa = best_face(model.parts[pc.part_a], world[pc.part_a], world[pc.part_b], f.sa);
    f.fb = best_face(model.parts[pc.part_b], world[pc.part_b], world[pc.part_a], f.sb);
    return f;
  }

  // The rigid points of a part pair with brash (out[first, end)) share the brash's crushing force as a ceiling on
  // their normal impulses (Body::brash_crush_force_n; the smaller of two brash bodies').
  void cap_brash(const PairCandidate& pc, std::vector<Contact>& out, size_t first) const {
    const Body& a = model.bodies[pc.body_a];
    const Body& b = model.bodies[pc.body_b];
    if (!a.brash && !b.brash) return;
    const double f = !a.brash ? b.brash_crush_force_n
                              : !b.brash ? a.brash_crush_force_n
                                         : std::min(a.brash_crush_force_n, b.brash_crush_force_n);
    const size_t n = out.size() - first;
    for (size_t i = first; i < out.size(); ++i)
      out[i].max_normal_impulse = model.settings.time_step_s * f / static_cast<double>(n);
  }

  bool manifold(const PairCandidate& pc, const FaceAxes& axes, const fcl::Contactd& hint, Scratch& sc,
                std::vector<Contact>& out) {
    const ConvexPart& A = model.parts[pc.part_a];
    const ConvexPart& B = model.parts[pc.part_b];
    const PartWorld& wa = world[pc.part_a];
    const PartWorld& wb = world[pc.part_b];
    const double spec = model.settings.solver.speculative_m;
    const bool structure = is_structure_pair(pc);
    const double mu = structure ? model.settings.ice.mu_ice_structure : ice_ice_mu(pc.body_a, pc.body_b);
    auto emit = [&](const Vec3& p, const Vec3& n, double gap) {
      Contact c;
      c.body_a = pc.body_a;
      c.part_a = pc.part_a;
      c.body_b = pc.body_b;
      c.part_b = pc.part_b;
      c.point = p;
      c.normal = n;
      c.gap = gap;
      c.mu = mu;
      c.span_lo = c.span_hi = p;
      out.push_back(c);
    };

    // 1. Face axes of least overlap on both parts.
    const double sa = axes.sa, sb = axes.sb;
    const int fa = axes.fa, fb = axes.fb;
    const double face_overlap = -std::max(sa, sb);
    if (fa < 0 && fb < 0) {  // cannot happen for closed parts; keep FCL's point rather than fail
      emit(hint.pos, hint.normal, -std::max(0.0, hint.penetration_depth));
      return true;
    }

    // 2. FCL's normal, oriented from a to b by the smaller support overlap.
    Vec3 nh = hint.normal;
    if (!(nh.squaredNorm() > 0.5)) nh = Vec3::UnitZ();
    {
      double amax = -1e300, amin = 1e300, bmax = -1e300, bmin = 1e300;
      for (int i = 0; i < wa.nv; ++i) {
        const double t = nh.dot(wa.v[i]);
        amax = std::max(amax, t);
        amin = std::min(amin, t);
      }
      for (int i = 0; i < wb.nv; ++i) {
        const double t = nh.dot(wb.v[i]);
        bmax = std::max(bmax, t);
        bmin = std::min(bmin, t);
      }
      if (bmax - amin < amax - bmin) nh = -nh;
    }

    // 3. Edge-on-edge: every face axis overlaps clearly more than FCL's penetration. Keep FCL's single point,
    // unless FCL's normal is that of a face shared with another part of the same body (not a real surface).
    const double depth = std::max(0.0, hint.penetration_depth);
    auto along_internal = [&](const ConvexPart& P, const PartWorld& w, const Vec3& n) {
      for (size_t f = 0; f < P.faces.size(); ++f)
        if (P.face_internal[f] && std::abs(w.n[f].dot(n)) > 0.985) return true;
      return false;
    };
    if (depth < 0.6 * face_overlap - 1e-3 && !along_internal(A, wa, nh) && !along_internal(B, wb, nh)) {
      emit(hint.pos, nh, -depth);
      return true;
    }

    // 4. Reference face (prefer a unless b's face is clearly better) and the incident face most against it.
    const bool flip = sb > sa + 1e-4;
    const ConvexPart& R = flip ? B : A;
    const PartWorld& rw = flip ? wb : wa;
    const ConvexPart& I = flip ? A : B;
    const PartWorld& iw = flip ? wa : wb;
    const int rf = flip ? fb : fa;
    const Vec3 nr = rw.n[rf];
    int inc = 0;
    double most = 1e300;
    for (size_t f = 0; f < I.faces.size(); ++f) {
      const double d = iw.n[f].dot(nr);
      if (d < most) {
        most = d;
        inc = static_cast<int>(f);
      }
    }

    // 5. Clip the incident face by the side planes of the reference face.
    sc.poly.clear();
    for (int i : I.faces[inc]) sc.poly.push_back(iw.v[i]);
    const std::vector<int>& rface = R.faces[rf];
    const size_t m = rface.size();
    for (size_t e = 0; e < m && !sc.poly.empty(); ++e) {
      const Vec3& r0 = rw.v[rface[e]];
      const Vec3& r1 = rw.v[rface[(e + 1) % m]];
      const Vec3 side = (r1 - r0).cross(nr);  // outward side-plane normal for a CCW face
      sc.tmp.swap(sc.poly);
      sc.poly.clear();
      const size_t k = sc.tmp.size();
      for (size_t i = 0; i < k; ++i) {
        const Vec3& p = sc.tmp[i];
        const Vec3& q = sc.tmp[(i + 1) % k];
        const double dp = side.dot(p - r0), dq = side.dot(q - r0);
        if (dp <= 0) sc.poly.push_back(p);
        if ((dp <= 0) != (dq <= 0)) sc.poly.push_back(p + (dp / (dp - dq)) * (q - p));
      }
    }

    // 6. Points within the speculative distance of the reference plane; at most 4 kept (deepest, then the widest
    // spread), so that a flat contact resists tilting about any axis.
    const size_t first = out.size();
    const Vec3 n_ab = flip ? Vec3(-nr) : nr;
    for (const Vec3& p : sc.poly) {
      const double s = nr.dot(p) - rw.d[rf];
      if (s <= spec) emit(p - 0.5 * s * nr, n_ab, s);
    }
    const size_t cnt = out.size() - first;
    if (cnt == 0) {
      emit(hint.pos, nh, -depth);
      return true;
    }
    if (cnt > 4) {
      Contact* c = &out[first];
      std::vector<Contact> keep;
      keep.reserve(4);
      size_t i1 = 0;
      for (size_t i = 1; i < cnt; ++i)
        if (c[i].gap < c[i1].gap) i1 = i;
      size_t i2 = i1;
      double best = -1;
      for (size_t i = 0; i < cnt; ++i) {
        const double d = (c[i].point - c[i1].point).squaredNorm();
        if (d > best) best = d, i2 = i;
      }
      auto area = [&](size_t i) { return (c[i2].point - c[i1].point).cross(c[i].point - c[i1].point).dot(nr); };
      size_t i3 = i1;
      best = -1;
      for (size_t i = 0; i < cnt; ++i)
        if (std::abs(area(i)) > best) best = std::abs(area(i)), i3 = i;
      const double side3 = area(i3) >= 0 ? 1.0 : -1.0;
      size_t i4 = i1;
      best = 0;
      for (size_t i = 0; i < cnt; ++i)
        if (-side3 * area(i) > best) best = -side3 * area(i), i4 = i;
      size_t chosen[4] = {i1, i2, i3, i4};
      for (int k = 0; k < 4; ++k)
        if (std::find(chosen, chosen + k, chosen[k]) == chosen + k) keep.push_back(c[chosen[k]]);
      out.resize(first);
      out.insert(out.end(), keep.begin(), keep.end());
    }
    return false;
  }
};

CollisionWorld::CollisionWorld(const Model& model, const State& state, ThreadPool& pool)
    : impl_(std::make_unique<Impl>(model, pool)) {
  Impl& m = *impl_;
  m.add_parts(state, 0);
  m.tree_of.assign(model.bodies.size(), 0);
  std::vector<fcl::CollisionObjectd*> awake, sleeping;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const Body& body = model.bodies[b];
    m.tree_of[b] = state.awake[b] ? Impl::kAwakeTree : Impl::kSleepingTree;
    for (int p = body.first_part; p < body.first_part + body.part_count; ++p)
      (state.awake[b] ? awake : sleeping).push_back(m.objects[p].get());
  }
  m.awake_tree.registerObjects(awake);
  m.awake_tree.setup();
  m.sleeping_tree.registerObjects(sleeping);
  m.sleeping_tree.setup();
}

CollisionWorld::~CollisionWorld() = default;

void CollisionWorld::add_bodies(const State& state, int first_new) {
  Impl& m = *impl_;
  const size_t nb = m.model.bodies.size();
  if (static_cast<size_t>(first_new) >= nb) return;
  m.add_parts(state, m.model.bodies[first_new].first_part);
  m.tree_of.resize(nb, Impl::kRemoved);
  for (size_t b = first_new; b < nb; ++b) {
    const Body& body = m.model.bodies[b];
    m.tree_of[b] = state.awake[b] ? Impl::kAwakeTree : Impl::kSleepingTree;
    auto& tree = state.awake[b] ? m.awake_tree : m.sleeping_tree;
    for (int p = body.first_part; p < body.first_part + body.part_count; ++p) tree.registerObject(m.objects[p].get());
  }
}

void CollisionWorld::remove_body(int b) {
  Impl& m = *impl_;
  if (m.tree_of[b] == Impl::kRemoved) return;
  auto& tree = m.tree_of[b] == Impl::kAwakeTree ? m.awake_tree : m.sleeping_tree;
  const Body& body = m.model.bodies[b];
  // A removed body never comes back (fracture gives its pieces new bodies): its parts' FCL objects and shapes (a copy
  // of each part's geometry, with FCL's edges and neighbours) and, once no part of their batch is left, their arrays
  // are freed, so that a run's memory follows the ice that exists, not every piece it ever had.
  for (int p = body.first_part; p < body.first_part + body.part_count; ++p) {
    tree.unregisterObject(m.objects[p].get());
    m.objects[p].reset();
    m.shapes[p].reset();
    m.part_arrays.release(p);
  }
  m.tree_of[b] = Impl::kRemoved;
}

void CollisionWorld::update_bodies(const State& state, const std::vector<int>& moved) {
  Impl& m = *impl_;
  m.moved_awake.clear();
  m.moved_sleeping.clear();
  // Poses in parallel (each part writes only its own data), tree updates in body order.
  m.box_changed.resize(m.model.parts.size());
  m.pool.parallel_for(static_cast<int>(moved.size()), [&](int begin, int end, int) {
    for (int i = begin; i < end; ++i) {
      const int b = moved[i];
      if (m.tree_of[b] == Impl::kRemoved) continue;
      const Body& body = m.model.bodies[b];
      const Mat3 R = state.orientation[b].toRotationMatrix();
      for (int p = body.first_part; p < body.first_part + body.part_count; ++p)
        m.box_changed[p] = m.place_part(p, state.position[b], R);
    }
  });
  for (int b : moved) {
    if (m.tree_of[b] == Impl::kRemoved) continue;
    const Body& body = m.model.bodies[b];
    for (int p = body.first_part; p < body.first_part + body.part_count; ++p)
      if (m.box_changed[p])
        (m.tree_of[b] == Impl::kAwakeTree ? m.moved_awake : m.moved_sleeping).push_back(m.objects[p].get());
  }
  if (!m.moved_awake.empty()) m.awake_tree.update(m.moved_awake);
  if (!m.moved_sleeping.empty()) m.sleeping_tree.update(m.moved_sleeping);
  // Bodies that fell asleep or woke up since the last call change trees (their boxes are current).
  for (size_t b = 0; b < m.model.bodies.size(); ++b) {
    const uint8_t want = state.awake[b] ? Impl::kAwakeTree : Impl::kSleepingTree;
    if (m.tree_of[b] == Impl::kRemoved || m.tree_of[b] == want) continue;
    const Body& body = m.model.bodies[b];
    auto& from = m.tree_of[b] == Impl::kAwakeTree ? m.awake_tree : m.sleeping_tree;
    auto& to = want == Impl::kAwakeTree ? m.awake_tree : m.sleeping_tree;
    for (int p = body.first_part; p < body.first_part + body.part_count; ++p) {
      from.unregisterObject(m.objects[p].get());
      to.registerObject(m.objects[p].get());
    }
    m.tree_of[b] = want;
  }
}

void CollisionWorld::find_contacts(const State& state, std::vector<Contact>& out) {
  Impl& m = *impl_;
  out.clear();
  // Broad phase: candidate part pairs, then a fixed order so that runs are deterministic.
  m.pairs.clear();
  m.state = &state;
  m.awake_pairs_in_grid();
  m.awake_tree.collide(&m.sleeping_tree, &m, &Impl::broadphase_callback);
  std::sort(m.pairs.begin(), m.pairs.end());
  stats_ = CollisionStats{};
  stats_.broadphase_pairs = static_cast<long>(m.pairs.size());

  // Narrow phase per body pair, in chunks of body pairs handed to whichever thread is free; each chunk's contacts
  // are kept in pair order in its thread's buffer, and the chunks are put together in chunk order.
  const int npairs = static_cast<int>(m.pairs.size());
  m.group_start.clear();
  for (int i = 0; i < npairs; ++i)
    if (i == 0 || m.pairs[i].body_a != m.pairs[i - 1].body_a || m.pairs[i].body_b != m.pairs[i - 1].body_b)
      m.group_start.push_back(i);
  m.group_start.push_back(npairs);
  const int ngroups = static_cast<int>(m.group_start.size()) - 1;
  for (auto& sc : m.scratch) {
    sc.contacts.clear();
    sc.hits = sc.edges = sc.crushing = 0;
  }
  constexpr int kChunk = 8;
  m.chunk_ranges.resize((ngroups + kChunk - 1) / kChunk);
  m.pool.parallel_chunks(ngroups, kChunk, [&](int begin, int end, int w, int chunk) {
    Scratch& sc = m.scratch[w];
    const int first = static_cast<int>(sc.contacts.size());
    fcl::CollisionRequestd req(1, true);
    req.gjk_solver_type = fcl::GST_LIBCCD;
    for (int g = begin; g < end; ++g) {
      const int pair_begin = m.group_start[g], pair_end = m.group_start[g + 1];
      if (m.is_compliant(m.pairs[pair_begin])) {  // the law is one per pair of body classes
        sc.crushing += m.crushing_contacts(pair_begin, pair_end, sc, sc.contacts, sc.hits);
        continue;
      }
      for (int i = pair_begin; i < pair_end; ++i) {
        const PairCandidate& pc = m.pairs[i];
        // A separating face axis proves the parts apart: most box-overlapping neighbours end here, before GJK.
        const Impl::FaceAxes axes = m.face_axes(pc);
        if (axes.sa > 0 || axes.sb > 0) continue;
        fcl::CollisionResultd res;
        fcl::collide(m.objects[pc.part_a].get(), m.objects[pc.part_b].get(), req, res);
        if (!res.isCollision() || res.numContacts() == 0) continue;
        ++sc.hits;
        // FCL's normal points from its first object to its second: part_a to part_b here.
        const size_t made = sc.contacts.size();
        if (m.manifold(pc, axes, res.getContact(0), sc, sc.contacts)) ++sc.edges;
        m.cap_brash(pc, sc.contacts, made);
      }
    }
    m.chunk_ranges[chunk] = {w, first, static_cast<int>(sc.contacts.size())};
  });
  // The chunks in pair order, whichever thread ran them: the contacts are in sorted pair order, as with one thread.
  for (const ChunkRange& r : m.chunk_ranges) {
    const std::vector<Contact>& cs = m.scratch[r.worker].contacts;
    out.insert(out.end(), cs.begin() + r.first, cs.begin() + r.end);
  }
  for (auto& sc : m.scratch) {
    stats_.narrowphase_hits += sc.hits;
    stats_.edge_contacts += sc.edges;
    stats_.crushing_contacts += sc.crushing;
  }
  m.state = nullptr;
}

ContactPatch convex_overlap(const ConvexPart& pa, const Vec3& xa, const Quat& qa, const ConvexPart& pb,
                            const Vec3& xb, const Quat& qb, PatchSide side, double eps) {
  PartArrays arrays;
  std::vector<PartWorld> views;
  arrays.add({&pa, &pb}, views);
  PartWorld &wa = views[0], &wb = views[1];
  transform_part(arrays.local(0), xa, qa.toRotationMatrix(), wa);
  transform_part(arrays.local(1), xb, qb.toRotationMatrix(), wb);
  PatchScratch ps;
  PatchMember m;
  m.A = &pa, m.wa = &wa, m.B = &pb, m.wb = &wb;
  const Vec3 origin = overlap_origin(wa, wb);
  if (!clip_member(m, Vec3::Zero(), origin, side, ps.clip, ps.surface)) return ContactPatch{};
  Vec3 centre;
  ContactPatch r = patch_sums(&m, 1, origin, centre);
  if (r.valid)
    complete_patch(r, centre, &m, 1, ps.surface, Vec3::Zero(), origin, [eps](const Vec3&, const Vec3&) { return eps; },
                   ps);
  return r;
}

}  // namespace floesim::sim
