// Options of the render stage (floesim-render --config render.json): one strict struct, every field with a
// default, a unit and a line of doc (`floesim-render --help-config` prints the table).
#pragma once
#include <string>

#include "pipeline/options.h"

namespace floesim::render {

// Accepts "#rrggbb" colours (what every colour picker gives).
Check<std::string> hex_colour();
// Parses "#rrggbb" into r, g, b in 0..1 (the string must have passed hex_colour()).
void parse_hex_colour(const std::string& s, float rgb[3]);

struct RenderOptions {
  int width_px = 1280;                 // frame width (even: H.264 uses 4:2:0 chroma)
  int height_px = 720;                 // frame height (even)
  double fps = 25;                     // playback rate; one video frame per stored results frame
  int max_frames = 0;                  // render only the first N frames (0 = all)
  std::string view = "chase";          // chase: behind and above the vessel; top: orthographic, north up
  double chase_distance_m = 170;       // horizontal distance of the camera behind the vessel's centre of mass
  double chase_height_m = 60;          // camera height above the water
  double chase_pitch_deg = 20;         // downward tilt of the line of sight
  double fov_deg = 45;                 // vertical field of view of the chase camera
  double top_width_m = 400;            // width of water shown across the frame in the top view
  double view_distance_m = 2500;       // chase view: far clip distance; floes beyond are not drawn
  bool fog = true;                     // chase view: haze that fades the far field into the sky
  int supersample = 2;                 // render at N x the size and downsample (anti-aliasing; cost ~ N^2)
  bool overlay = true;                 // time, frame, speed, fracture count (and a scale bar in the top view)
  bool floe_edges = true;              // outline the top face of each floe (separates touching floes)
  std::string sky_colour = "#c5d0da";
  std::string water_colour = "#1f2d38";
  std::string floe_top_colour = "#f4f8fb";         // floes of the input field
  std::string floe_side_colour = "#9fc3d6";
  std::string bending_piece_colour = "#a6d0f2";    // light blue: pieces of bending or radial fracture
  std::string splitting_piece_colour = "#f5b860";  // amber: pieces of splitting fracture
  std::string edge_colour = "#5f7687";
  std::string hull_colour = "#a3322b";
  std::string deck_colour = "#9aa1a6";

  template <class V>
  void visit(V& v) {
    v.field("width_px", width_px, "px", "frame width (even, H.264 needs it)", int_in_range(16, 7680));
    v.field("height_px", height_px, "px", "frame height (even)", int_in_range(16, 4320));
    v.field("fps", fps, "1/s", "video playback rate; one video frame per results frame", in_range(0.1, 240));
    v.field("max_frames", max_frames, "-", "render only the first N results frames (0 = all)",
            int_in_range(0, 1 << 30));
    v.field("view", view, "-", "camera: chase (behind and above the vessel) or top (orthographic, north up)",
            one_of({"chase", "top"}));
    v.field("chase_distance_m", chase_distance_m, "m", "chase camera: horizontal distance behind the vessel",
            non_negative());
    v.field("chase_height_m", chase_height_m, "m", "chase camera: height above the water", positive());
    v.field("chase_pitch_deg", chase_pitch_deg, "deg", "chase camera: downward tilt of the line of sight",
            in_range(0, 90));
    v.field("fov_deg", fov_deg, "deg", "chase camera: vertical field of view", in_range(5, 120));
    v.field("top_width_m", top_width_m, "m", "top view: width of water across the frame", positive());
    v.field("view_distance_m", view_distance_m, "m", "chase view: far clip distance (floes beyond are not drawn)",
            positive());
    v.field("fog", fog, "-", "chase view: haze fading the far field into the sky");
    v.field("supersample", supersample, "-", "render at N x size and downsample (anti-aliasing, cost ~N^2)",
            int_in_range(1, 4));
    v.field("overlay", overlay, "-",
            "draw time, frame, speed and fracture events so far (and a scale bar in the top view)");
    v.field("floe_edges", floe_edges, "-", "outline the top face of each floe");
    v.field("sky_colour", sky_colour, "#rrggbb", "background above the horizon", hex_colour());
    v.field("water_colour", water_colour, "#rrggbb", "open water", hex_colour());
    v.field("floe_top_colour", floe_top_colour, "#rrggbb", "top face of the floes of the input field",
            hex_colour());
    v.field("floe_side_colour", floe_side_colour, "#rrggbb", "sides of the floes", hex_colour());
    v.field("bending_piece_colour", bending_piece_colour, "#rrggbb",
            "top face of pieces broken off by bending or radial fracture (darker per generation)", hex_colour());
    v.field("splitting_piece_colour", splitting_piece_colour, "#rrggbb",
            "top face of pieces of a split floe (darker per generation)", hex_colour());
    v.field("edge_colour", edge_colour, "#rrggbb", "floe outlines", hex_colour());
    v.field("hull_colour", hull_colour, "#rrggbb", "hull sides", hex_colour());
    v.field("deck_colour", deck_colour, "#rrggbb", "deck and other upward faces of the hull", hex_colour());
    if (width_px % 2 != 0) v.problem("width_px", "must be even (H.264 4:2:0), got " + std::to_string(width_px));
    if (height_px % 2 != 0) v.problem("height_px", "must be even (H.264 4:2:0), got " + std::to_string(height_px));
  }
};

}  // namespace floesim::render
