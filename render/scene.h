// Draws one results frame: water, floe slabs, the hull, seen from a camera that follows the vessel (chase, top or
// side; split puts two of them side by side or stacked in one frame), then the load strip chart (strip_chart.h) and
// the text overlay. All geometry comes from the results file; the floe slabs and the hull are built once, in their
// body frames. Per frame and view, the floes inside the view are posed (rotation + translation of the prebuilt
// slab) into one batch drawn with a single call, and the hull, smooth-shaded under the sun, is drawn with its pose
// matrix. Pieces of broken floes are bodies like any other floe, coloured by how they were made (floe_top_colour
// below); a floe that broke has no state from then on and so is not drawn. A floe pressed against the vessel at
// the frame (/states/in_contact) shows contact_colour on its top.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/results_io.h"
#include "render/render_options.h"

namespace floesim::render {

struct FrameStats {
  size_t floes_drawn = 0;   // passed the frustum test
  size_t floes_culled = 0;  // outside the view, not drawn
};

class SceneRenderer {
 public:
  // Checks the geometry and the states (errors name `source`, the results file), builds the vertex arrays and
  // creates the off-screen context. `r` must outlive the renderer.
  SceneRenderer(const Results& r, const RenderOptions& o, const std::string& source);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Renders results frame k into `out` (8-bit BGR, width_px x height_px, overlay included).
  void render(size_t frame, cv::Mat& out);
  const FrameStats& last_stats() const;
  std::string gl_renderer() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A hull made of convex parts (floesim-hull, the simulator's collision model) has the faces between neighbouring
// parts twice, once per part and triangulated differently. Inside the solid they are hidden, but they peek through
// the hairline cracks of the deck as coloured dots, so the renderer drops them. A face is internal if its centroid
// lies inside another coplanar triangle (either orientation): an outer surface never overlaps itself.
// v: [V x 3] vertices, t: [T x 3] triangles; returns one flag per triangle.
std::vector<bool> hull_internal_faces(const std::vector<double>& v, const std::vector<int32_t>& t);

// The top colour of a floe (before the small per-id shade and the lighting): floes of the input field (origin
// mode 0) in floe_top_colour; a piece in the colour of the fracture that made it (bending and radial share one),
// 15 % darker per generation after the first and no darker than generation 4, so that a piece stands out from
// the floe it broke from and the viewer sees at a glance what broke and how.
void floe_top_colour(const RenderOptions& o, int32_t origin_mode, int32_t generation, float rgb[3]);

// How much faster than real time the video plays: simulated seconds per second of video, fps times the results'
// frame interval (the output_interval_s attribute, else the first two frames' spacing); NaN if neither is known.
double playback_speed(const Results& r, double fps);

// The pixel at which the top view shows world point (x, y) in results frame `frame` (for tests and overlays):
// the view is centred on the vessel, north up, top_width_m across.
cv::Point2d top_view_pixel(const Results& r, const RenderOptions& o, size_t frame, double x_m, double y_m);

}  // namespace floesim::render
