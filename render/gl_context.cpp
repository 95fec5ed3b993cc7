#include "render/gl_context.h"

#include <string>

#include "pipeline/error.h"

namespace floesim::render {

OffscreenContext::OffscreenContext(int width_px, int height_px) : width_(width_px), height_(height_px) {
  FLOESIM_REQUIRE(width_px > 0 && height_px > 0, "internal: off-screen size ", width_px, " x ", height_px);
  ctx_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
  FLOESIM_REQUIRE(ctx_ != nullptr, "cannot create an OSMesa off-screen GL context (is libOSMesa installed?)");
  buffer_.resize(static_cast<size_t>(width_px) * height_px * 4);
  if (!OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, width_px, height_px)) {
    OSMesaDestroyContext(ctx_);
    throw Error("cannot make an OSMesa context of " + std::to_string(width_px) + " x " + std::to_string(height_px) +
                " pixels current (too large? lower width_px/height_px or supersample)");
  }
  OSMesaPixelStore(OSMESA_Y_UP, 0);  // the first row of the buffer is the top of the image
  std::string missing;
#define FLOESIM_GL_LOAD(name)                                                                 \
  gl_.name = reinterpret_cast<decltype(gl_.name)>(OSMesaGetProcAddress("gl" #name));          \
  if (!gl_.name) missing += " gl" #name;
  FLOESIM_GL_FUNCTIONS(FLOESIM_GL_LOAD)
#undef FLOESIM_GL_LOAD
  if (!missing.empty()) {
    OSMesaDestroyContext(ctx_);
    throw Error("OSMesa does not provide the GL functions" + missing);
  }
}

OffscreenContext::~OffscreenContext() {
  if (ctx_) OSMesaDestroyContext(ctx_);
}

const char* OffscreenContext::renderer() const {
  const GLubyte* s = gl_.GetString(GL_RENDERER);
  return s ? reinterpret_cast<const char*>(s) : "?";
}

void OffscreenContext::frame_rgba_top_down(cv::Mat& out) {
  gl_.Finish();  // also copies the rendered image into buffer_ (OSMesa's front buffer)
  const GLenum err = gl_.GetError();
  FLOESIM_REQUIRE(err == GL_NO_ERROR, "OpenGL error 0x", std::hex, err, " while finishing the frame");
  out = cv::Mat(height_, width_, CV_8UC4, buffer_.data());
}

}  // namespace floesim::render
