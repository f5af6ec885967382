#define GL_GLEXT_PROTOTYPES
#include "edge_blend.hpp"

#include <GL/gl.h>
#include <GL/glext.h>

namespace vrflow::viewer {

void applyBlendMask(const std::vector<std::uint8_t>& mask, int width, int height, int k) {
  // An alpha-only image drawn over the frame with dst = dst * src alpha; drawn downwards from
  // the top-left corner so the mask's rows run from the top.
  glPushAttrib(GL_ALL_ATTRIB_BITS);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_LIGHTING);
  glDisable(GL_STENCIL_TEST);
  glEnable(GL_BLEND);
  glBlendFunc(GL_ZERO, GL_SRC_ALPHA);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glWindowPos2i(0, height * k);
  glPixelZoom(static_cast<float>(k), -static_cast<float>(k));
  glDrawPixels(width, height, GL_ALPHA, GL_UNSIGNED_BYTE, mask.data());
  glPixelZoom(1.0f, 1.0f);
  glPopAttrib();
}

}  // namespace vrflow::viewer
