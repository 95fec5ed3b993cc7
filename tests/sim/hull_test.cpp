// The parametric icebreaker (main particulars, convex parts, displacement) and the hull loader on the generated OBJ
// and on two real benchmark hulls.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/error.h"
#include "sim/vessel/hull.h"
#include "tests/sim/obj_faces.h"
#include "tests/sim/sim_fixtures.h"

#ifndef FLOESIM_SHARED_DATA_DIR
#error "FLOESIM_SHARED_DATA_DIR must be defined by the build"
#endif

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;

using testing::hull_file;
using testing::expect_error;
using testing::temp_dir;

// Half-breadths of the waterline: points where edges of the parts cross z = 0.
struct Waterline {
  double max_half_beam = 0;       // anywhere
  double midship_half_beam = 0;   // |x| < 5 m
  double x_of_max = 0;
};
Waterline waterline(const std::vector<TriMesh>& parts) {
  Waterline w;
  for (const TriMesh& p : parts)
    for (const auto& t : p.triangles)
      for (int k = 0; k < 3; ++k) {
        const Vec3 &a = p.vertices[t[k]], &b = p.vertices[t[(k + 1) % 3]];
        if (a.z() * b.z() > 0 || a.z() == b.z()) continue;
        const Vec3 q = a + (b - a) * (-a.z() / (b.z() - a.z()));
        if (std::abs(q.y()) > w.max_half_beam) w.max_half_beam = std::abs(q.y()), w.x_of_max = q.x();
        if (std::abs(q.x()) < 5) w.midship_half_beam = std::max(w.midship_half_beam, std::abs(q.y()));
      }
  return w;
}

// Box [x0, x1] x [-b/2, b/2] x [-T, D - T] as a closed mesh (outward triangles).
TriMesh box(double x0, double x1, double b, double T, double D) {
  TriMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? x1 : x0, i & 2 ? b / 2 : -b / 2, i & 4 ? D - T : -T);
  const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

TEST(Hydrostatics, BargeOfTwoBoxesClosedForm) {
  // A 10 x 4 barge floating 1.5 m deep in 2 m depth, as two 5 m boxes sharing a face: the shared face is not
  // wetted. V = 60, WP = 40, S = bottom 40 + sides 2 * (10 + 4) * 1.5 = 82, KB = 0.75, LCB at the middle.
  const std::vector<TriMesh> parts{box(-5, 0, 4, 1.5, 2), box(0, 5, 4, 1.5, 2)};
  const Hydrostatics h = hydrostatics(parts, 1025.0, 0.0);
  EXPECT_NEAR(h.volume_m3, 60.0, 1e-9);
  EXPECT_NEAR(h.displacement_t, 61.5, 1e-9);
  EXPECT_NEAR(h.waterplane_area_m2, 40.0, 1e-9);
  EXPECT_NEAR(h.wetted_surface_m2, 82.0, 1e-9);
  EXPECT_NEAR(h.kb_m, 0.75, 1e-9);
  EXPECT_NEAR(h.lcb_m, 0.0, 1e-9);
  EXPECT_NEAR(h.length_wl_m, 10.0, 1e-9);
  EXPECT_NEAR(h.beam_wl_m, 4.0, 1e-9);
  EXPECT_NEAR(h.draught_m, 1.5, 1e-9);
  EXPECT_NEAR(h.block_coefficient, 1.0, 1e-9);
}

TEST(GeneratedHull, MainParticularsAndDisplacement) {
  const HullGeneratorOptions o;
  const std::vector<TriMesh> parts = generate_hull(o);
  ASSERT_EQ(parts.size(), static_cast<size_t>(o.sections));
  EXPECT_GE(parts.size(), 20u);
  EXPECT_LE(parts.size(), 40u);
  Vec3 lo = Vec3::Constant(1e300), hi = -lo;
  for (const TriMesh& p : parts) {
    EXPECT_TRUE(is_convex(p, 1e-6)) << "a part is not convex";
    EXPECT_GT(mass_properties(p).volume, 0);
    for (const Vec3& v : p.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  }
  EXPECT_NEAR(hi.x() - lo.x(), o.length_m, 0.01);
  EXPECT_NEAR(-lo.z(), o.draught_m, 0.01);
  EXPECT_NEAR(hi.z() - lo.z(), o.depth_m, 0.01);

  const Waterline w = waterline(parts);
  EXPECT_NEAR(2 * w.midship_half_beam, o.beam_m, 0.05);
  EXPECT_NEAR(2 * w.max_half_beam, o.reamer_beam_m, 0.05);
  EXPECT_GT(w.x_of_max, 0.1 * o.length_m) << "the reamers (widest waterline) must be in the forward part";

  const Hydrostatics h = hydrostatics(parts, 1025.0, 0.0);
  EXPECT_NEAR(h.displacement_t, 13000.0, 0.05 * 13000.0);
  EXPECT_NEAR(h.draught_m, o.draught_m, 0.01);
  EXPECT_NEAR(h.beam_wl_m, o.reamer_beam_m, 0.05);
  EXPECT_GT(h.block_coefficient, 0.5);
  EXPECT_LT(h.block_coefficient, 0.75);
  // The centre of buoyancy is below the waterline, above half the draught for a full, flat-bottomed hull.
  EXPECT_GT(h.kb_m, 0.5 * o.draught_m);
  EXPECT_LT(h.kb_m, o.draught_m);
  // Wetted surface: between the waterplane + the projected side area and a box's wetted surface.
  EXPECT_GT(h.wetted_surface_m2, h.waterplane_area_m2);
  EXPECT_LT(h.wetted_surface_m2, h.length_wl_m * (h.beam_wl_m + 2 * h.draught_m) + 2 * h.beam_wl_m * h.draught_m);
}

TEST(GeneratedHull, SubmergedVolumeOfPartsEqualsSurfaceClipping) {
  // Faces shared by neighbouring parts cancel: clipping the merged surface equals summing the parts' clips.
  const std::vector<TriMesh> parts = generate_hull(HullGeneratorOptions{});
  double sum = 0;
  TriMesh all;
  for (const TriMesh& p : parts) {
    sum += submerged_part(p.vertices, p.triangles, 0.0).volume;
    const int off = static_cast<int>(all.vertices.size());
    all.vertices.insert(all.vertices.end(), p.vertices.begin(), p.vertices.end());
    for (const auto& t : p.triangles) all.triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
  }
  EXPECT_NEAR(submerged_part(all.vertices, all.triangles, 0.0).volume, sum, 1e-9 * sum);
}

TEST(GeneratedHull, ObjRoundTripThroughLoader) {
  const fs::path dir = temp_dir("roundtrip");
  const fs::path obj = dir / "hull.obj";
  HullGeneratorOptions o;
  const std::string summary = write_generated_hull(o, obj, "");
  EXPECT_NE(summary.find("displacement"), std::string::npos);
  ASSERT_TRUE(fs::exists(obj));
  ASSERT_TRUE(fs::exists(dir / "hull.json"));
  const nlohmann::json side = nlohmann::json::parse(std::ifstream(dir / "hull.json"));
  EXPECT_EQ(side["parts"].get<int>(), o.sections);
  EXPECT_EQ(side["provenance"]["program"], "floesim-hull");
  EXPECT_NEAR(side["hydrostatics"]["displacement_t"].get<double>(), 13000.0, 650.0);
  {  // the header records the particulars and the displacement
    std::ifstream in(obj);
    std::string first, all;
    for (std::string line; std::getline(in, line) && line.rfind("#", 0) == 0;) all += line + "\n";
    EXPECT_NE(all.find("displacement"), std::string::npos);
    EXPECT_NE(all.find("length_m 107.75"), std::string::npos);
  }

  const std::vector<TriMesh> parts = generate_hull(o);
  const HullModel m = load_hull(obj, HullLoadOptions{"refuse", 24, 0.05});  // all parts convex: nothing refused
  ASSERT_EQ(m.parts.size(), parts.size());
  for (size_t k = 0; k < parts.size(); ++k) {
    const double v0 = mass_properties(parts[k]).volume, v1 = mass_properties(m.parts[k]).volume;
    EXPECT_NEAR(v1, v0, 1e-9 * v0) << "part " << k;
  }
  EXPECT_NEAR(m.parts_volume_m3, m.mesh_volume_m3, 1e-12 * m.mesh_volume_m3);
  std::istringstream rep(m.report);
  int convex_lines = 0;
  for (std::string line; std::getline(rep, line);) convex_lines += line.find("convex: kept") != std::string::npos;
  EXPECT_EQ(convex_lines, o.sections) << m.report;
  EXPECT_EQ(m.surface.triangles.size(), [&] {
    size_t n = 0;
    for (const TriMesh& p : parts) n += p.triangles.size();
    return n;
  }());
  fs::remove_all(dir);
}

TEST(GeneratedHull, BadOptionsAreErrors) {
  HullGeneratorOptions o;
  o.reamer_beam_m = 20;  // < beam
  EXPECT_THROW(generate_hull(o), Error);
  o = HullGeneratorOptions{};
  o.sections = 2;
  EXPECT_THROW(generate_hull(o), Error);
}

// A structure's hull from parameters (issue #34). A round section is the regular N-gon around the circle of the
// stated diameter, of area N r^2 tan(pi / N); a frustum between two such sections of areas A0, A1 a height H apart
// holds H (A0 + A1 + sqrt(A0 A1)) / 3 (the pyramid frustum). Each part is convex, the parts' volumes add up to the
// closed form of the whole, and every side face of a cone leans at the stated slope: its outward normal makes the
// angle alpha with the vertical, up and out on an upward-breaking cone, down and out on a downward-breaking one.
double ngon_area(double r, int n) { return n * r * r * std::tan(kPi / n); }
double frustum_volume(double a0, double a1, double h) { return h * (a0 + a1 + std::sqrt(a0 * a1)) / 3; }

// The largest deviation from `slope_deg` of the side faces' lean (faces neither horizontal nor vertical), and the
// sign of their normals' z.
std::pair<double, double> side_face_lean(const TriMesh& part, double slope_deg) {
  double worst = 0, sign = 0;
  for (const auto& t : part.triangles) {
    const Vec3& a = part.vertices[t[0]];
    const Vec3 n = (part.vertices[t[1]] - a).cross(part.vertices[t[2]] - a).normalized();
    if (std::abs(n.z()) > 1 - 1e-9 || std::abs(n.z()) < 1e-9) continue;  // a cap or a vertical side
    worst = std::max(worst, std::abs(std::acos(std::abs(n.z())) * 180 / kPi - slope_deg));
    sign = n.z() > 0 ? 1 : -1;
  }
  return {worst, sign};
}

TEST(StructureShapes, VolumesWaterplanesAndSlopesAgainstClosedForms) {
  StructureShapeOptions o;  // upward cone: w 10 m, neck 4 m, 45 deg, 10 m below and above the waterline, 32 faces
  const int n = o.sides;
  const std::vector<TriMesh> up = generate_structure(o);
  ASSERT_EQ(up.size(), 2u);
  for (const TriMesh& p : up) EXPECT_TRUE(is_convex(p));
  // Frustum from r = 5 + 10 = 15 m at z = -10 to the neck r = 2 at z = 3 (tan 45 x (10 - 4) / 2); neck to z = 10.
  const double v_cone = frustum_volume(ngon_area(15, n), ngon_area(2, n), 13), v_neck = ngon_area(2, n) * 7;
  EXPECT_NEAR(mass_properties(up[0]).volume, v_cone, 1e-9 * v_cone);
  EXPECT_NEAR(mass_properties(up[1]).volume, v_neck, 1e-9 * v_neck);
  const Hydrostatics h = hydrostatics(up);
  EXPECT_NEAR(h.volume_m3, frustum_volume(ngon_area(15, n), ngon_area(5, n), 10), 1e-9 * h.volume_m3);
  EXPECT_NEAR(h.waterplane_area_m2, ngon_area(5, n), 1e-9 * h.waterplane_area_m2);
  const auto [lean_up, up_sign] = side_face_lean(up[0], 45);
  EXPECT_LT(lean_up, 1e-9);
  EXPECT_EQ(up_sign, 1.0);
  // Downward cone at 60 deg, neck 3 m below the waterline... tan 60 x (10 - 4) / 2 = 5.196 m; 8 m deep.
  o.breaking = "downward";
  o.slope_deg = 60;
  o.depth_m = 8;
  const std::vector<TriMesh> down = generate_structure(o);
  ASSERT_EQ(down.size(), 2u);
  const double neck = std::tan(60 * kPi / 180) * 3, rt = 5 + 10 / std::tan(60 * kPi / 180);
  EXPECT_NEAR(mass_properties(down[1]).volume, frustum_volume(ngon_area(2, n), ngon_area(rt, n), 10 + neck), 1e-6);
  EXPECT_NEAR(hydrostatics(down).waterplane_area_m2, ngon_area(5, n), 1e-9 * ngon_area(5, n));
  const auto [lean_down, down_sign] = side_face_lean(down[1], 60);
  EXPECT_LT(lean_down, 1e-9);
  EXPECT_EQ(down_sign, -1.0);
  // A cylinder and a caisson: prisms.
  StructureShapeOptions c;
  c.shape = "cylinder";
  EXPECT_NEAR(hydrostatics(generate_structure(c)).volume_m3, ngon_area(5, n) * 10, 1e-9 * 800);
  c.shape = "caisson";
  c.length_m = 30;
  EXPECT_NEAR(hydrostatics(generate_structure(c)).volume_m3, 30.0 * 10 * 10, 1e-9);
}

TEST(StructureShapes, BadOptionsNameTheKey) {
  StructureShapeOptions o;
  o.neck_width_m = 12;  // wider than the waterline
  expect_error([&] { generate_structure(o); }, {"neck_width_m"});
  o = StructureShapeOptions{};
  o.height_m = 2;  // the 45 deg cone's neck is 3 m up
  expect_error([&] { generate_structure(o); }, {"height_m"});
  o = StructureShapeOptions{};
  o.slope_deg = 85;
  expect_error([&] { generate_structure(o); }, {"slope_deg"});
  o = StructureShapeOptions{};
  o.shape = "tripod";
  expect_error([&] { generate_structure(o); }, {"shape"});
}

TEST(LoadHull, MissingAndUnreadableFilesNameTheFile) {
  const fs::path dir = temp_dir("errors");
  try {
    load_hull(dir / "nope.obj");
    FAIL() << "no error for a missing file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nope.obj"), std::string::npos) << e.what();
  }
  const fs::path junk = dir / "junk.obj";
  std::ofstream(junk) << "this is not a mesh\n";
  try {
    load_hull(junk);
    FAIL() << "no error for a file without meshes";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("junk.obj"), std::string::npos) << e.what();
  }
  // An open mesh (a single triangle... a tetrahedron missing a face) is refused with the reason.
  const fs::path open = dir / "open.obj";
  std::ofstream(open) << "o tet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n";
  try {
    load_hull(open);
    FAIL() << "no error for an open mesh";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("open.obj"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not closed"), std::string::npos) << e.what();
  }
  // A flat (zero-volume) closed mesh: degenerate.
  const fs::path flat = dir / "flat.obj";
  std::ofstream(flat) << "o flat\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n";
  EXPECT_THROW(load_hull(flat), Error);
  fs::remove_all(dir);
}

TEST(LoadHull, InwardFacingConvexMeshIsFlipped) {
  const fs::path dir = temp_dir("flip");
  // A unit cube written with every triangle facing inwards: loaded with positive volume, and the report says so.
  const fs::path cube = dir / "cube.obj";
  std::ofstream(cube) << "o cube\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                         "f 1 4 3\nf 1 2 4\nf 5 8 6\nf 5 7 8\nf 1 6 2\nf 1 5 6\nf 3 8 7\nf 3 4 8\n"
                         "f 1 7 5\nf 1 3 7\nf 2 8 4\nf 2 6 8\n";
  const HullModel m = load_hull(cube);
  ASSERT_EQ(m.parts.size(), 1u);
  EXPECT_NEAR(mass_properties(m.parts[0]).volume, 1.0, 1e-12);
  EXPECT_NE(m.report.find("flipped"), std::string::npos) << m.report;
  fs::remove_all(dir);
}

TEST(LoadHull, NodeTransformsPlaceTheMeshes) {
  // Collada with two instances of a unit cube: one translated, one mirrored and stretched (determinant < 0, which
  // would turn the triangles inside out unless the loader reverses them). Z_UP is kept as the file says.
  const fs::path dir = temp_dir("dae");
  const fs::path dae = dir / "cubes.dae";
  std::ofstream(dae) << R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="cube" name="cube"><mesh>
    <source id="pos"><float_array id="pos-array" count="24">0 0 0 1 0 0 0 1 0 1 1 0 0 0 1 1 0 1 0 1 1 1 1 1</float_array>
      <technique_common><accessor source="#pos-array" count="8" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor>
      </technique_common></source>
    <vertices id="vtx"><input semantic="POSITION" source="#pos"/></vertices>
    <triangles count="12"><input semantic="VERTEX" source="#vtx" offset="0"/>
      <p>0 2 3 0 3 1 4 5 7 4 7 6 0 1 5 0 5 4 2 6 7 2 7 3 0 4 6 0 6 2 1 3 7 1 7 5</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="scene">
    <node id="moved" name="moved"><matrix>1 0 0 10 0 1 0 20 0 0 1 -3 0 0 0 1</matrix>
      <instance_geometry url="#cube"/></node>
    <node id="mirrored" name="mirrored"><matrix>-2 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</matrix>
      <instance_geometry url="#cube"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
  const HullModel m = load_hull(dae);
  ASSERT_EQ(m.parts.size(), 2u) << m.report;
  const MassProperties a = mass_properties(m.parts[0]), b = mass_properties(m.parts[1]);
  EXPECT_NEAR(a.volume, 1.0, 1e-9);
  EXPECT_NEAR((a.centroid - Vec3(10.5, 20.5, -2.5)).norm(), 0, 1e-9);
  EXPECT_NEAR(b.volume, 2.0, 1e-9);
  EXPECT_NEAR((b.centroid - Vec3(-1.0, 0.5, 0.5)).norm(), 0, 1e-9);
  EXPECT_EQ(m.report.find("flipped"), std::string::npos) << m.report;
  fs::remove_all(dir);
}

// ---- the real benchmark hulls (model scale, waterline at z = 0, not convex) ----

// The file's own faces (fan-triangulated), for a reference independent of assimp and of the loader.
using floesim::sim::testing::read_obj_faces;

struct RealHull {
  const char* file;
  double published_volume_m3;  // displacement volume at the design draught (model scale, published)
};

void check_real_hull(const RealHull& r) {
  const fs::path f = hull_file(r.file);
  const TriMesh raw = read_obj_faces(f);
  const double raw_volume = mass_properties(raw).volume;
  const double raw_displaced = submerged_part(raw.vertices, raw.triangles, 0.0).volume;
  // The benchmark geometry itself matches the published displacement (checks the reading and the clipping).
  EXPECT_NEAR(raw_displaced, r.published_volume_m3, 0.01 * r.published_volume_m3);

  const HullModel m = load_hull(f, HullLoadOptions{"slice", 24, 0.05});
  std::cout << r.file << ":\n" << m.report;
  ASSERT_GT(m.parts.size(), 10u);
  for (const TriMesh& p : m.parts) ASSERT_TRUE(is_convex(p, 1e-6));
  EXPECT_NEAR(m.mesh_volume_m3, raw_volume, 1e-6 * raw_volume);
  // Hulls of slices can only add volume; horizontal cuts of the concave sections keep it small.
  const double verr = (m.parts_volume_m3 - m.mesh_volume_m3) / m.mesh_volume_m3;
  EXPECT_GE(verr, 0);
  EXPECT_LT(verr, 0.02);
  // What the simulator floats: the parts clipped at the waterline.
  const Hydrostatics h = hydrostatics(m.parts, 1000.0, 0.0);
  std::cout << "  displaced volume: raw mesh " << raw_displaced << " m^3, convex parts " << h.volume_m3
            << " m^3, published " << r.published_volume_m3 << " m^3\n";
  EXPECT_GE(h.volume_m3, raw_displaced * (1 - 1e-9));
  EXPECT_LT(h.volume_m3, raw_displaced * 1.02);
  // The surface (all parts merged) floats the same volume.
  EXPECT_NEAR(submerged_part(m.surface.vertices, m.surface.triangles, 0.0).volume, h.volume_m3,
              1e-9 * h.volume_m3);
}

// KCS model (scale 1:31.6): Lpp 7.2786 m, T 0.3418 m, displacement volume 1.6490 m^3 (SIMMAN / Tokyo 2015).
TEST(LoadHull, KcsSlicedIntoConvexParts) { check_real_hull({"KCS_model_scale_L7.2786m.obj", 1.6490}); }

// DTMB 5415 model (INSEAN 2340, scale 1:24.83): Lpp 5.72 m, T 0.248 m, displacement volume 0.549 m^3 (SIMMAN 2008).
TEST(LoadHull, Dtmb5415SlicedIntoConvexParts) { check_real_hull({"DTMB5415_model_scale_L5.72m.obj", 0.549}); }

TEST(LoadHull, RefuseNamesTheFile) {
  const fs::path f = hull_file("KCS_model_scale_L7.2786m.obj");
  try {
    load_hull(f, HullLoadOptions{"refuse", 24, 0.05});
    FAIL() << "a non-convex hull was accepted with non_convex = refuse";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("KCS_model_scale_L7.2786m.obj"), std::string::npos) << msg;
    EXPECT_NE(msg.find("not convex"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace floesim::sim
