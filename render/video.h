// The render stage: results HDF5 -> one off-screen rendered frame per stored results frame -> H.264 MP4, plus a
// JSON sidecar (provenance, frame count). floesim-render is a thin main over render_video().
#pragma once
#include <filesystem>
#include <iosfwd>
#include <string>

#include <nlohmann/json.hpp>

#include "pipeline/results_io.h"
#include "render/render_options.h"

namespace floesim::render {

// Reads render.json strictly (errors name the file and the key).
RenderOptions read_render_options(const std::filesystem::path& config);

// What a run cost (printed by the executable, never written into artefacts: they must be reproducible).
struct RenderStats {
  size_t frames = 0;
  double render_ms_per_frame = 0;  // GL drawing, read-back, downsampling, overlay
  double encode_ms_per_frame = 0;  // H.264 encoding and muxing
  double floes_drawn_per_frame = 0;
  double floes_culled_per_frame = 0;
  std::string gl_renderer;
};

// Renders frames [0, min(frames, max_frames)) of `r` to `out_mp4` (must end in .mp4) and writes the sidecar
// <out without extension>.json holding `provenance`, the frame count and the playback speed. Both appear only when
// complete. `progress` (may be null) gets a line with the time left every 10 % of the frames (pipeline/progress.h).
RenderStats render_video(const Results& r, const RenderOptions& o, const std::filesystem::path& out_mp4,
                         const nlohmann::json& provenance, const std::string& source,
                         std::ostream* progress = nullptr);
// The stage: reads the config first (cheap errors first), then the results.
RenderStats render_video(const std::filesystem::path& results, const std::filesystem::path& config,
                         const std::filesystem::path& out_mp4, std::ostream* progress = nullptr);

// One frame as an image (PNG/JPEG by extension) for reports and for checking a look without encoding a video.
void render_still(const std::filesystem::path& results, const std::filesystem::path& config, size_t frame,
                  const std::filesystem::path& out_image);

}  // namespace floesim::render
