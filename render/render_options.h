// Options of the render stage (floesim-render --config render.json): one strict struct, every field with a
// default, a unit and a line of doc (`floesim-render --help-config` prints the table).
#pragma once
#include <string>
#include <vector>

#include "pipeline/options.h"

namespace floesim::render {

// Accepts "#rrggbb" colours (what every colour picker gives).
Check<std::string> hex_colour();
// Parses "#rrggbb" into r, g, b in 0..1 (the string must have passed hex_colour()).
void parse_hex_colour(const std::string& s, float rgb[3]);
// Accepts exactly two camera views, each chase, top or side (the halves of a split frame).
Check<std::vector<std::string>> two_views();
// "auto" or a number >= 0 (> 0 if `strictly_positive`); the plot options use it too.
Check<Json> auto_or_number(bool strictly_positive);

struct RenderOptions {
  int width_px = 1280;                 // frame width (even: H.264 uses 4:2:0 chroma)
  int height_px = 720;                 // frame height (even)
  double fps = 25;                     // playback rate; one video frame per stored results frame
  int max_frames = 0;                  // render only the first N frames (0 = all)
  std::string view = "chase";          // chase: behind and above the vessel; top: orthographic, north up;
                                       // side: orthographic from abeam (starboard); split: two of them
  std::vector<std::string> split_views = {"chase", "top"};  // the two halves of the split view
  std::string split_layout = "side_by_side";                // or "stacked" (one above the other)
  double chase_distance_m = 170;       // horizontal distance of the camera behind the vessel's centre of mass
  double chase_height_m = 60;          // camera height above the water
  double chase_pitch_deg = 20;         // downward tilt of the line of sight
  double fov_deg = 45;                 // vertical field of view of the chase camera
  double top_width_m = 400;            // width of water shown across the frame in the top view
  double view_distance_m = 2500;       // chase view: far clip distance; floes beyond are not drawn
  double side_width_m = 200;           // side view: length of the scene shown across the frame
  double side_depth_m = 60;            // side view: floes whose centre lies within this distance across the
                                       // vessel's centre plane are drawn (a slab of the field, seen edge-on)
  double side_waterline = 0.4;         // side view: height of the waterline in the scene, from its top (0..1)
  bool strip_chart = true;             // the surge ice load strip chart in a band at the bottom of the frame
  double strip_height = 0.24;          // its band's height as a fraction of the frame height
  double strip_span_s = 0;             // time shown: 0 = the whole run; else a sliding window of this length
  Json strip_average_window_s = "auto";  // moving average, s; "auto": as floesim-plot (20 s rigid, 0.5 s else)
  Json strip_max_kN = "auto";          // top of the load axis, kN; "auto": fits the average, clips rare spikes
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
  bool show_contact = true;                        // floes pressed against the vessel in contact_colour
  std::string contact_colour = "#4fd86a";          // green: in contact with the vessel at this frame
  std::string hull_colour = "#a3322b";
  std::string deck_colour = "#9aa1a6";

  template <class V>
  void visit(V& v) {
    v.field("width_px", width_px, "px", "frame width (even, H.264 needs it)", int_in_range(16, 7680));
    v.field("height_px", height_px, "px", "frame height (even)", int_in_range(16, 4320));
    v.field("fps", fps, "1/s", "video playback rate; one video frame per results frame", in_range(0.1, 240));
    v.field("max_frames", max_frames, "-", "render only the first N results frames (0 = all)",
            int_in_range(0, 1 << 30));
    v.field("view", view, "-",
            "camera: chase (behind and above the vessel), top (orthographic, north up), side (orthographic from "
            "abeam, starboard, bow to the right, showing what goes under the hull) or split (split_views)",
            one_of({"chase", "top", "side", "split"}));
    v.field("split_views", split_views, "-", "split view: the two views shown, e.g. [\"chase\", \"top\"]",
            two_views());
    v.field("split_layout", split_layout, "-", "split view: side_by_side (left, right) or stacked (top, bottom)",
            one_of({"side_by_side", "stacked"}));
    v.field("chase_distance_m", chase_distance_m, "m", "chase camera: horizontal distance behind the vessel",
            non_negative());
    v.field("chase_height_m", chase_height_m, "m", "chase camera: height above the water", positive());
    v.field("chase_pitch_deg", chase_pitch_deg, "deg", "chase camera: downward tilt of the line of sight",
            in_range(0, 90));
    v.field("fov_deg", fov_deg, "deg", "chase camera: vertical field of view", in_range(5, 120));
    v.field("top_width_m", top_width_m, "m", "top view: width of water across the frame", positive());
    v.field("view_distance_m", view_distance_m, "m", "chase view: far clip distance (floes beyond are not drawn)",
            positive());
    v.field("side_width_m", side_width_m, "m", "side view: length of the scene across the frame", positive());
    v.field("side_depth_m", side_depth_m, "m",
            "side view: floes with their centre within this distance across the vessel's centre plane are drawn",
            positive());
    v.field("side_waterline", side_waterline, "-", "side view: height of the waterline, as a fraction from the top",
            in_range(0.05, 0.95));
    v.field("fog", fog, "-", "chase view: haze fading the far field into the sky");
    v.field("strip_chart", strip_chart, "-",
            "surge ice load strip chart at the bottom of the frame: raw, moving average, cursor at the frame time");
    v.field("strip_height", strip_height, "-", "strip chart band height as a fraction of the frame height",
            in_range(0.1, 0.5));
    v.field("strip_span_s", strip_span_s, "s",
            "strip chart time span: 0 = the whole run, else a sliding window of this length", non_negative());
    v.field("strip_average_window_s", strip_average_window_s, "s",
            "strip chart centred moving-average window, or \"auto\" (as floesim-plot: 20 s rigid, 0.5 s otherwise)",
            auto_or_number(true));
    v.field("strip_max_kN", strip_max_kN, "kN",
            "strip chart top of the load axis, or \"auto\" (fits the average; loads below 1 kN are shown in N)",
            auto_or_number(true));
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
    v.field("show_contact", show_contact, "-",
            "colour the top of floes pressed against the vessel at the frame (results /states/in_contact)");
    v.field("contact_colour", contact_colour, "#rrggbb", "top face of floes in contact with the vessel", hex_colour());
    v.field("hull_colour", hull_colour, "#rrggbb", "hull sides", hex_colour());
    v.field("deck_colour", deck_colour, "#rrggbb", "deck and other upward faces of the hull", hex_colour());
    if (width_px % 2 != 0) v.problem("width_px", "must be even (H.264 4:2:0), got " + std::to_string(width_px));
    if (height_px % 2 != 0) v.problem("height_px", "must be even (H.264 4:2:0), got " + std::to_string(height_px));
  }
};

}  // namespace floesim::render
