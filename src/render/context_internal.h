#pragma once
// Back-end factories behind createGlContext (render/context.h). Each back end
// lives in its own source file so that OSMesa, EGL and GLFW headers never meet.

#include <memory>

#include "render/context.h"

namespace lo::render_internal {

std::unique_ptr<GlContext> createOsMesaContext(const GlContextParams& params);
std::unique_ptr<GlContext> createEglContext(const GlContextParams& params);
std::unique_ptr<GlContext> createGlfwContext(const GlContextParams& params);

}  // namespace lo::render_internal
