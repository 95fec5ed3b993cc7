// Render benchmark: a synthetic transit through ~1000 floes (10-30 vertex outlines, non-convex, drifting and
// turning) with a ship-shaped hull, rendered to MP4 in every view (chase, top, side, split chase + top) with the
// load strip chart and the floes pushed by the hull coloured as in contact; prints ms per frame.
//
//   render_bench OUT_DIR [frames=200] [floes=1000] [width=1280] [height=720] [supersample=2]
//
// Writes OUT_DIR/bench_results.h5, OUT_DIR/<view>.mp4 and a still of the middle frame of each.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <random>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "pipeline/atomic_file.h"
#include "pipeline/results_io.h"
#include "render/scene.h"
#include "render/strip_chart.h"
#include "render/video.h"
#include "pipeline/geometry2d.h"

using namespace floesim;

namespace {


// Ship-shaped hull: waterplane outline with a parallel body and a rounded bow, extruded keel to deck, plus a
// deckhouse. Body frame: x forward, origin at the centre of mass on the waterline.
void add_hull(Results& r) {
  std::vector<std::pair<double, double>> ring;  // CCW seen from above
  const double L = 108, B = 25, bow = 35;
  for (int i = 0; i <= 12; ++i) {  // starboard side, stern to bow shoulder, then the bow curve, then port
    const double x = -L / 2 + (L - bow) * i / 12.0;
    ring.push_back({x, -B / 2});
  }
  for (int i = 1; i < 16; ++i) {
    const double a = -kPi / 2 + kPi * i / 16.0;
    ring.push_back({L / 2 - bow + bow * std::cos(a), B / 2 * std::sin(a)});
  }
  for (int i = 12; i >= 0; --i) ring.push_back({-L / 2 + (L - bow) * i / 12.0, B / 2});
  auto vtx = [&](double x, double y, double z) {
    r.hull_vertices_m.insert(r.hull_vertices_m.end(), {x, y, z});
    return static_cast<int32_t>(r.hull_vertices_m.size() / 3 - 1);
  };
  auto prism = [&](const std::vector<std::pair<double, double>>& outline, double z0, double z1) {
    const int32_t base = static_cast<int32_t>(r.hull_vertices_m.size() / 3);
    const int32_t n = static_cast<int32_t>(outline.size());
    for (auto [x, y] : outline) vtx(x, y, z0);
    for (auto [x, y] : outline) vtx(x, y, z1);
    double cx = 0, cy = 0;
    for (auto [x, y] : outline) cx += x / n, cy += y / n;
    const int32_t c0 = vtx(cx, cy, z0), c1 = vtx(cx, cy, z1);
    for (int32_t i = 0; i < n; ++i) {
      const int32_t j = (i + 1) % n;
      r.hull_triangles.insert(r.hull_triangles.end(), {base + i, base + j, base + n + j, base + i, base + n + j,
                                                       base + n + i, c1, base + n + i, base + n + j, c0, base + j,
                                                       base + i});
    }
  };
  prism(ring, -8, 6);
  prism({{-30, -8}, {-10, -8}, {-10, 8}, {-30, 8}}, 6, 18);  // deckhouse and bridge
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: render_bench OUT_DIR [frames=200] [floes=1000] [width=1280] [height=720] [supersample=2]\n";
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  const int frames = argc > 2 ? std::stoi(argv[2]) : 200;
  const int n_floes = argc > 3 ? std::stoi(argv[3]) : 1000;
  render::RenderOptions o;
  o.width_px = argc > 4 ? std::stoi(argv[4]) : 1280;
  o.height_px = argc > 5 ? std::stoi(argv[5]) : 720;
  o.supersample = argc > 6 ? std::stoi(argv[6]) : 2;
  if (frames < 1 || n_floes < 1) {
    std::cerr << "render_bench: frames and floes must be >= 1\n";
    return 2;
  }
  ensure_directory(dir);

  // Floes on a jittered grid ahead of and around the vessel (~70 % concentration), star-shaped outlines.
  Results r;
  std::mt19937_64 rng(20180611);
  std::uniform_real_distribution<double> u(0, 1);
  const int cols = static_cast<int>(std::ceil(std::sqrt(n_floes * 2.5)));
  const int rows = (n_floes + cols - 1) / cols;
  const double cell = 26;
  struct Floe {
    double x, y, yaw, drift_x, drift_y, spin;
  };
  std::vector<Floe> fl;
  r.floe_vertex_offset = {0};
  for (int k = 0; k < n_floes; ++k) {
    const int i = k % cols, j = k / cols;
    const double radius = cell * (0.32 + 0.22 * u(rng));
    const int nv = 10 + static_cast<int>(u(rng) * 21);
    for (int v = 0; v < nv; ++v) {
      const double a = 2 * kPi * (v + 0.3 * u(rng)) / nv;
      const double rr = radius * (0.7 + 0.3 * u(rng));
      r.floe_vertices_m.insert(r.floe_vertices_m.end(), {rr * std::cos(a), rr * std::sin(a)});
    }
    r.floe_vertex_offset.push_back(static_cast<int64_t>(r.floe_vertices_m.size() / 2));
    r.floe_id.push_back(k + 1);
    r.floe_thickness_m.push_back(0.6 + 1.2 * u(rng));
    // Floes of the input field that never break (the layout wants a lineage for every floe).
    r.floe_parent_id.push_back(-1);
    r.floe_generation.push_back(0);
    r.floe_origin_mode.push_back(kFractureNone);
    r.floe_created_s.push_back(0);
    r.floe_ended_s.push_back(std::numeric_limits<double>::infinity());
    fl.push_back({-150 + cell * i + 8 * (u(rng) - 0.5), (j - rows / 2.0) * cell + 8 * (u(rng) - 0.5),
                  2 * kPi * u(rng), 0.2 * (u(rng) - 0.5), 0.2 * (u(rng) - 0.5), 0.02 * (u(rng) - 0.5)});
  }
  add_hull(r);

  // The vessel steams east at 3 m/s with a slow yaw swing; floes in its way are pushed aside (crudely).
  const double dt_frame = 0.5, speed = 3.0;
  r.frame_offset = {0};
  for (int k = 0; k < frames; ++k) {
    const double t = k * dt_frame;
    const double vx = speed * t, vy = 2 * std::sin(0.02 * t), yaw = 0.03 * std::sin(0.05 * t);
    r.frame_time_s.push_back(t);
    r.state_body_id.push_back(0);
    r.state_position_m.insert(r.state_position_m.end(), {vx, vy, 0.0});
    r.state_quaternion.insert(r.state_quaternion.end(), {std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)});
    r.state_in_contact.push_back(0);
    for (int f = 0; f < n_floes; ++f) {
      double x = fl[f].x + fl[f].drift_x * t, y = fl[f].y + fl[f].drift_y * t;
      const double dx = x - vx, dy = y - vy;
      const bool pushed = dx > -60 && dx < 60 && std::abs(dy) < 25;
      if (pushed) y += (dy >= 0 ? 1 : -1) * (25 - std::abs(dy));
      r.state_in_contact.push_back(pushed ? 1 : 0);
      const double a = fl[f].yaw + fl[f].spin * t;
      r.state_body_id.push_back(f + 1);
      r.state_position_m.insert(r.state_position_m.end(), {x, y, 0.1});
      r.state_quaternion.insert(r.state_quaternion.end(), {std::cos(a / 2), 0, 0, std::sin(a / 2)});
    }
    r.frame_offset.push_back(static_cast<int64_t>(r.state_body_id.size()));
  }
  // Series: ten steps per frame (the strip chart bins them), a surge ice load of ~400 kN with a slow swell and
  // rare single-step spikes, as rigid contacts give.
  const int steps_per_frame = 10;
  for (int k = 0; k < frames * steps_per_frame; ++k)
    for (const auto& f : series_fields()) {
      std::vector<double> row(f.cols, 0.0);
      const double t = k * dt_frame / steps_per_frame;
      if (std::string(f.name) == "time_s") row[0] = t;
      if (std::string(f.name) == "ice_load")
        row[0] = -(4e5 + 1.5e5 * std::sin(0.2 * t) + 2e5 * (u(rng) - 0.5) + (u(rng) < 0.01 ? 2e6 : 0.0));
      auto& v = r.series[f.name];
      v.insert(v.end(), row.begin(), row.end());
    }
  write_results(dir / "bench_results.h5", r);

  {
    // The strip chart alone (its share of every view's time below): drawn into a grey frame at every frame time.
    const render::LoadStripChart strip(r, o, "bench");
    cv::Mat img(o.height_px, o.width_px, CV_8UC3, cv::Scalar(90, 90, 90));
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < frames; ++k) strip.draw(img, r.frame_time_s[static_cast<size_t>(k)]);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("strip chart alone: %.2f ms/frame (%zu steps of series)\n", 1000 * s / frames, r.steps());
  }
  for (const char* view : {"chase", "top", "side", "split"}) {
    o.view = view;
    const auto t0 = std::chrono::steady_clock::now();
    const auto st = render::render_video(r, o, dir / (std::string(view) + ".mp4"), nlohmann::json::object(), "bench");
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%-6s %dx%d ss%d, %d floes, %zu frames: %.1f ms/frame render + %.1f ms/frame encode "
                "(%.1f ms/frame wall incl. setup); %.0f floes drawn, %.0f culled per frame; %s\n",
                view, o.width_px, o.height_px, o.supersample, n_floes, st.frames, st.render_ms_per_frame,
                st.encode_ms_per_frame, 1000 * wall / st.frames, st.floes_drawn_per_frame,
                st.floes_culled_per_frame, st.gl_renderer.c_str());
    render::SceneRenderer scene(r, o, "bench");
    cv::Mat img;
    scene.render(static_cast<size_t>(frames / 2), img);
    AtomicFile png(dir / (std::string(view) + "_still.png"));
    cv::imwrite(png.tmp().string(), img);
    png.commit();
  }
  return 0;
}
