#include "render/video.h"

#include <chrono>
#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/interrupt.h"
#include "pipeline/progress.h"
#include "pipeline/provenance.h"
#include "render/scene.h"

namespace floesim::render {

namespace fs = std::filesystem;

RenderOptions read_render_options(const fs::path& config) {
  return read_options<RenderOptions>(load_json_file(config), config.string());
}

RenderStats render_video(const Results& r, const RenderOptions& o, const fs::path& out_mp4,
                         const nlohmann::json& provenance, const std::string& source, std::ostream* progress) {
  using clock = std::chrono::steady_clock;
  FLOESIM_REQUIRE(out_mp4.extension() == ".mp4", out_mp4.string(),
                  ": the video must be an .mp4 file (H.264 in MP4 plays everywhere)");
  SceneRenderer scene(r, o, source);  // checks the results before any file is created
  const size_t n = o.max_frames > 0 ? std::min(r.frames(), static_cast<size_t>(o.max_frames)) : r.frames();
  ensure_directory(out_mp4.parent_path());

  AtomicFile video(out_mp4);
  cv::VideoWriter writer;
  writer.open(video.tmp().string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('a', 'v', 'c', '1'), o.fps,
              cv::Size(o.width_px, o.height_px));
  FLOESIM_REQUIRE(writer.isOpened(), out_mp4.string(),
                  ": OpenCV cannot open an H.264 ('avc1') video writer; it needs OpenCV's FFmpeg backend with "
                  "libx264, and a writable directory");

  RenderStats st;
  st.gl_renderer = scene.gl_renderer();
  double render_s = 0, encode_s = 0;
  cv::Mat frame;
  // SIGINT/SIGTERM stop the loop between two frames; the temporary video is then removed (pipeline/interrupt.h).
  InterruptPolling polling;
  const auto start = clock::now();
  ProgressLine line(progress, static_cast<long>(n));
  for (size_t k = 0; k < n; ++k) {
    check_interrupt();
    const auto t0 = clock::now();
    scene.render(k, frame);
    const auto t1 = clock::now();
    writer.write(frame);
    const auto t2 = clock::now();
    render_s += std::chrono::duration<double>(t1 - t0).count();
    encode_s += std::chrono::duration<double>(t2 - t1).count();
    st.floes_drawn_per_frame += static_cast<double>(scene.last_stats().floes_drawn);
    st.floes_culled_per_frame += static_cast<double>(scene.last_stats().floes_culled);
    const long done = static_cast<long>(k + 1);
    if (line.due(done))
      line.print(done, std::chrono::duration<double>(clock::now() - start).count(),
                 "frame " + std::to_string(done) + " / " + std::to_string(n));
  }
  const auto t3 = clock::now();
  writer.release();  // flushes the encoder's delayed frames and writes the MP4 index
  encode_s += std::chrono::duration<double>(clock::now() - t3).count();
  std::error_code ec;
  FLOESIM_REQUIRE(fs::file_size(video.tmp(), ec) > 0 && !ec, out_mp4.string(),
                  ": the encoder wrote nothing (disk full?)");
  {
    // The encoder does not report write errors: the file must read back with every frame (a full disk leaves an
    // MP4 without its index, which does not open).
    cv::VideoCapture back(video.tmp().string(), cv::CAP_FFMPEG);
    const double frames = back.isOpened() ? back.get(cv::CAP_PROP_FRAME_COUNT) : -1;
    if (frames != static_cast<double>(n))
      throw Error(out_mp4.string() + ": the encoded video does not read back (" +
                  (frames < 0 ? std::string("it does not open") : std::to_string(static_cast<long>(frames)) +
                   " frames of " + std::to_string(n)) + "): " + cut_short_reason(video.tmp().parent_path()));
  }

  st.frames = n;
  st.render_ms_per_frame = 1000 * render_s / static_cast<double>(n);
  st.encode_ms_per_frame = 1000 * encode_s / static_cast<double>(n);
  st.floes_drawn_per_frame /= static_cast<double>(n);
  st.floes_culled_per_frame /= static_cast<double>(n);

  const double playback = playback_speed(r, o.fps);
  // What a viewer must know that the video does not show: frames left out.
  nlohmann::json warnings = nlohmann::json::array();
  if (n < r.frames())
    warnings.push_back("the video shows the first " + std::to_string(n) + " of the run's " +
                       std::to_string(r.frames()) + " frames (render.max_frames), up to t = " +
                       std::to_string(std::lround(r.frame_time_s[n - 1])) + " s of " +
                       std::to_string(std::lround(r.frame_time_s.back())) + " s");
  nlohmann::json side = {
      {"video", out_mp4.filename().string()},
      {"codec", "H.264 (avc1), MP4"},
      {"frames", n},
      {"results_frames", r.frames()},
      {"width_px", o.width_px},
      {"height_px", o.height_px},
      {"fps", o.fps},
      {"duration_s", static_cast<double>(n) / o.fps},
      // Simulated seconds per second of video (fps x the frame interval): "plays 5x real time".
      {"playback_speed", std::isfinite(playback) ? nlohmann::json(playback) : nlohmann::json()},
      {"simulated_time_s", {r.frame_time_s.front(), r.frame_time_s[n - 1]}},
      {"view", o.view},
      {"split_views", o.view == "split" ? nlohmann::json(o.split_views) : nlohmann::json()},
      {"strip_chart", o.strip_chart},
      {"warnings", warnings},
      {"provenance", provenance},
  };
  fs::path sidecar = out_mp4;
  sidecar.replace_extension(".json");
  AtomicFile side_file(sidecar);
  write_file_checked(side_file.tmp(), side.dump(2) + "\n", sidecar);
  video.commit();
  side_file.commit();
  return st;
}

// The series the render draws (the strip chart's surge ice load, and its rigid and compliant parts for the filter of
// PHYSICS.md §5); the others stay on disk.
const std::set<std::string> kRenderSeries = {"time_s", "ice_load", "ice_load_rigid", "ice_load_compliant"};

RenderStats render_video(const fs::path& results, const fs::path& config, const fs::path& out_mp4,
                         std::ostream* progress) {
  const RenderOptions o = read_render_options(config);
  const Results r = read_results(results, true, kRenderSeries);
  const auto prov = make_provenance("floesim-render", {{"results", results}, {"config", config}}, options_to_json(o));
  return render_video(r, o, out_mp4, prov, results.string(), progress);
}

void render_still(const fs::path& results, const fs::path& config, size_t frame, const fs::path& out_image) {
  const RenderOptions o = read_render_options(config);
  const Results r = read_results(results, true, kRenderSeries);
  FLOESIM_REQUIRE(frame < r.frames(), results.string(), ": frame ", frame, " requested, the results hold ",
                  r.frames(), " frames (0 .. ", r.frames() - 1, ")");
  SceneRenderer scene(r, o, results.string());
  cv::Mat img;
  scene.render(frame, img);
  ensure_directory(out_image.parent_path());
  AtomicFile f(out_image);
  // Encoded in memory, then written with every write checked: imwrite does not report a full disk.
  std::vector<uchar> bytes;
  bool ok = false;
  try {
    ok = cv::imencode(out_image.extension().string(), img, bytes);
  } catch (const cv::Exception&) {
    ok = false;
  }
  FLOESIM_REQUIRE(ok, out_image.string(), ": cannot encode the image (use .png or .jpg)");
  write_file_checked(f.tmp(), std::string(bytes.begin(), bytes.end()), out_image);
  f.commit();
}

}  // namespace floesim::render
