// Closed triangle meshes: mass properties and clipping at the water plane. Used for hull parts and floe slabs.
#pragma once
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace floesim::sim {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// A closed triangle mesh; triangles are counter-clockwise seen from outside (outward normals).
struct TriMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

struct MassProperties {
  double volume = 0;                     // m^3
  Vec3 centroid = Vec3::Zero();          // m
  Mat3 inertia = Mat3::Zero();           // kg m^2 per (kg/m^3) of density, about the centroid (multiply by density)
};

// Exact for closed meshes (signed tetrahedra; Mirtich/Eberly). Negative volume means inward-facing triangles.
MassProperties mass_properties(const TriMesh& m);

// Part of a closed mesh below the horizontal plane z = z0 (mesh given in world coordinates):
// volume, centroid (centre of buoyancy) and waterplane area. Works for non-convex closed meshes too.
struct Submerged {
  double volume = 0;             // m^3
  Vec3 centroid = Vec3::Zero();  // m (meaningless if volume == 0)
  double waterplane_area = 0;    // m^2, area of the section at z = z0
};
Submerged submerged_part(const std::vector<Vec3>& world_vertices, const std::vector<std::array<int, 3>>& triangles,
                         double z0 = 0.0);

// Convex hull (quickhull) of points, as a closed outward-oriented TriMesh. Error if the points are degenerate.
TriMesh convex_hull(const std::vector<Vec3>& points);

// True if every vertex lies on the inner side of every triangle's plane (within tol metres).
bool is_convex(const TriMesh& m, double tol = 1e-6);

// Slab of thickness h extruded from a CCW polygon (vertices relative to anything), spanning z = z_bottom .. z_bottom+h.
TriMesh extrude_polygon(const std::vector<Eigen::Vector2d>& ccw_polygon, double z_bottom, double h);

}  // namespace floesim::sim
