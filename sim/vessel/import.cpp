// A user's CAD mesh: loading it (assimp) into convex parts (load_hull, hull_model_from_parts, require_floating),
// placing it in the hull frame (place_point, describe_placement) and the floesim-hull stage for it
// (write_imported_hull).
#include "sim/vessel/hull.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>

#include <Eigen/Geometry>
#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/provenance.h"
#include "pipeline/geometry2d.h"
#include "sim/vessel/hull_internal.h"
#include "sim/vessel/particulars.h"

namespace floesim::sim {

namespace fs = std::filesystem;
using namespace detail;

namespace {

std::string percent(double f) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%+.2f %%", 100.0 * f);
  return buf;
}

// ---- mesh topology -----------------------------------------------------------------------------------------------

struct Topology {
  int unbalanced_edges = 0;   // edges not used equally often in both directions: holes or flipped triangles
  int boundary_edges = 0;     // edges used once (holes)
  int non_manifold_edges = 0;  // edges used more than twice
  bool even = true;           // every edge used an even number of times (closed, maybe inconsistently oriented)
};

Topology topology(const TriMesh& m) {
  std::map<std::pair<int, int>, std::pair<int, int>> uses;  // (lo, hi) -> (uses lo->hi, uses hi->lo)
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (a < b) ++uses[{a, b}].first;
      else ++uses[{b, a}].second;
    }
  Topology top;
  for (const auto& [e, u] : uses) {
    const int total = u.first + u.second;
    top.unbalanced_edges += u.first != u.second;
    top.boundary_edges += total == 1;
    top.non_manifold_edges += total > 2;
    top.even = top.even && total % 2 == 0;
  }
  return top;
}

// Re-orients triangles consistently by walking across manifold edges (used by exactly two triangles): a neighbour
// must use the shared edge in the opposite direction. Returns the number of triangles flipped.
int orient_consistently(TriMesh& m) {
  std::map<std::pair<int, int>, std::vector<int>> tris_of_edge;
  for (int i = 0; i < static_cast<int>(m.triangles.size()); ++i)
    for (int k = 0; k < 3; ++k) {
      const int a = m.triangles[i][k], b = m.triangles[i][(k + 1) % 3];
      tris_of_edge[{std::min(a, b), std::max(a, b)}].push_back(i);
    }
  auto uses_forward = [&](int t, int a, int b) {
    for (int k = 0; k < 3; ++k)
      if (m.triangles[t][k] == a && m.triangles[t][(k + 1) % 3] == b) return true;
    return false;
  };
  std::vector<char> done(m.triangles.size(), 0);
  int flipped = 0;
  for (size_t seed = 0; seed < m.triangles.size(); ++seed) {
    if (done[seed]) continue;
    done[seed] = 1;
    std::vector<int> queue{static_cast<int>(seed)};
    for (size_t h = 0; h < queue.size(); ++h) {
      const int t = queue[h];
      for (int k = 0; k < 3; ++k) {
        const int a = m.triangles[t][k], b = m.triangles[t][(k + 1) % 3];
        const auto& nb = tris_of_edge[{std::min(a, b), std::max(a, b)}];
        if (nb.size() != 2) continue;
        const int u = nb[0] == t ? nb[1] : nb[0];
        if (done[u]) continue;
        done[u] = 1;
        if (uses_forward(u, a, b)) {
          std::swap(m.triangles[u][1], m.triangles[u][2]);
          ++flipped;
        }
        queue.push_back(u);
      }
    }
  }
  return flipped;
}

void flip(TriMesh& m) {
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
}

// Welds vertices at identical positions and drops triangles that collapse; formats differ in how they share
// vertices (OBJ groups, STL not at all) and assimp only joins vertices whose every attribute matches.
TriMesh weld(const std::vector<Vec3>& v, const std::vector<std::array<int, 3>>& tris) {
  TriMesh m;
  std::map<std::array<double, 3>, int> index;
  std::vector<int> remap(v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    const auto [it, fresh] = index.emplace(std::array<double, 3>{v[i].x(), v[i].y(), v[i].z()},
                                           static_cast<int>(m.vertices.size()));
    if (fresh) m.vertices.push_back(v[i]);
    remap[i] = it->second;
  }
  for (const auto& t : tris) {
    const std::array<int, 3> u{remap[t[0]], remap[t[1]], remap[t[2]]};
    if (u[0] != u[1] && u[1] != u[2] && u[2] != u[0]) m.triangles.push_back(u);
  }
  return m;
}

}  // namespace

// ---- loading ---------------------------------------------------------------------------------------------------

namespace {

struct Body {
  std::string name;
  TriMesh mesh;
  std::string notes;  // topology repairs, for the report
};

// Sutherland-Hodgman step: keeps the part of `poly` with sign * (p[axis] - value) >= 0. A crossing point is
// interpolated from the lexicographically smaller end of its edge, so neighbouring cells cut the same edge into the
// same point.
void clip_polygon(std::vector<Vec3>& poly, int axis, double value, double sign) {
  if (poly.empty()) return;
  std::vector<Vec3> out;
  const size_t n = poly.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = poly[i];
    const Vec3& q = poly[(i + 1) % n];
    const double dp = sign * (p[axis] - value), dq = sign * (q[axis] - value);
    if (dp >= 0) out.push_back(p);
    if ((dp > 0 && dq < 0) || (dp < 0 && dq > 0)) {
      const bool p_first = std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3);
      const Vec3& a = p_first ? p : q;
      const Vec3& c = p_first ? q : p;
      Vec3 x = a + (c - a) * ((value - a[axis]) / (c[axis] - a[axis]));
      x[axis] = value;
      out.push_back(x);
    }
  }
  poly.swap(out);
}

// Volume of the closed mesh where x < x0: the triangles clipped to that half-space, summed as signed tetrahedra
// with their apex on the plane x = x0, where the cap lies (so the cap adds nothing).
double volume_behind(const TriMesh& m, double x0, const Vec3& centre) {
  const Vec3 ref(x0, centre.y(), centre.z());
  double v6 = 0;
  std::vector<Vec3> poly;
  for (const auto& t : m.triangles) {
    poly = {m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]};
    clip_polygon(poly, 0, x0, -1.0);
    for (size_t k = 1; k + 1 < poly.size(); ++k)
      v6 += (poly[0] - ref).dot((poly[k] - ref).cross(poly[k + 1] - ref));
  }
  return v6 / 6.0;
}

// The points whose convex hull is the hull of (solid inside the cell x in [a, b], z in [c, d]): every vertex of
// the mesh's triangles clipped to the cell (mesh vertices inside it, edges crossing its planes, triangles crossing
// its edge lines). Sorted and unique.
std::vector<Vec3> cell_points(const TriMesh& m, const std::vector<int>& tris, double a, double b, double c, double d) {
  std::vector<Vec3> pts, poly;
  for (int i : tris) {
    const auto& t = m.triangles[i];
    poly = {m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]};
    clip_polygon(poly, 0, a, 1.0);
    clip_polygon(poly, 0, b, -1.0);
    clip_polygon(poly, 2, c, 1.0);
    clip_polygon(poly, 2, d, -1.0);
    pts.insert(pts.end(), poly.begin(), poly.end());
  }
  auto less = [](const Vec3& p, const Vec3& q) {
    return std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3);
  };
  std::sort(pts.begin(), pts.end(), less);
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  return pts;
}

// Convex hull of a cell's points, or nothing if the cell holds no volume (a gap in the mesh along x or z).
bool cell_hull(const std::vector<Vec3>& pts, double size, TriMesh& out) {
  if (pts.size() < 4) return false;
  const Bounds cb(pts);
  if ((cb.hi - cb.lo).minCoeff() <= 1e-9 * size) return false;
  out = convex_hull(pts);
  return true;
}

struct Sliced {
  std::vector<TriMesh> parts;
  int layered_sections = 0;  // sections also cut horizontally
  int max_layers = 1;
  int merges = 0;            // neighbouring sections merged into one part
};

// Cuts a closed mesh into `n` sections along x and takes the convex hull of each. A section whose hull adds more
// than `target` of its own volume (a bulbous bow, a skeg, flare over a narrow waterline: a concave cross-section)
// is also cut by horizontal planes into 2, 4 or 8 layers, whichever first meets the target (else the best), with
// one hull per cell. Cells share their cutting planes, so their hulls meet without overlapping. Then neighbouring
// uncut sections are merged while the hull of both adds less than `merge` of their volume (a parallel middle body
// needs no cuts), which keeps the part count, and so the contact work, down.
Sliced slice_convex(const TriMesh& m, int n, double target, double merge) {
  const Bounds b(m.vertices);
  const double size = b.diagonal();
  const Vec3 centre = 0.5 * (b.lo + b.hi);
  std::vector<double> plane(n + 1);
  for (int k = 0; k <= n; ++k) plane[k] = k == n ? b.hi.x() : b.lo.x() + (b.hi.x() - b.lo.x()) * k / n;
  std::vector<double> behind(n + 1);
  behind[0] = 0;
  behind[n] = mass_properties(m).volume;
  for (int k = 1; k < n; ++k) behind[k] = volume_behind(m, plane[k], centre);
  // Triangles by section (those whose x range meets the section's).
  std::vector<std::vector<int>> tris(n);
  for (int i = 0; i < static_cast<int>(m.triangles.size()); ++i) {
    const auto& t = m.triangles[i];
    const double lo = std::min({m.vertices[t[0]].x(), m.vertices[t[1]].x(), m.vertices[t[2]].x()});
    const double hi = std::max({m.vertices[t[0]].x(), m.vertices[t[1]].x(), m.vertices[t[2]].x()});
    for (int k = 0; k < n; ++k)
      if (hi >= plane[k] && lo <= plane[k + 1]) tris[k].push_back(i);
  }
  const double inf = std::numeric_limits<double>::infinity();
  Sliced out;
  bool open_run = false;  // the last part is an uncut section that the next may merge into
  for (int k = 0; k < n; ++k) {
    const double truth = behind[k + 1] - behind[k];
    const std::vector<Vec3> pts = cell_points(m, tris[k], plane[k], plane[k + 1], -inf, inf);
    TriMesh whole;
    if (!cell_hull(pts, size, whole)) {
      open_run = false;
      continue;
    }
    std::vector<TriMesh> best{whole};
    double best_excess = mass_properties(whole).volume - truth;
    int best_layers = 1;
    if (best_excess > target * truth) {
      const Bounds sb(pts);
      for (int layers : {2, 4, 8}) {
        std::vector<TriMesh> cells;
        double v = 0;
        for (int j = 0; j < layers; ++j) {
          const double c = j == 0 ? -inf : sb.lo.z() + (sb.hi.z() - sb.lo.z()) * j / layers;
          const double d = j == layers - 1 ? inf : sb.lo.z() + (sb.hi.z() - sb.lo.z()) * (j + 1) / layers;
          TriMesh cell;
          if (!cell_hull(cell_points(m, tris[k], plane[k], plane[k + 1], c, d), size, cell)) continue;
          v += mass_properties(cell).volume;
          cells.push_back(std::move(cell));
        }
        if (v - truth < best_excess) best = std::move(cells), best_excess = v - truth, best_layers = layers;
        if (best_excess <= target * truth) break;
      }
    }
    if (best_layers > 1) {
      ++out.layered_sections, out.max_layers = std::max(out.max_layers, best_layers);
      for (TriMesh& p : best) out.parts.push_back(std::move(p));
      open_run = false;
      continue;
    }
    // Uncut section: merge into the previous part if that is an uncut section too and the union stays convex.
    if (open_run) {
      TriMesh& last = out.parts.back();
      std::vector<Vec3> both = last.vertices;
      both.insert(both.end(), whole.vertices.begin(), whole.vertices.end());
      TriMesh merged = convex_hull(both);
      const double v_sep = mass_properties(last).volume + mass_properties(whole).volume;
      if (mass_properties(merged).volume - v_sep <= merge * v_sep) {
        last = std::move(merged);
        ++out.merges;
        continue;
      }
    }
    out.parts.push_back(std::move(whole));
    open_run = true;
  }
  return out;
}


}  // namespace

// A section whose convex hull adds more than this fraction of its volume is also cut horizontally.
constexpr double kSectionExcessTarget = 0.02;
// Neighbouring sections are merged into one part while the hull of both adds less than this fraction.
constexpr double kMergeExcess = 0.001;

HullModel hull_model_from_parts(std::vector<TriMesh> parts) {
  HullModel h;
  h.parts = std::move(parts);
  h.surface = merge(h.parts);
  h.mesh = h.surface;
  return h;
}

namespace {

// A mesh instance of the file's node tree, in world coordinates.
struct Instance {
  std::string name;
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  int skipped_faces = 0;  // points and lines
};

// The file and the options are checked before anything is read: file present and regular, non_convex, slices,
// scale, origin, and the placement's axis names (place_point checks up_direction and bow_direction).
void check_load_inputs(const fs::path& file, const HullLoadOptions& o, const HullPlacement& placement) {
  const std::string where = file.string();
  FLOESIM_REQUIRE(fs::exists(file), where, ": hull file not found");
  FLOESIM_REQUIRE(fs::is_regular_file(file), where, ": not a regular file");
  FLOESIM_REQUIRE(o.non_convex == "slice" || o.non_convex == "refuse", where,
                  ": non_convex must be \"slice\" or \"refuse\", got \"", o.non_convex, "\"");
  FLOESIM_REQUIRE(o.slices >= 2, where, ": slices must be >= 2, got ", o.slices);
  FLOESIM_REQUIRE(placement.scale > 0 && std::isfinite(placement.scale), where, ": scale must be > 0, got ",
                  placement.scale);
  FLOESIM_REQUIRE(placement.origin_m.size() == 2, where, ": origin_m must be [x, y]");
  try {
    place_point(placement, Vec3::Zero());  // checks up_direction and bow_direction
  } catch (const Error& e) {
    throw Error(where + ": " + e.what());
  }
}

// One instance of `mesh` (index `index` of the scene) under a node with transform `world`: vertices transformed,
// triangles kept (a mirroring transform turns outward normals inward: reversed), points and lines counted.
Instance mesh_instance(const aiMesh* mesh, const aiNode* node, unsigned index, const Eigen::Matrix4d& world,
                       const std::string& where) {
  const bool mirrored = world.topLeftCorner<3, 3>().determinant() < 0;
  Instance in;
  in.name = mesh->mName.length > 0 ? mesh->mName.C_Str()
                                   : (node->mName.length > 0 ? std::string(node->mName.C_Str()) : "mesh") + "#" +
                                         std::to_string(index);
  for (unsigned k = 0; k < mesh->mNumVertices; ++k) {
    const aiVector3D& p = mesh->mVertices[k];
    const Eigen::Vector4d w = world * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
    in.v.emplace_back(w.x() / w.w(), w.y() / w.w(), w.z() / w.w());
  }
  for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
    const aiFace& face = mesh->mFaces[f];
    if (face.mNumIndices != 3) {
      ++in.skipped_faces;
      continue;
    }
    for (unsigned k = 0; k < 3; ++k)
      FLOESIM_REQUIRE(face.mIndices[k] < mesh->mNumVertices, where, ": mesh '", in.name, "' face ", f,
                      " names vertex ", face.mIndices[k], " of ", mesh->mNumVertices, " (damaged file)");
    std::array<int, 3> t{int(face.mIndices[0]), int(face.mIndices[1]), int(face.mIndices[2])};
    if (mirrored) std::swap(t[1], t[2]);  // a mirroring transform turns outward normals inward
    in.t.push_back(t);
  }
  return in;
}

// Every mesh instance under `node` (its parent's world transform `up`), depth first, appended to `out`: node
// transforms are applied here, so a mesh instanced twice stays two parts.
void collect_instances(const aiScene* scene, const aiNode* node, const Eigen::Matrix4d& up, const std::string& where,
                       std::vector<Instance>& out) {
  Eigen::Matrix4d local;
  const aiMatrix4x4& a = node->mTransformation;
  local << a.a1, a.a2, a.a3, a.a4, a.b1, a.b2, a.b3, a.b4, a.c1, a.c2, a.c3, a.c4, a.d1, a.d2, a.d3, a.d4;
  const Eigen::Matrix4d world = up * local;
  for (unsigned i = 0; i < node->mNumMeshes; ++i) {
    // assimp does not validate what its importers build (no aiProcess_ValidateDataStructure, which also refuses
    // harmless files): indices are checked here before they index anything.
    FLOESIM_REQUIRE(node->mMeshes[i] < scene->mNumMeshes && scene->mMeshes[node->mMeshes[i]] != nullptr, where,
                    ": the file's node tree references mesh ", node->mMeshes[i], " of ", scene->mNumMeshes,
                    " (damaged file)");
    out.push_back(mesh_instance(scene->mMeshes[node->mMeshes[i]], node, node->mMeshes[i], world, where));
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) collect_instances(scene, node->mChildren[c], world, where, out);
}

// Reads the mesh file with assimp and returns every mesh instance in the node tree, in world (file) coordinates.
std::vector<Instance> read_instances(const std::string& where) {
  Assimp::Importer importer;
  // Our world is z-up like most CAD exports. assimp would turn a Collada file declaring Z_UP into its own y-up
  // convention with a root rotation; keep the file's axes instead. (glTF is y-up by definition: such a hull must
  // be exported z-up.)
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  // Triangulate n-gons; join identical vertices. No PreTransformVertices: node transforms are applied below, so
  // a mesh instanced twice stays two parts.
  const aiScene* scene = importer.ReadFile(where, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  FLOESIM_REQUIRE(scene != nullptr, where, ": cannot read as a mesh file: ", importer.GetErrorString());
  FLOESIM_REQUIRE(!(scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE), where, ": the file is incomplete or damaged");
  FLOESIM_REQUIRE(scene->mRootNode != nullptr && scene->mNumMeshes > 0, where, ": the file holds no meshes");
  std::vector<Instance> instances;
  collect_instances(scene, scene->mRootNode, Eigen::Matrix4d::Identity(), where, instances);
  FLOESIM_REQUIRE(!instances.empty(), where, ": the file's node tree references no meshes");
  return instances;
}

// The placement, before anything else: welding, slicing along x and the hydrostatics all work in the hull frame.
// Equal file positions stay equal (one deterministic map), so welding is unchanged. A proper rotation keeps the
// triangles' orientation. Returns the largest finite file coordinate (it sets the rounding of single-precision
// input).
double place_instances(std::vector<Instance>& instances, const HullPlacement& placement) {
  double file_max_abs = 0;  // largest file coordinate: sets the rounding of single-precision input
  for (Instance& in : instances)
    for (Vec3& p : in.v) {
      if (p.allFinite()) file_max_abs = std::max(file_max_abs, p.cwiseAbs().maxCoeff());
      p = place_point(placement, p);
    }
  return file_max_abs;
}

// The instances as one vertex and triangle list (indices offset), in order.
Instance joined(const std::vector<const Instance*>& parts) {
  Instance all;
  for (const Instance* in : parts) {
    const int off = static_cast<int>(all.v.size());
    all.v.insert(all.v.end(), in->v.begin(), in->v.end());
    for (const auto& t : in->t) all.t.push_back({t[0] + off, t[1] + off, t[2] + off});
  }
  return all;
}

// Closed meshes are bodies of their own (welded, re-oriented consistently where that closes them): appended to
// `bodies`. Returns the meshes that are open on their own. A non-finite vertex or a mesh without triangles is an
// error.
std::vector<const Instance*> closed_bodies(const std::vector<Instance>& instances, const std::string& where,
                                           std::vector<Body>& bodies) {
  std::vector<const Instance*> open;
  for (const Instance& in : instances) {
    for (const Vec3& p : in.v)
      FLOESIM_REQUIRE(p.allFinite(), where, ": mesh '", in.name, "' has a non-finite vertex coordinate");
    Body body{in.name, weld(in.v, in.t), ""};
    if (in.skipped_faces > 0) body.notes += std::to_string(in.skipped_faces) + " point/line faces ignored; ";
    FLOESIM_REQUIRE(!body.mesh.triangles.empty(), where, ": mesh '", in.name, "' has no triangles (degenerate mesh)");
    Topology top = topology(body.mesh);
    if (top.unbalanced_edges > 0 && top.even) {
      const int f = orient_consistently(body.mesh);
      top = topology(body.mesh);
      if (top.unbalanced_edges == 0) body.notes += std::to_string(f) + " triangles re-oriented consistently; ";
    }
    if (top.unbalanced_edges == 0) {
      if (top.non_manifold_edges > 0)
        body.notes += std::to_string(top.non_manifold_edges) + " non-manifold edges; ";
      bodies.push_back(std::move(body));
    } else {
      open.push_back(&in);
    }
  }
  return open;
}

// Meshes that are open on their own (an OBJ whose hull, deck and transom are separate groups, as in the KCS and
// DTMB 5415 benchmark files) are welded together into one body if together they close; otherwise the file is
// refused: buoyancy needs a watertight hull.
Body welded_open_meshes(const std::vector<const Instance*>& open, const std::string& where) {
  std::string names;
  for (const Instance* in : open) names += (names.empty() ? "'" : ", '") + in->name + "'";
  const Instance all = joined(open);
  Body body{open.size() == 1 ? open[0]->name : "", weld(all.v, all.t), ""};
  if (open.size() > 1)
    for (const Instance* in : open) body.name += (body.name.empty() ? "" : "+") + in->name;
  Topology top = topology(body.mesh);
  int flipped = 0;
  if (top.unbalanced_edges > 0 && top.even) {
    flipped = orient_consistently(body.mesh);
    top = topology(body.mesh);
  }
  FLOESIM_REQUIRE(top.unbalanced_edges == 0, where, ": mesh", open.size() > 1 ? "es " : " ", names,
                  open.size() > 1 ? " are" : " is", " not closed (", top.unbalanced_edges,
                  " edges without a matching opposite edge, ", top.boundary_edges, " of them boundary edges, i.e. holes",
                  open.size() > 1 ? ", also when welded together" : "",
                  "); a hull must be watertight for buoyancy. Close the holes (e.g. Blender: Select > All by Trait >"
                  " Non Manifold, then F to fill) and export again.");
  if (open.size() > 1) body.notes += "open on their own, closed when welded together: one body; ";
  if (flipped > 0) body.notes += std::to_string(flipped) + " triangles re-oriented consistently; ";
  if (top.non_manifold_edges > 0) body.notes += std::to_string(top.non_manifold_edges) + " non-manifold edges; ";
  return body;
}

// Where meshes meet (the KCS rudder on its hull): edges shared by more than two triangles of the whole file that
// no body has on its own are reported (accepted: each body is closed on its own).
void report_touching_meshes(const std::vector<Instance>& instances, const std::vector<Body>& bodies,
                            std::ostream& report) {
  std::vector<const Instance*> every;
  for (const Instance& in : instances) every.push_back(&in);
  const Instance all = joined(every);
  int within = 0;
  for (const Body& body : bodies) within += topology(body.mesh).non_manifold_edges;
  const int total = topology(weld(all.v, all.t)).non_manifold_edges;
  if (instances.size() > 1 && total > within)
    report << "meshes touch each other along " << total - within
           << " non-manifold edges (accepted: each body above is closed on its own)\n";
}

// A body that is not convex (by more than tol) is cut into convex sections along x (non_convex "slice", else an
// error), whose volume must stay within max_volume_error of the body's; the parts are appended to the model and
// described on `line`.
void slice_into_parts(Body& body, double volume, double tol, const HullLoadOptions& o, const std::string& where,
                      HullModel& model, std::ostream& line) {
  FLOESIM_REQUIRE(o.non_convex == "slice", where, ": mesh '", body.name,
                  "' is not convex (a vertex lies more than ", fmt_num(tol),
                  " m outside the plane of a face); set \"non_convex\": \"slice\" to cut it into convex sections"
                  " along x, or split it into convex meshes (one per object) yourself");
  Sliced sliced;
  try {
    sliced = slice_convex(body.mesh, o.slices, kSectionExcessTarget, kMergeExcess);
  } catch (const Error& e) {
    throw Error(where + ": mesh '" + body.name + "': slicing into convex parts failed: " + e.what());
  }
  std::vector<TriMesh>& pieces = sliced.parts;
  double v = 0;
  for (const TriMesh& p : pieces) v += mass_properties(p).volume;
  const double err = (v - volume) / volume;
  FLOESIM_REQUIRE(std::abs(err) <= o.max_volume_error, where, ": mesh '", body.name, "' is not convex and its ",
                  pieces.size(), " convex parts change its volume by ", percent(err), " (", fmt_num(volume),
                  " -> ", fmt_num(v), " m^3), more than max_volume_error = ", o.max_volume_error,
                  "; raise \"slices\" or split the mesh into convex meshes (one per object) yourself");
  line << "not convex: cut into " << o.slices << " sections along x";
  if (sliced.layered_sections > 0)
    line << " (" << sliced.layered_sections << " of them also into up to " << sliced.max_layers
         << " horizontal layers)";
  if (sliced.merges > 0) line << ", " << sliced.merges << " neighbouring sections merged";
  line << ", " << pieces.size() << " convex part" << (pieces.size() == 1 ? "" : "s") << ", volume " << fmt_num(v) << " m^3 (" << percent(err) << ")";
  model.parts_volume_m3 += v;
  for (TriMesh& p : pieces) model.parts.push_back(std::move(p));
}

// A closed body into the model: its volume (a body whose triangles face inwards is flipped; one enclosing no
// volume is an error), the merged mesh, and its convex parts (a convex body is one part); one report line.
void add_body(Body& body, const HullLoadOptions& o, double file_max_abs, double scale, const std::string& where,
              HullModel& model, std::ostream& report) {
  const Bounds bb(body.mesh.vertices);
  const double size = bb.diagonal();
  MassProperties mp = mass_properties(body.mesh);
  FLOESIM_REQUIRE(body.mesh.vertices.size() >= 4 && size > 0 && std::abs(mp.volume) > 1e-9 * size * size * size,
                  where, ": mesh '", body.name, "' is degenerate (it encloses no volume)");
  if (mp.volume < 0) {
    flip(body.mesh);
    mp.volume = -mp.volume;
    body.notes += "triangles faced inwards: flipped; ";
  }
  model.mesh_volume_m3 += mp.volume;
  model.mesh = merge({model.mesh, body.mesh});
  std::ostringstream line;
  line << "mesh '" << body.name << "': closed, " << body.mesh.triangles.size() << " triangles, volume "
       << fmt_num(mp.volume) << " m^3; " << body.notes;
  // Tolerance relative to the mesh: assimp stores single-precision coordinates (relative error ~6e-8).
  const double max_abs = std::max(bb.lo.cwiseAbs().maxCoeff(), bb.hi.cwiseAbs().maxCoeff());
  const double tol = 1e-6 * std::max({size, max_abs, file_max_abs * scale});
  if (is_convex(body.mesh, tol)) {
    line << "convex: kept as 1 part";
    model.parts.push_back(std::move(body.mesh));
    model.parts_volume_m3 += mp.volume;
  } else {
    slice_into_parts(body, mp.volume, tol, o, where, model, line);
  }
  report << line.str() << "\n";
}

}  // namespace

HullModel load_hull(const fs::path& file, const HullLoadOptions& o, const HullPlacement& placement) {
  const std::string where = file.string();
  check_load_inputs(file, o, placement);

  // Every mesh instance in the node tree, in world coordinates, then placed in the hull frame.
  std::vector<Instance> instances = read_instances(where);
  const double file_max_abs = place_instances(instances, placement);

  // Closed meshes are bodies of their own; the open ones together must close into one more.
  std::ostringstream report;
  report << "placement: " << describe_placement(placement) << "\n";
  std::vector<Body> bodies;
  const std::vector<const Instance*> open = closed_bodies(instances, where, bodies);
  if (!open.empty()) bodies.push_back(welded_open_meshes(open, where));
  report_touching_meshes(instances, bodies, report);

  // Each body's volume and convex parts, then the totals.
  HullModel model;
  for (Body& body : bodies) add_body(body, o, file_max_abs, placement.scale, where, model, report);
  model.surface = merge(model.parts);
  model.placement = placement;
  report << "total: " << model.parts.size() << " convex part" << (model.parts.size() == 1 ? "" : "s")
         << ", mesh volume " << fmt_num(model.mesh_volume_m3)
         << " m^3, parts volume " << fmt_num(model.parts_volume_m3) << " m^3 ("
         << percent((model.parts_volume_m3 - model.mesh_volume_m3) / model.mesh_volume_m3) << ")\n";
  model.report = report.str();
  return model;
}


// ---- placement of a mesh from CAD --------------------------------------------------------------------------------

namespace {

// A file axis named "+x" .. "-z": its index (0..2) and sign; Error naming `key` otherwise.
struct Axis {
  int index;
  double sign;
};
Axis file_axis(const std::string& d, const char* key, const char* allowed) {
  if (d.size() == 2 && (d[0] == '+' || d[0] == '-') && d[1] >= 'x' && d[1] <= 'z')
    return {d[1] - 'x', d[0] == '+' ? 1.0 : -1.0};
  throw Error(std::string(key) + " must be one of " + allowed + ", got \"" + d + "\"");
}

// The rotation of the placement as a signed permutation (hull axis k is file axis index[k] times sign[k]) and the
// file point that becomes the hull origin.
struct Frame {
  int index[3];
  double sign[3];
  Vec3 origin;
};
Frame placement_frame(const HullPlacement& p) {
  const Axis up = file_axis(p.up_direction, "up_direction", "+z, -z, +y, -y, +x, -x");
  const Axis bow = file_axis(p.bow_direction, "bow_direction", "+x, -x, +y, -y, +z, -z");
  FLOESIM_REQUIRE(up.index != bow.index, "bow_direction must be horizontal, across up_direction = \"",
                  p.up_direction, "\", got \"", p.bow_direction,
                  "\": set up_direction to the file's vertical axis (\"+y\" for a y-up export) and bow_direction to "
                  "the axis the bow points along");
  // Port = up x bow (z x x = y): the hull frame is right-handed whatever the two axes, so the map is a rotation.
  Vec3 u = Vec3::Zero(), b = Vec3::Zero();
  u[up.index] = up.sign;
  b[bow.index] = bow.sign;
  const Vec3 port = u.cross(b);
  Frame f;
  f.index[0] = bow.index, f.sign[0] = bow.sign;
  f.index[2] = up.index, f.sign[2] = up.sign;
  f.index[1] = 3 - up.index - bow.index, f.sign[1] = port[f.index[1]];
  // origin_m on the horizontal axes in axis order, the waterline's height along up.
  int h = 0;
  for (int k = 0; k < 3; ++k) {
    if (k == up.index) f.origin[k] = up.sign * p.waterline_z_m;
    else f.origin[k] = p.origin_m.size() == 2 ? p.origin_m[h++] : 0.0;
  }
  return f;
}

std::string axis_name(int index, double sign) { return std::string(sign > 0 ? "+" : "-") + char('x' + index); }

// The turn about z of a z-up placement (the hull's x from the bow), degrees.
double bow_turn_deg(const std::string& bow) {
  return bow == "-x" ? 180.0 : bow == "+y" ? -90.0 : bow == "-y" ? 90.0 : 0.0;
}

}  // namespace

Vec3 place_point(const HullPlacement& p, const Vec3& q) {
  // A permutation with signs (no products with zero): exact in floating point, and a proper rotation (port stays
  // port, normals outward).
  const Frame f = placement_frame(p);
  const Vec3 d = q - f.origin;
  return p.scale * Vec3(f.sign[0] * d[f.index[0]], f.sign[1] * d[f.index[1]], f.sign[2] * d[f.index[2]]);
}

std::string describe_placement(const HullPlacement& p) {
  const Frame f = placement_frame(p);
  std::ostringstream s;
  s << "scale " << fmt_num(p.scale) << "; ";
  if (p.up_direction == "+z") {
    s << "bow towards " << p.bow_direction;
    if (p.bow_direction == "+x") s << " (no turn)";
    else s << ", turned " << fmt_num(bow_turn_deg(p.bow_direction)) << " deg about z to +x";
    s << "; calm waterline at file z = " << fmt_num(p.waterline_z_m) << " -> z = 0";
    s << "; file (x, y) = (" << fmt_num(f.origin.x()) << ", " << fmt_num(f.origin.y()) << ") -> origin";
  } else {
    // Which file axis each hull axis is, and the file point that becomes the origin.
    s << "up towards " << p.up_direction << ", bow towards " << p.bow_direction << ": hull x = file "
      << axis_name(f.index[0], f.sign[0]) << ", y = file " << axis_name(f.index[1], f.sign[1]) << ", z = file "
      << axis_name(f.index[2], f.sign[2]) << "; calm waterline at file " << p.up_direction.substr(1) << " = "
      << fmt_num(f.origin[p.up_direction[1] - 'x']) << " -> z = 0; file (x, y, z) = (" << fmt_num(f.origin.x())
      << ", " << fmt_num(f.origin.y()) << ", " << fmt_num(f.origin.z()) << ") -> origin";
  }
  return s.str();
}

void require_floating(const HullModel& hull, const std::string& where) {
  FLOESIM_REQUIRE(!hull.surface.vertices.empty(), where, ": the hull has no parts");
  const Bounds b(hull.surface.vertices);
  const HullPlacement& p = hull.placement;
  // The hull's z range in the file's own frame and units, for the message.
  const double f_lo = b.lo.z() / p.scale + p.waterline_z_m, f_hi = b.hi.z() / p.scale + p.waterline_z_m;
  const std::string height = p.up_direction == "+z" ? std::string("file z") : "height along " + p.up_direction;
  const std::string fix = "; set waterline_z_m to the height of the calm waterline in the mesh's own frame, "
                          "between its keel and deck (" + height + " from " + fmt_num(f_lo) + " to " + fmt_num(f_hi) +
                          "; e.g. keel + draught for a mesh with its keel at height 0), and up_direction to the "
                          "file's vertical axis if the mesh lies on its side or upside down (\"+y\" for a y-up "
                          "export)";
  FLOESIM_REQUIRE(b.lo.z() < 0, where, ": waterline_z_m = ", fmt_num(p.waterline_z_m),
                  " puts the whole hull above the water (its lowest point is ", fmt_num(b.lo.z()),
                  " m above the waterline): it would displace nothing", fix);
  FLOESIM_REQUIRE(b.hi.z() > 0, where, ": waterline_z_m = ", fmt_num(p.waterline_z_m),
                  " puts the whole hull under water (its highest point is ", fmt_num(-b.hi.z()),
                  " m below the waterline): a ship must pierce the surface", fix);
  // A waterline at the keel (a few micrometres of keel below it) or at the deck is a placement error too: a ship
  // displaces a good part of its volume (half or so), not nothing and not all of it.
  const double v = submerged_part(hull.surface.vertices, hull.surface.triangles, 0.0).volume;
  const double f = v / hull.parts_volume_m3;
  FLOESIM_REQUIRE(f >= 0.01, where, ": waterline_z_m = ", fmt_num(p.waterline_z_m),
                  " leaves the hull a displacement of (almost) zero (", fmt_num(v), " m^3 below the waterline, ",
                  percent(f), " of its volume)", fix);
  FLOESIM_REQUIRE(f <= 0.99, where, ": waterline_z_m = ", fmt_num(p.waterline_z_m), " puts (almost) the whole hull "
                  "under water (", percent(f), " of its volume below the waterline)", fix);
}

namespace {

// Mass in the unit that reads best: kg for a model, t for a ship.
std::string mass_text(double kg) { return kg < 1e4 ? fmt_num(kg, 4) + " kg" : fmt_num(kg / 1000.0, 5) + " t"; }

}  // namespace

std::string write_imported_hull(const HullImportOptions& o, const fs::path& out_obj, const fs::path& config_file) {
  const std::string where = config_file.empty() ? std::string("hull options") : config_file.string();
  // The options' own checks, also when the struct was filled in code rather than read from JSON.
  check_options(o, where);
  fs::path mesh_file = o.file;
  if (mesh_file.is_relative() && !config_file.empty()) mesh_file = config_file.parent_path() / mesh_file;
  FLOESIM_REQUIRE(fs::exists(mesh_file), where, ": file names ", mesh_file.string(), ", which does not exist");

  // 1. Load, place, decompose; refuse a hull that does not float.
  HullModel m = load_hull(mesh_file, o.load, o.placement);
  require_floating(m, where);
  // The parts go to an OBJ that the simulator reads with assimp in single precision. Rounded to float, a part's
  // sliver faces would tilt and the part would no longer pass as convex. So, as for the generated hull, each part
  // is snapped to a binary grid that floats hold exactly (the float spacing at the hull's largest coordinate) and
  // is rebuilt as the convex hull of its snapped vertices: what is written is read back bit for bit, and convex.
  {
    const Bounds all(m.surface.vertices);
    const double max_abs = std::max(all.lo.cwiseAbs().maxCoeff(), all.hi.cwiseAbs().maxCoeff());
    const double g = std::ldexp(1.0, static_cast<int>(std::ceil(std::log2(max_abs))) - 23);
    double v = 0;
    for (TriMesh& part : m.parts) {
      for (Vec3& p : part.vertices) p = (p / g).array().round().matrix() * g;
      part = convex_hull(part.vertices);
      v += mass_properties(part).volume;
    }
    m.parts_volume_m3 = v;
    m.surface = merge(m.parts);
  }

  // 2. What it displaces, by the convex parts (what the simulator floats) and by the mesh itself (the reference).
  const double rho = o.water_density_kg_m3;
  const Hydrostatics h = hydrostatics(m.parts, rho, 0.0);
  const double v_mesh = submerged_part(m.mesh.vertices, m.mesh.triangles, 0.0).volume;
  const double volume_error = (m.parts_volume_m3 - m.mesh_volume_m3) / m.mesh_volume_m3;
  const double displacement_error = (h.volume_m3 - v_mesh) / v_mesh;
  const Bounds b(m.surface.vertices);
  // The draught at mid-waterline-length (the keel line there: a sonar dome or skeg does not count) and the deepest.
  double x_wl_lo = std::numeric_limits<double>::infinity(), x_wl_hi = -x_wl_lo;
  for (const auto& t : m.surface.triangles)
    for (int k = 0; k < 3; ++k) {
      const Vec3 &a = m.surface.vertices[t[k]], &c = m.surface.vertices[t[(k + 1) % 3]];
      if (a.z() * c.z() > 0 || a.z() == c.z()) continue;
      const double x = a.x() + (c.x() - a.x()) * (-a.z() / (c.z() - a.z()));
      x_wl_lo = std::min(x_wl_lo, x), x_wl_hi = std::max(x_wl_hi, x);
    }
  const double x_mid = 0.5 * (x_wl_lo + x_wl_hi);
  const double draught_mid = -lowest_z_at(m.surface, x_mid);
  size_t nv = 0, nt = 0;
  for (const TriMesh& p : m.parts) nv += p.vertices.size(), nt += p.triangles.size();

  std::ostringstream head;
  head << "floesim hull from " << mesh_file.filename().string() << ", " << m.parts.size() << " convex parts\n"
       << "written by floesim-hull " << version() << "; frame: x forward, y to port, z up, metres; calm waterline"
       << " z = 0\n"
       << "placement: " << describe_placement(o.placement) << "\n"
       << "volume below z = 0: " << fmt_num(h.volume_m3) << " m^3 (mesh " << fmt_num(v_mesh) << " m^3, "
       << percent(displacement_error) << "); displacement " << mass_text(rho * h.volume_m3) << " at rho_w = " << rho
       << " kg/m^3\n";

  nlohmann::json side;
  std::vector<NamedInput> inputs;
  inputs.push_back({"mesh", mesh_file});
  if (!config_file.empty()) inputs.push_back({"config", config_file});
  side["provenance"] = make_provenance("floesim-hull", inputs, options_to_json(o));
  side["hull_file"] = out_obj.filename().string();
  side["source_file"] = mesh_file.string();
  side["frame"] = "x forward, y to port, z up; calm waterline z = 0; origin at the placement's origin_m; metres";
  {
    const Frame f = placement_frame(o.placement);
    side["placement"] = {{"scale", o.placement.scale},
                         {"up_direction", o.placement.up_direction},
                         {"bow_direction", o.placement.bow_direction},
                         {"hull_axes_in_file", {axis_name(f.index[0], f.sign[0]), axis_name(f.index[1], f.sign[1]),
                                                axis_name(f.index[2], f.sign[2])}},
                         {"waterline_z_m", o.placement.waterline_z_m},
                         {"origin_m", o.placement.origin_m},
                         {"origin_in_file_m", {f.origin.x(), f.origin.y(), f.origin.z()}},
                         {"description", describe_placement(o.placement)}};
    // The turn about z alone describes a z-up file's placement.
    if (o.placement.up_direction == "+z") side["placement"]["turn_about_z_deg"] = bow_turn_deg(o.placement.bow_direction);
  }
  side["parts"] = m.parts.size();
  side["vertices"] = nv;
  side["triangles"] = nt;
  side["extent_m"] = {{"x", {b.lo.x(), b.hi.x()}}, {"y", {b.lo.y(), b.hi.y()}}, {"z", {b.lo.z(), b.hi.z()}}};
  side["mesh_volume_m3"] = m.mesh_volume_m3;
  side["parts_volume_m3"] = m.parts_volume_m3;
  side["volume_error"] = volume_error;
  side["mesh_displaced_volume_m3"] = v_mesh;
  side["displaced_volume_error"] = displacement_error;
  side["displacement_kg"] = rho * h.volume_m3;
  side["waterline"] = {{"z_in_file", o.placement.waterline_z_m},
                       {"length_wl_m", h.length_wl_m},
                       {"beam_wl_m", h.beam_wl_m},
                       {"x_wl_m", {x_wl_lo, x_wl_hi}},
                       {"draught_mid_wl_m", draught_mid},
                       {"draught_max_m", h.draught_m}};
  side["hydrostatics"] = hydrostatics_json(h, rho);
  // The particulars of the mesh as read and placed (the reference), not of its convex parts.
  std::ostringstream particulars_text;
  add_particulars(m.mesh, mesh_file.string(), side, particulars_text);
  {  // what the loader did, one line per entry (placement, meshes, total)
    nlohmann::json lines = nlohmann::json::array();
    std::istringstream rep(m.report);
    for (std::string line; std::getline(rep, line);) lines.push_back(line);
    side["loader_report"] = lines;
  }

  fs::path sidecar = out_obj;
  sidecar.replace_extension(".json");
  FLOESIM_REQUIRE(sidecar != out_obj, out_obj.string(), ": the hull file must not end in .json (the sidecar does)");
  ensure_directory(out_obj.parent_path());
  write_obj(out_obj, m.parts, head.str());
  write_text_atomic(sidecar, side.dump(2) + "\n");

  std::ostringstream sum;
  sum << "hull: " << mesh_file.filename().string() << " -> " << m.parts.size() << " convex parts, " << nv
      << " vertices, " << nt << " triangles -> " << out_obj.string() << " (+ " << sidecar.filename().string() << ")\n"
      << "  placement            " << describe_placement(o.placement) << "\n"
      << "  extent x " << fmt_num(b.lo.x()) << " .. " << fmt_num(b.hi.x()) << " m, y " << fmt_num(b.lo.y()) << " .. "
      << fmt_num(b.hi.y()) << " m, z " << fmt_num(b.lo.z()) << " .. " << fmt_num(b.hi.z()) << " m\n"
      << "  volume               mesh " << fmt_num(m.mesh_volume_m3) << " m^3, convex parts "
      << fmt_num(m.parts_volume_m3) << " m^3 (" << percent(volume_error) << ")\n"
      << "  volume below z = 0   mesh " << fmt_num(v_mesh) << " m^3, convex parts " << fmt_num(h.volume_m3)
      << " m^3 (" << percent(displacement_error) << ")\n"
      << "  displacement         " << mass_text(rho * h.volume_m3) << " (rho_w " << rho << " kg/m^3)\n"
      << "  waterline            "
      << (o.placement.up_direction == "+z" ? std::string("file z") : "height along file " + o.placement.up_direction)
      << " = " << fmt_num(o.placement.waterline_z_m) << "; L x B "
      << fmt_num(h.length_wl_m) << " x " << fmt_num(h.beam_wl_m) << " m, x " << fmt_num(x_wl_lo) << " .. "
      << fmt_num(x_wl_hi) << " m\n"
      << "  draught              " << fmt_num(draught_mid) << " m at mid waterline length, " << fmt_num(h.draught_m)
      << " m at the deepest point\n"
      << "  waterplane area      " << fmt_num(h.waterplane_area_m2) << " m^2, LCB " << fmt_num(h.lcb_m) << " m, KB "
      << fmt_num(h.kb_m) << " m, wetted surface " << fmt_num(h.wetted_surface_m2) << " m^2\n"
      << particulars_text.str() << "loader:\n";
  std::istringstream rep(m.report);
  for (std::string line; std::getline(rep, line);) sum << "  " << line << "\n";
  return sum.str();
}

}  // namespace floesim::sim
