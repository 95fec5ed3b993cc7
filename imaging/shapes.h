// Plane-geometry helpers the imaging module needs beyond pipeline/geometry2d.h: point-in-polygon,
// polygon distance (floe placement and the no-overlap check of digitised outlines) and clipping to the image.
#pragma once
#include "pipeline/geometry2d.h"

namespace floesim::imaging {

struct BBox {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool overlaps(const BBox& o, double margin = 0) const {
    return x0 - margin <= o.x1 && o.x0 - margin <= x1 && y0 - margin <= o.y1 && o.y0 - margin <= y1;
  }
};
BBox bounding_box(const Polygon& p);

// Even-odd rule; points exactly on an edge may go either way.
bool point_in_polygon(const Vec2& p, const Polygon& poly);

// Distance between segments ab and cd (0 if they touch or cross).
double segment_distance(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d);

// True if two simple polygons overlap, touch, or come closer than `gap` (metres or pixels, as the inputs).
bool polygons_within(const Polygon& a, const Polygon& b, double gap);

// Sutherland-Hodgman clip to the rectangle [x0, x1] x [y0, y1]. The result is exact (one simple polygon) when
// the subject is convex or star-shaped about a point inside the rectangle: the intersection is then connected.
// Returns an empty polygon if nothing (or only a degenerate sliver) is left.
Polygon clip_to_rect(const Polygon& p, double x0, double y0, double x1, double y1);

}  // namespace floesim::imaging
