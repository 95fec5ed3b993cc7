// The vessel's hull: a parametric icebreaker generator (written as OBJ) and the loader any user hull goes through.
// Defined in generate.cpp (the parametric icebreaker, write_obj), import.cpp (loading and placing a CAD mesh,
// write_imported_hull) and hull.cpp (hydrostatics); hull_internal.h holds the helpers they share.
#pragma once
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/options.h"
#include "sim/geometry/mesh.h"

namespace floesim::sim {

// Parametric icebreaker with Oden's main particulars by default. Frame: x forward, y to port, z up,
// calm waterline at z = 0, origin at midship on the centreline.
struct HullGeneratorOptions {
  double length_m = 107.75;          // length over all (Oden ~108 m)
  double beam_m = 25.0;              // moulded beam of the parallel body
  double reamer_beam_m = 31.0;       // beam at the bow reamers
  double draught_m = 8.0;            // design draught
  double depth_m = 14.0;             // keel to deck
  double stem_angle_deg = 22.0;      // bow stem angle to the waterline (Oden's broad bow is very flat)
  double entrance_angle_deg = 90.0;  // waterline entrance angle; 90: the spoon bow, square across (Oden's)
  int sections = 30;                 // convex parts along the length (20..40)
  template <class V>
  void visit(V& v) {
    v.field("length_m", length_m, "m", "length over all", positive());
    v.field("beam_m", beam_m, "m", "beam of the parallel body", positive());
    v.field("reamer_beam_m", reamer_beam_m, "m", "beam at the bow reamers (>= beam_m)", positive());
    v.field("draught_m", draught_m, "m", "design draught", positive());
    v.field("depth_m", depth_m, "m", "keel to deck (> draught_m)", positive());
    v.field("stem_angle_deg", stem_angle_deg, "deg", "stem angle to the waterline", in_range(5, 80));
    v.field("entrance_angle_deg", entrance_angle_deg, "deg",
            "waterline entrance angle alpha: below 90 the bow is cut by two planes through the stem line, each meeting "
            "the waterline at alpha to the centreline (a wedge bow, normal flare arctan(tan(stem) / sin(alpha))); "
            "90 = the spoon bow, its waterline square across",
            in_range(10, 90));
    v.field("sections", sections, "-", "number of convex parts", int_in_range(4, 64));
    if (reamer_beam_m < beam_m) v.problem("reamer_beam_m", "must be >= beam_m");
    if (depth_m <= draught_m) v.problem("depth_m", "must be > draught_m");
  }
};

// A structure's hull from parameters (issue #34): a vertical cylinder, a caisson, or a cone with a neck, breaking the
// ice upwards (the cone widens downwards from its neck above the waterline, as on bridge piers and lighthouses) or
// downwards (it widens upwards from a neck below the waterline, as on Kulluk). Frame: z up, calm waterline z = 0,
// origin on the axis at the waterline; x is the direction the ice comes from (a caisson's length). Round sections are
// regular polygons of `sides` faces around the circle of the stated diameter (its width across flats; a face looks
// along +x), so that every side face has the stated slope.
struct StructureShapeOptions {
  std::string shape = "cone";       // cone | cylinder | caisson
  std::string breaking = "upward";  // cone: upward | downward
  double waterline_width_m = 10;    // w: diameter (cone, cylinder) or width across y (caisson) at the waterline
  double neck_width_m = 4;          // w_T: cone's neck diameter
  double slope_deg = 45;            // alpha: cone's slope from the horizontal
  double length_m = 0;              // caisson's length along x; 0 = waterline_width_m
  double depth_m = 10;              // the structure reaches this far below the waterline
  double height_m = 10;             // and this far above it
  int sides = 32;                   // vertices of a round section
  template <class V>
  void visit(V& v) {
    v.field("shape", shape, "-", "cone, cylinder (vertical) or caisson (a box)",
            one_of({"cone", "cylinder", "caisson"}));
    v.field("breaking", breaking, "-",
            "cone: upward (widens downwards from a neck above the waterline) or downward (widens upwards from a neck "
            "below it)",
            one_of({"upward", "downward"}));
    v.field("waterline_width_m", waterline_width_m, "m", "width at the waterline: a cone's or cylinder's diameter, a "
            "caisson's width across y", positive());
    v.field("neck_width_m", neck_width_m, "m", "cone: neck diameter w_T (below waterline_width_m)", positive());
    v.field("slope_deg", slope_deg, "deg", "cone: slope from the horizontal (20-70, the design formulas' range)",
            in_range(20, 70));
    v.field("length_m", length_m, "m", "caisson: length along x (0 = waterline_width_m)", non_negative());
    v.field("depth_m", depth_m, "m", "how far the structure reaches below the waterline", positive());
    v.field("height_m", height_m, "m", "how far it reaches above the waterline", positive());
    v.field("sides", sides, "-", "faces around a round section (a regular polygon around the circle)",
            int_in_range(8, 256));
    if (shape == "cone" && neck_width_m >= waterline_width_m)
      v.problem("neck_width_m", "must be smaller than waterline_width_m (the cone narrows to its neck)");
  }
};

// The structure as convex parts: a cylinder or caisson is one part; a cone is its frustum from the structure's end
// on the wide side to the neck, and the neck's cylinder from there to the other end (an Error if the neck lies beyond
// that end: raise height_m, or depth_m for a downward-breaking cone, or widen the neck).
std::vector<TriMesh> generate_structure(const StructureShapeOptions& o);
// The floesim-hull stage for a structure: writes out_obj and its sidecar (hydrostatics, the shape's figures, no ship
// particulars) atomically and returns the summary printed on stdout.
std::string write_generated_structure(const StructureShapeOptions& o, const std::filesystem::path& out_obj,
                                      const std::filesystem::path& config_file);

// Builds the hull as convex parts (one mesh each) and writes it as an OBJ with one object ("o part_k") per part.
std::vector<TriMesh> generate_hull(const HullGeneratorOptions& o);
void write_obj(const std::filesystem::path& file, const std::vector<TriMesh>& parts, const std::string& header);

// Hydrostatics of a hull made of parts (in the hull's frame) floating with the water surface at z = z0.
// (Added by the vessel helper; additive to the interface above.)
struct Hydrostatics {
  double volume_m3 = 0;                    // displaced volume (below z0)
  double displacement_t = 0;               // rho_w * volume / 1000
  double waterplane_area_m2 = 0;           // area of the section at z0
  Vec3 centre_of_buoyancy = Vec3::Zero();  // m, hull frame
  double lcb_m = 0;                        // x of the centre of buoyancy (positive forward of the origin)
  double kb_m = 0;                         // height of the centre of buoyancy above the lowest point (keel)
  double wetted_surface_m2 = 0;            // outer surface below z0; faces shared by two parts are excluded
  double length_wl_m = 0;                  // x extent of the waterplane
  double beam_wl_m = 0;                    // y extent of the waterplane
  double draught_m = 0;                    // z0 - lowest point
  double block_coefficient = 0;            // volume / (length_wl * beam_wl * draught)
};
Hydrostatics hydrostatics(const std::vector<TriMesh>& parts, double rho_w_kg_m3 = 1025.0, double z0 = 0.0);

// The floesim-hull stage: generates the hull, writes out_obj and its sidecar (out_obj with extension .json:
// particulars, hydrostatics, provenance) atomically and returns the summary printed on stdout. config_file (may be
// empty) is recorded in the provenance.
std::string write_generated_hull(const HullGeneratorOptions& o, const std::filesystem::path& out_obj,
                                 const std::filesystem::path& config_file);

// How the loader treats a mesh that is not convex.
struct HullLoadOptions {
  std::string non_convex = "slice";  // "slice": cut into sections along x, convex hull of each; "refuse": error
  int slices = 24;                   // sections per non-convex mesh when slicing
  double max_volume_error = 0.05;    // refuse if the decomposition changes the volume by more than this fraction
  template <class V>
  void visit(V& v) {
    v.field("non_convex", non_convex, "-", "what to do with a non-convex mesh: slice | refuse",
            one_of({"slice", "refuse"}));
    v.field("slices", slices, "-", "sections per non-convex mesh", int_in_range(2, 400));
    v.field("max_volume_error", max_volume_error, "-", "largest accepted relative volume change", in_range(0, 1));
  }
};

// Where a mesh from CAD lies in its own frame, and so how it is brought into the hull frame the simulator uses (x
// forward, y to port, z up, calm waterline at z = 0): a point p of the file goes to
//   scale * R * (p - o),
// with R the proper rotation that takes up_direction to +z and bow_direction to +x (so port, up x bow, to +y), and
// o the file point on the calm waterline (height waterline_z_m along up_direction) at the horizontal position
// origin_m. For the default z-up file, R is the turn about z that takes the bow to +x and o = [origin_m, waterline_z_m].
// Meshes exported y-up (Blender's and many tools' OBJ default) need only up_direction "+y". Lengths are in the
// file's own units and frame.
struct HullPlacement {
  double scale = 1.0;                        // file units -> metres (0.001 for a file in mm; 1/31.6 full -> model)
  std::string up_direction = "+z";           // which file axis points up (deck above keel): +z | -z | +y | ... | -x
  std::string bow_direction = "+x";          // where the bow points in the file: +x | -x | +y | -y (| +z | -z)
  double waterline_z_m = 0.0;                // height of the calm waterline along up_direction (file units, unscaled)
  std::vector<double> origin_m = {0.0, 0.0};  // the file's horizontal coordinates that become the hull frame's origin
  template <class V>
  void visit(V& v) {
    v.field("scale", scale, "-", "multiplies the file's coordinates (file units -> metres)", positive());
    v.field("up_direction", up_direction, "-",
            "which axis of the file points up (keel to deck): +z (default), or +y for a y-up export (Blender's OBJ "
            "default), or -z, -y, +x, -x; applied before the bow turn",
            one_of({"+z", "-z", "+y", "-y", "+x", "-x"}));
    v.field("bow_direction", bow_direction, "-",
            "where the bow points in the file: +x, -x, +y or -y (or +z, -z in a file whose up_direction is x or y)",
            one_of({"+x", "-x", "+y", "-y", "+z", "-z"}));
    // The two directions must span the horizontal: a bow along the up axis leaves port undefined.
    if (up_direction.size() == 2 && bow_direction.size() == 2 && up_direction[1] == bow_direction[1])
      v.problem("bow_direction",
                "must be horizontal, across up_direction = \"" + up_direction + "\", got \"" + bow_direction +
                    "\": set up_direction to the file's vertical axis (\"+y\" for a y-up export) and bow_direction "
                    "to the axis the bow points along");
    v.field("waterline_z_m", waterline_z_m, "m",
            "height of the calm waterline along up_direction, in the file's own frame and units (e.g. the draught if "
            "the keel is at height 0; for a +y-up file, the file y of the waterline)",
            Check<double>([](const double& z) -> std::string { return std::isfinite(z) ? "" : "must be finite"; }));
    v.field("origin_m", origin_m, "m",
            "the file's coordinates on its two horizontal axes, in axis order ([x, y] in a z-up file, [x, z] in a "
            "y-up one, [y, z] in an x-up one), of the point that becomes the hull frame's origin (e.g. midship on the "
            "centreline)",
            Check<std::vector<double>>([](const std::vector<double>& p) -> std::string {
              if (p.size() != 2) return "must be 2 numbers (the file's two horizontal coordinates)";
              for (double x : p)
                if (!std::isfinite(x)) return "must be finite numbers";
              return "";
            }));
  }
};

// The placement as a map of points: file frame -> hull frame, and one line saying what it does.
Vec3 place_point(const HullPlacement& p, const Vec3& file_point);
std::string describe_placement(const HullPlacement& p);

struct HullModel {
  std::vector<TriMesh> parts;   // convex parts, in the hull frame (the file's frame after the placement; metres)
  TriMesh surface;              // all parts merged: used for buoyancy clipping and rendering
  TriMesh mesh;                 // the input meshes as read (welded, oriented, placed), merged: the reference
  double mesh_volume_m3 = 0;    // volume enclosed by the input meshes (as read, after scaling)
  double parts_volume_m3 = 0;   // volume of the convex parts
  HullPlacement placement;      // how the file was placed
  std::string report;           // what the loader did: the placement, then one line per mesh (convex kept / sliced
                                // into N, volume error)
};

// A HullModel of convex parts made in the program (generate_hull): the parts and their merged surface, which is
// also the reference mesh (no file, no placement).
HullModel hull_model_from_parts(std::vector<TriMesh> parts);

// Loads any mesh file assimp reads (OBJ first of all); each mesh is one part. Convex meshes are kept as they are;
// non-convex ones are sliced or refused per the options, never silently replaced by their convex hull.
// Details (vessel helper): node transforms are applied (mirroring ones too); vertices at equal positions are
// welded; inconsistently oriented triangles are re-oriented and an inside-out mesh is flipped; meshes that are open
// on their own but close when welded together (OBJ groups hull / deck / transom, as in the KCS and DTMB 5415 files)
// become one body; anything still open is an Error. Slicing cuts along x; a section whose hull would add more than
// 2 % of its volume (bulb, skeg, flare) is also cut horizontally into up to 8 layers, and neighbouring uncut
// sections are merged while that adds < 0.1 %. Convexity is judged to 1e-6 of the mesh size.
// The placement is applied to the vertices as read, before anything else (so slicing runs along the placed x).
HullModel load_hull(const std::filesystem::path& file, const HullLoadOptions& o = {},
                    const HullPlacement& placement = {});

// Refuses (Error naming `where`, the key to fix and the mesh's z range in the file) a hull that, in the hull frame,
// lies entirely above or below the calm waterline z = 0, or displaces less than 1 % or more than 99 % of its volume
// there (a waterline at the keel or at the deck).
void require_floating(const HullModel& hull, const std::string& where);

// The floesim-hull stage for a user's mesh: the hull section of a case ("file" beside the placement and the
// decomposition options).
struct HullImportOptions {
  std::string file;                    // the mesh (OBJ or anything assimp reads); relative to the config file
  HullPlacement placement;             // read from the same level: scale, up_direction, bow_direction, waterline_z_m,
                                       // origin_m
  HullLoadOptions load;                // read from the same level: non_convex, slices, max_volume_error
  double water_density_kg_m3 = 1025.0;  // for the displacement reported (the simulation uses its own water density)
  template <class V>
  void visit(V& v) {
    v.field("file", file, "-", "the hull mesh (OBJ or anything assimp reads); relative to this file's folder",
            Check<std::string>([](const std::string& f) -> std::string { return f.empty() ? "must name a file" : ""; }));
    placement.visit(v);
    load.visit(v);
    v.field("water_density_kg_m3", water_density_kg_m3, "kg/m^3", "water density for the displacement reported",
            positive());
  }
};

// Loads, places and decomposes o.file, refuses a hull that does not float (require_floating), writes the convex
// parts to out_obj (one object per part, hull frame) and its sidecar (out_obj with extension .json: placement,
// parts, volume error, displacement and waterline, provenance) atomically and returns the summary printed on stdout.
// Nothing is written if the hull is refused. config_file (may be empty) is recorded in the provenance and names
// the keys in errors; a relative o.file is taken relative to its folder.
std::string write_imported_hull(const HullImportOptions& o, const std::filesystem::path& out_obj,
                                const std::filesystem::path& config_file);

}  // namespace floesim::sim
