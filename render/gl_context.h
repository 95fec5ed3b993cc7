// The off-screen OpenGL context (Mesa OSMesa + llvmpipe, no display needed) and the GL entry points the renderer
// uses. Every GL function is loaded through OSMesaGetProcAddress instead of being linked by name: if another
// library drags libGL (glvnd) into the process, calls linked by name can land in a dispatch table with no context
// and silently draw nothing (black frames). Only this file and scene.cpp see GL.
#pragma once
#include <GL/gl.h>
#include <GL/osmesa.h>

#include <vector>

#include <opencv2/core.hpp>

namespace floesim::render {

// Fixed-function GL 1.x (compatibility profile): client vertex arrays, lights, fog. The X-macro keeps the list of
// names, the pointer declarations and the loader in one place; the types come from the prototypes in GL/gl.h
// (decltype only: nothing is linked by name).
#define FLOESIM_GL_FUNCTIONS(X)                                                                              \
  X(Clear) X(ClearColor) X(Enable) X(Disable) X(Viewport) X(MatrixMode) X(LoadMatrixd) X(EnableClientState)  \
  X(DisableClientState) X(VertexPointer) X(NormalPointer) X(ColorPointer) X(DrawArrays) X(Color4f)           \
  X(Lightfv) X(LightModelfv) X(LightModeli) X(ColorMaterial) X(ShadeModel) X(Fogi) X(Fogf) X(Fogfv)          \
  X(LineWidth) X(ReadPixels) X(PixelStorei) X(Finish) X(GetError) X(GetString) X(DepthFunc) X(DepthMask)     \
  X(Hint) X(ClipPlane) X(BlendFunc)

struct GlApi {
#define FLOESIM_GL_DECLARE(name) decltype(&::gl##name) name = nullptr;
  FLOESIM_GL_FUNCTIONS(FLOESIM_GL_DECLARE)
#undef FLOESIM_GL_DECLARE
};

// One OSMesa RGBA context with a 24-bit depth buffer, rendering into memory we own. Made current on
// construction (one context per thread at a time).
class OffscreenContext {
 public:
  OffscreenContext(int width_px, int height_px);  // Error if OSMesa cannot create it (names the size)
  ~OffscreenContext();
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  const GlApi& gl() const { return gl_; }
  int width() const { return width_; }
  int height() const { return height_; }
  // Finishes drawing and points `out` at the frame: 8-bit RGBA, the TOP row first (the context is made with
  // OSMESA_Y_UP = 0, so OSMesa lays rows out as images do). No copy: `out` aliases the buffer and is valid until
  // the next drawing. (A glReadPixels copy and a flip cost ~4 ms per frame at 2560 x 1440.)
  void frame_rgba_top_down(cv::Mat& out);
  const char* renderer() const;

 private:
  OSMesaContext ctx_ = nullptr;
  std::vector<unsigned char> buffer_;
  int width_, height_;
  GlApi gl_;
};

}  // namespace floesim::render
