// Hulls as they come from CAD (issue #13 item 4): the placement options (scale, bow_direction, waterline_z_m,
// origin_m) bring a mesh into the hull frame (bow +x, calm waterline z = 0); the hull stage reports what it did and
// refuses a hull that does not float. On the two real hulls of ../shared/data/hulls, which lie with their bow towards
// -x and their calm waterline at z = 0 (keel at z = -T), placed as they are, placed from a copy with the keel at
// z = 0, and (DTMB 5415) from a full-scale copy scaled back down.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "pipeline/error.h"
#include "pipeline/options.h"
#include "sim/vessel/hull.h"
#include "tests/sim/obj_faces.h"
#include "tests/sim/sim_fixtures.h"

#ifndef FLOESIM_SHARED_DATA_DIR
#error "FLOESIM_SHARED_DATA_DIR must be defined by the build"
#endif

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;
using testing::read_obj_faces;

using testing::hull_file;
using testing::temp_dir;

// A copy of an OBJ (in a temporary folder, never in the repository) with every vertex v -> scale * (v + shift):
// the same hull as a CAD file might hold it (keel at z = 0, full scale).
fs::path transformed_copy(const fs::path& src, const fs::path& dst, double scale, const Vec3& shift) {
  std::ifstream in(src);
  std::ofstream out(dst);
  char buf[128];
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("v ", 0) == 0) {
      std::istringstream s(line.substr(2));
      Vec3 v;
      s >> v.x() >> v.y() >> v.z();
      v = scale * (v + shift);
      std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g", v.x(), v.y(), v.z());
      out << buf << "\n";
    } else {
      out << line << "\n";
    }
  }
  return dst;
}

// Volume of a closed, outward-oriented triangle mesh below z = 0 by the divergence theorem, written here apart from
// the library's clipping: each triangle is clipped to z <= 0 and its fan contributes the signed volume of the
// tetrahedra it spans with the origin. The origin lies in the plane z = 0, so the missing cap (the waterplane)
// would contribute nothing and need not be built.
double volume_below_waterline(const TriMesh& m) {
  double six_v = 0;
  for (const auto& t : m.triangles) {
    std::vector<Vec3> poly;
    for (int k = 0; k < 3; ++k) {
      const Vec3 &p = m.vertices[t[k]], &q = m.vertices[t[(k + 1) % 3]];
      if (p.z() <= 0) poly.push_back(p);
      if ((p.z() < 0) != (q.z() < 0) && p.z() != q.z()) poly.push_back(p + (q - p) * (-p.z() / (q.z() - p.z())));
    }
    for (size_t k = 1; k + 1 < poly.size(); ++k) six_v += poly[0].dot(poly[k].cross(poly[k + 1]));
  }
  return six_v / 6.0;
}

TEST(HullPlacement, TurnsTheBowToPlusXKeepingPortToPort) {
  // Bow and port in the file for each bow_direction; placed, the bow must be +x and port +y (a proper rotation).
  struct Case {
    const char* bow;
    Vec3 bow_dir, port_dir;
  };
  for (const Case& c : {Case{"+x", {1, 0, 0}, {0, 1, 0}}, Case{"-x", {-1, 0, 0}, {0, -1, 0}},
                        Case{"+y", {0, 1, 0}, {-1, 0, 0}}, Case{"-y", {0, -1, 0}, {1, 0, 0}}}) {
    HullPlacement p;
    p.bow_direction = c.bow;
    p.scale = 2.0;
    p.waterline_z_m = 0.5;
    p.origin_m = {10.0, -3.0};
    const Vec3 o(10.0, -3.0, 0.5);  // the file's origin on the waterline -> hull origin
    EXPECT_NEAR(place_point(p, o).norm(), 0, 1e-12) << c.bow;
    EXPECT_NEAR((place_point(p, o + c.bow_dir) - Vec3(2, 0, 0)).norm(), 0, 1e-12) << c.bow;
    EXPECT_NEAR((place_point(p, o + c.port_dir) - Vec3(0, 2, 0)).norm(), 0, 1e-12) << c.bow;
    EXPECT_NEAR((place_point(p, o + Vec3(0, 0, 1)) - Vec3(0, 0, 2)).norm(), 0, 1e-12) << c.bow;
  }
}

// The error reading the case's hull section gives, or "no error".
std::string problem(const char* text) {
  try {
    read_options<HullImportOptions>(Json::parse(text), "case.json", "hull");
  } catch (const Error& e) {
    return std::string(e.what());
  }
  return std::string("no error");
}

TEST(HullPlacement, OptionsAreCheckedNamingTheKey) {
  EXPECT_NE(problem(R"({"file": "h.obj", "bow_direction": "x+"})").find("hull.bow_direction"), std::string::npos);
  EXPECT_NE(problem(R"({"file": "h.obj", "scale": 0})").find("hull.scale must be > 0"), std::string::npos);
  EXPECT_NE(problem(R"({"file": "h.obj", "origin_m": [1]})").find("hull.origin_m"), std::string::npos);
  EXPECT_NE(problem(R"({"file": "h.obj", "waterline": 0.3})").find("waterline"), std::string::npos);
  EXPECT_NE(problem(R"({"scale": 2})").find("hull.file"), std::string::npos);
  const HullImportOptions o =
      read_options<HullImportOptions>(Json::parse(R"({"file": "h.obj", "bow_direction": "-x", "waterline_z_m": 0.3,
        "scale": 0.5, "slices": 30})"), "case.json", "hull");
  EXPECT_EQ(o.placement.bow_direction, "-x");
  EXPECT_EQ(o.placement.waterline_z_m, 0.3);
  EXPECT_EQ(o.placement.scale, 0.5);
  EXPECT_EQ(o.load.slices, 30);
}

// A unit cube, keel at z = 0.
fs::path cube(const fs::path& dir) {
  const fs::path f = dir / "cube.obj";
  std::ofstream(f) << "o cube\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                      "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\n"
                      "f 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\n";
  return f;
}

TEST(HullPlacement, UpDirectionTurnsTheFilesVerticalToPlusZBeforeTheBowTurn) {
  // Per case, worked out by hand: the file's up, bow and port directions and the file point on the calm waterline
  // (height 0.5 along up) at origin_m = [10, -3] on the file's two horizontal axes in axis order. Placed, up must
  // be +z, the bow +x and port +y (right-handed: the map is a rotation, so normals stay outward).
  struct Case {
    const char *up, *bow;
    Vec3 up_dir, bow_dir, port_dir, origin;
  };
  for (const Case& c : {
           // y-up (Blender's OBJ export: file (x, y, z) = Blender (x, z, -y)); facing -x with +y up, port is +z.
           Case{"+y", "-x", {0, 1, 0}, {-1, 0, 0}, {0, 0, 1}, {10, 0.5, -3}},
           Case{"+y", "+z", {0, 1, 0}, {0, 0, 1}, {1, 0, 0}, {10, 0.5, -3}},
           Case{"-y", "+x", {0, -1, 0}, {1, 0, 0}, {0, 0, 1}, {10, -0.5, -3}},
           Case{"+x", "+y", {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5, 10, -3}},
           // x down: facing -z with -x up, port is -y.
           Case{"-x", "-z", {-1, 0, 0}, {0, 0, -1}, {0, -1, 0}, {-0.5, 10, -3}},
           // Upside down: z down, bow +x, port -y.
           Case{"-z", "+x", {0, 0, -1}, {1, 0, 0}, {0, -1, 0}, {10, -3, -0.5}},
           // The default: z up, the turn about z alone (the cases of the test above).
           Case{"+z", "-y", {0, 0, 1}, {0, -1, 0}, {1, 0, 0}, {10, -3, 0.5}}}) {
    HullPlacement p;
    p.up_direction = c.up;
    p.bow_direction = c.bow;
    p.scale = 2.0;
    p.waterline_z_m = 0.5;
    p.origin_m = {10.0, -3.0};
    const std::string label = std::string("up ") + c.up + ", bow " + c.bow;
    EXPECT_EQ(place_point(p, c.origin), Vec3::Zero()) << label;
    EXPECT_EQ(place_point(p, c.origin + c.bow_dir), Vec3(2, 0, 0)) << label;
    EXPECT_EQ(place_point(p, c.origin + c.port_dir), Vec3(0, 2, 0)) << label;
    EXPECT_EQ(place_point(p, c.origin + c.up_dir), Vec3(0, 0, 2)) << label;
    // The loader's report says what it did: the turn about z alone for a z-up file, the axes otherwise.
    const std::string said = describe_placement(p);
    EXPECT_NE(said.find(std::string(c.up) == "+z" ? std::string("turned 90 deg about z") : std::string("up towards ") + c.up),
              std::string::npos) << said;
  }
}

TEST(HullPlacement, BowAlongTheUpAxisIsRefusedNamingBothKeysAndTheFix) {
  for (const char* text : {R"({"file": "h.obj", "up_direction": "+y", "bow_direction": "-y"})",
                           R"({"file": "h.obj", "bow_direction": "+z"})",
                           R"({"file": "h.obj", "up_direction": "-x", "bow_direction": "+x"})"}) {
    const std::string msg = problem(text);
    EXPECT_NE(msg.find("case.json"), std::string::npos) << msg;
    EXPECT_NE(msg.find("hull.bow_direction must be horizontal"), std::string::npos) << msg;
    EXPECT_NE(msg.find("up_direction"), std::string::npos) << msg;
    EXPECT_NE(msg.find("\"+y\" for a y-up export"), std::string::npos) << msg;  // the fix
  }
  EXPECT_NE(problem(R"({"file": "h.obj", "up_direction": "y"})").find("hull.up_direction"), std::string::npos);
  // Placed in code, not read from JSON: the loader refuses the same, naming the file.
  const fs::path dir = temp_dir("bow_up");
  HullPlacement p;
  p.up_direction = "+y";
  p.bow_direction = "+y";
  testing::expect_error([&] { load_hull(cube(dir), {}, p); },
                        {"cube.obj", "bow_direction must be horizontal", "up_direction"});
  fs::remove_all(dir);
}

void expect_refused(const fs::path& dir, const HullImportOptions& o, const std::string& what) {
  const fs::path cfg = dir / "hull_options.json";
  std::ofstream(cfg) << "{}\n";
  try {
    write_imported_hull(o, dir / "out" / "hull.obj", cfg);
    ADD_FAILURE() << "not refused: " << what;
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("hull_options.json"), std::string::npos) << msg;  // the file of the settings
    EXPECT_NE(msg.find("waterline_z_m"), std::string::npos) << msg;      // the key to fix
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
  }
  EXPECT_FALSE(fs::exists(dir / "out" / "hull.obj"));  // nothing written
  EXPECT_FALSE(fs::exists(dir / "out" / "hull.json"));
}

TEST(HullPlacement, HullThatDoesNotFloatIsRefusedNamingTheKey) {
  const fs::path dir = temp_dir("refuse");
  HullImportOptions o;
  o.file = cube(dir).string();
  o.placement.waterline_z_m = -0.5;  // below the keel
  expect_refused(dir, o, "above the water");
  o.placement.waterline_z_m = 1.0;   // level with the deck: nothing pierces the surface
  expect_refused(dir, o, "under water");
  o.placement.waterline_z_m = 0.001;  // a waterline at the keel: 0.1 % of the volume displaced
  expect_refused(dir, o, "displacement of (almost) zero");
  o.placement.waterline_z_m = 0.5;   // floats: written, and the sidecar says what was done
  const std::string summary = write_imported_hull(o, dir / "out" / "hull.obj", "");
  EXPECT_NE(summary.find("displacement"), std::string::npos) << summary;
  const nlohmann::json side = nlohmann::json::parse(std::ifstream(dir / "out" / "hull.json"));
  EXPECT_EQ(side["parts"].get<int>(), 1);
  EXPECT_NEAR(side["displacement_kg"].get<double>(), 0.5 * 1025.0, 1e-9);
  EXPECT_NEAR(side["waterline"]["draught_mid_wl_m"].get<double>(), 0.5, 1e-12);
  EXPECT_EQ(side["placement"]["waterline_z_m"].get<double>(), 0.5);
  fs::remove_all(dir);
}

// ---- the real hulls ----------------------------------------------------------------------------------------------

struct RealHull {
  const char* file;
  double lpp_m;               // length between perpendiculars, model scale (published)
  double draught_m;           // design draught T at the keel line (published)
  double volume_m3;           // displacement volume at T (published)
};

// KCS model, scale 1:31.6 (SIMMAN 2008 / Tokyo 2015): Lpp 7.2786 m, T 0.3418 m, volume 1.6490 m^3.
const RealHull kKcs{"KCS_model_scale_L7.2786m.obj", 7.2786, 0.3418, 1.6490};
// DTMB 5415 model (INSEAN 2340), scale 1:24.824: Lpp 5.72 m, T 0.248 m (6.15 m full scale), volume 0.549 m^3.
const RealHull kDtmb{"DTMB5415_model_scale_L5.72m.obj", 5.72, 0.248, 0.549};

struct Placed {
  nlohmann::json side;
  HullModel reloaded;  // hull.obj as the simulator reads it
};

Placed place(const fs::path& mesh, const HullPlacement& p, const fs::path& out_dir) {
  HullImportOptions o;
  o.file = mesh.string();
  o.placement = p;
  o.water_density_kg_m3 = 1000.0;  // towing tank
  const std::string summary = write_imported_hull(o, out_dir / "hull.obj", "");
  std::cout << summary;
  Placed r;
  r.side = nlohmann::json::parse(std::ifstream(out_dir / "hull.json"));
  r.reloaded = load_hull(out_dir / "hull.obj", HullLoadOptions{"refuse", 24, 0.05});  // convex parts only
  return r;
}

// Half-breadth of the waterline (z = 0) of a mesh near x, from edges crossing z = 0 within +-dx of x.
double half_breadth_near(const TriMesh& m, double x, double dx) {
  double y = 0;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const Vec3 &a = m.vertices[t[k]], &b = m.vertices[t[(k + 1) % 3]];
      if (a.z() * b.z() > 0 || a.z() == b.z()) continue;
      const Vec3 c = a + (b - a) * (-a.z() / (b.z() - a.z()));
      if (std::abs(c.x() - x) <= dx) y = std::max(y, std::abs(c.y()));
    }
  return y;
}

void check_placed(const RealHull& r, const Placed& placed, const std::string& label) {
  const nlohmann::json& s = placed.side;
  const TriMesh& hull = placed.reloaded.surface;
  const double lwl = s["waterline"]["length_wl_m"].get<double>();
  const double x_lo = s["waterline"]["x_wl_m"][0].get<double>(), x_hi = s["waterline"]["x_wl_m"][1].get<double>();
  const double t_mid = s["waterline"]["draught_mid_wl_m"].get<double>();
  const double v_parts = s["hydrostatics"]["volume_m3"].get<double>();
  const double v_mesh = s["mesh_displaced_volume_m3"].get<double>();
  std::printf("[measured] %s %s: L_wl %.4f m (Lpp %.4f), x_wl %.4f .. %.4f m, T %.5f m (published %.4f, %+.3f %%), "
              "displaced volume mesh %.5f m^3, parts %.5f m^3 (%+.3f %%), published %.4f m^3 (mesh %+.3f %%)\n",
              r.file, label.c_str(), lwl, r.lpp_m, x_lo, x_hi, t_mid, r.draught_m,
              100 * (t_mid - r.draught_m) / r.draught_m, v_mesh, v_parts, 100 * (v_parts - v_mesh) / v_mesh,
              r.volume_m3, 100 * (v_mesh - r.volume_m3) / r.volume_m3);

  // Longitudinal extent: the waterline is the ship's length (L_wl a little over Lpp: the stern overhang), centred
  // near the origin (both files have theirs near midship).
  EXPECT_GT(lwl, 0.99 * r.lpp_m) << label;
  EXPECT_LT(lwl, 1.03 * r.lpp_m) << label;
  EXPECT_LT(std::abs(x_lo + x_hi), 0.05 * r.lpp_m) << label;
  // Bow at +x: the entrance is fine, the stern is broad (transom): the waterline 3 % of L from the forward end is
  // much narrower than 3 % of L from the aft end.
  const double aft = half_breadth_near(hull, x_lo + 0.03 * lwl, 0.01 * lwl);
  const double fwd = half_breadth_near(hull, x_hi - 0.03 * lwl, 0.01 * lwl);
  EXPECT_GT(aft, 2.0 * fwd) << label << ": half-breadths aft " << aft << " m, forward " << fwd << " m";
  // Draught at the keel line = T, within the decomposition (the hulls of slices are exact on a flat keel; 0.5 %).
  EXPECT_NEAR(t_mid, r.draught_m, 0.005 * r.draught_m) << label;
  // It floats at that draught: the volume the placed hull displaces below z = 0 is the published one. Mesh (by the
  // library's clip) within 1 %; the convex parts hold a little more (hulls of slices only add), under 2 %.
  EXPECT_NEAR(v_mesh, r.volume_m3, 0.01 * r.volume_m3) << label;
  EXPECT_GE(v_parts, v_mesh * (1 - 1e-9)) << label;
  EXPECT_LT(v_parts, v_mesh * 1.02) << label;
  EXPECT_NEAR(s["displacement_kg"].get<double>(), 1000.0 * v_parts, 1e-9 * v_parts) << label;
  // The hull as the simulator reads it back displaces what the sidecar says.
  EXPECT_NEAR(submerged_part(hull.vertices, hull.triangles, 0.0).volume, v_parts, 1e-6 * v_parts) << label;
}

void check_real_hull(const RealHull& r, bool full_scale_copy) {
  const fs::path dir = temp_dir(std::string(r.file).substr(0, 4));
  const fs::path f = hull_file(r.file);
  ASSERT_TRUE(fs::exists(f));

  // 1. The files as they lie: bow towards -x, calm waterline at z = 0 (keel at z = -T).
  {
    const TriMesh raw = read_obj_faces(f);
    double z_lo = 1e300, z_hi = -1e300;
    for (const Vec3& v : raw.vertices) z_lo = std::min(z_lo, v.z()), z_hi = std::max(z_hi, v.z());
    EXPECT_LT(z_lo, -0.99 * r.draught_m) << "the keel (or a dome below it) is at z = -T, not at z = 0";
    EXPECT_GT(z_hi, 0) << "the deck is above z = 0";
  }
  HullPlacement as_is;
  as_is.bow_direction = "-x";
  const Placed a = place(f, as_is, dir / "as_is");
  check_placed(r, a, "bow -x, waterline_z_m 0");

  // Independent check of the displaced volume: the raw file's faces, placed by hand (turned about z: z unchanged),
  // clipped at z = 0 by the divergence theorem above.
  const TriMesh raw = read_obj_faces(f);
  const double v_div = volume_below_waterline(raw);
  EXPECT_NEAR(v_div, a.side["mesh_displaced_volume_m3"].get<double>(), 1e-6 * v_div);
  EXPECT_NEAR(v_div, r.volume_m3, 0.01 * r.volume_m3);

  // 2. The same hull with its keel at z = 0 (as the issue pictured a CAD export): waterline_z_m = T places it the
  // same (to the single-precision rounding of the file).
  const fs::path keel0 = transformed_copy(f, dir / "keel_at_zero.obj", 1.0, Vec3(0, 0, r.draught_m));
  HullPlacement lifted = as_is;
  lifted.waterline_z_m = r.draught_m;
  const Placed b = place(keel0, lifted, dir / "keel0");
  check_placed(r, b, "keel at z = 0, waterline_z_m T");
  EXPECT_NEAR(b.side["hydrostatics"]["volume_m3"].get<double>(), a.side["hydrostatics"]["volume_m3"].get<double>(),
              1e-5 * r.volume_m3);
  // Forgetting waterline_z_m for that file puts the waterline at the keel: (almost) nothing displaced (KCS: some
  // micrometres of keel below z = 0; DTMB 5415: its sonar dome, under 1 % of the volume): refused, naming the key.
  HullImportOptions forgot;
  forgot.file = keel0.string();
  forgot.placement.bow_direction = "-x";
  expect_refused(dir, forgot, "");

  // 3. Full scale with its keel at z = 0, scaled down by the model's scale factor.
  if (full_scale_copy) {
    const double lambda = 24.824, t_full = 6.15;  // DTMB 5415: T = 6.15 m full scale
    const fs::path full = transformed_copy(f, dir / "full_scale.obj", lambda, Vec3(0, 0, t_full / lambda));
    HullPlacement down = as_is;
    down.scale = 1.0 / lambda;
    down.waterline_z_m = t_full;
    const Placed c = place(full, down, dir / "full");
    check_placed(r, c, "full scale, scale 1/24.824, waterline_z_m 6.15");
    EXPECT_NEAR(c.side["hydrostatics"]["volume_m3"].get<double>(),
                a.side["hydrostatics"]["volume_m3"].get<double>(), 1e-4 * r.volume_m3);
  }
  fs::remove_all(dir);
}

// A copy of an OBJ whose vertices are permuted and negated per axis (vertex k of the copy = sign[k] * v[axis[k]]),
// done on the text so that every coordinate keeps its digits: the same hull exported with other axes.
fs::path axes_copy(const fs::path& src, const fs::path& dst, const int axis[3], const int sign[3]) {
  std::ifstream in(src);
  std::ofstream out(dst);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("v ", 0) == 0) {
      std::istringstream s(line.substr(2));
      std::string c[3];
      s >> c[0] >> c[1] >> c[2];
      out << "v";
      for (int k = 0; k < 3; ++k) {
        std::string t = c[axis[k]];
        if (sign[k] < 0) t = t[0] == '-' ? t.substr(1) : t[0] == '+' ? "-" + t.substr(1) : "-" + t;
        out << " " << t;
      }
      out << "\n";
    } else {
      out << line << "\n";
    }
  }
  return dst;
}

// The same placed hull from two files: the meshes as read and placed, vertex for vertex (the files list them in
// the same order), and the hydrostatics of the convex parts the stage wrote.
void expect_same_placement(const HullModel& a, const Placed& pa, const HullModel& b, const Placed& pb, double size,
                           const std::string& label) {
  ASSERT_EQ(a.mesh.vertices.size(), b.mesh.vertices.size()) << label;
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles) << label;
  double worst = 0;
  for (size_t i = 0; i < a.mesh.vertices.size(); ++i)
    worst = std::max(worst, (a.mesh.vertices[i] - b.mesh.vertices[i]).norm());
  EXPECT_LE(worst, 1e-6 * size) << label;
  std::printf("[measured] %s: largest vertex difference %.3g m\n", label.c_str(), worst);
  const nlohmann::json &s = pa.side, &t = pb.side;
  EXPECT_EQ(t["parts"], s["parts"]) << label;
  for (const char* key : {"displacement_kg", "mesh_displaced_volume_m3", "mesh_volume_m3", "parts_volume_m3"})
    EXPECT_NEAR(t[key].get<double>(), s[key].get<double>(), 1e-6 * s[key].get<double>()) << label << ": " << key;
  for (const char* key : {"length_wl_m", "beam_wl_m", "draught_mid_wl_m", "draught_max_m"})
    EXPECT_NEAR(t["waterline"][key].get<double>(), s["waterline"][key].get<double>(), 1e-6 * size)
        << label << ": waterline." << key;
  for (int k = 0; k < 2; ++k)
    EXPECT_NEAR(t["waterline"]["x_wl_m"][k].get<double>(), s["waterline"]["x_wl_m"][k].get<double>(), 1e-6 * size)
        << label;
}

// The DTMB 5415 model as a y-up export would hold it, and as an x-up file with its bow along z: placed with
// up_direction (and the waterline and origin measured in those files), it is the hull placed from the z-up original.
TEST(HullPlacementRealHulls, Dtmb5415FromYUpAndXUpCopiesIsPlacedAsTheZUpOriginal) {
  const fs::path dir = temp_dir("dtmb_up");
  const fs::path f = hull_file(kDtmb.file);
  ASSERT_TRUE(fs::exists(f));
  HullPlacement as_is;
  as_is.bow_direction = "-x";
  const HullModel a = load_hull(f, {}, as_is);
  const Placed pa = place(f, as_is, dir / "as_is");
  auto check = [&](const fs::path& copy, const HullPlacement& p, const std::string& label) {
    const Placed pb = place(copy, p, dir / copy.stem());
    expect_same_placement(a, pa, load_hull(copy, {}, p), pb, kDtmb.lpp_m, label);
    return pb;
  };

  // 1. Blender's y-up OBJ export: file (x, y, z) = (x, z, -y) of the z-up hull. The bow stays at -x; up is +y.
  const int blender_axis[3] = {0, 2, 1}, blender_sign[3] = {1, 1, -1};
  const fs::path yup = axes_copy(f, dir / "y_up.obj", blender_axis, blender_sign);
  HullPlacement y = as_is;
  y.up_direction = "+y";
  const Placed b = check(yup, y, "y-up copy");
  EXPECT_EQ(b.side["placement"]["hull_axes_in_file"], nlohmann::json({"-x", "+z", "+y"}));

  // 2. The same y-up copy with its keel at height 0 and midship at file (x, z) = (2.5, -0.75): the waterline and
  // the origin are then given in the y-up file's own terms (waterline_z_m = T along +y, origin_m = [x, z]).
  HullPlacement ys = y;
  ys.waterline_z_m = kDtmb.draught_m;
  ys.origin_m = {2.5, -0.75};
  check(transformed_copy(yup, dir / "y_up_keel0.obj", 1.0, Vec3(2.5, kDtmb.draught_m, -0.75)), ys,
        "y-up copy, keel at y = 0, midship at (x, z) = (2.5, -0.75)");

  // 3. An x-up file with the bow towards +z: file (x, y, z) = (z, y, -x) of the z-up hull (a turn about y).
  const int xup_axis[3] = {2, 1, 0}, xup_sign[3] = {1, 1, -1};
  HullPlacement x;
  x.up_direction = "+x";
  x.bow_direction = "+z";
  check(axes_copy(f, dir / "x_up.obj", xup_axis, xup_sign), x, "x-up copy, bow +z");
  fs::remove_all(dir);
}

TEST(HullPlacementRealHulls, KcsBowMinusXWaterlineAtZero) { check_real_hull(kKcs, false); }
TEST(HullPlacementRealHulls, Dtmb5415BowMinusXWaterlineAtZeroAndFullScale) { check_real_hull(kDtmb, true); }

}  // namespace
}  // namespace floesim::sim
