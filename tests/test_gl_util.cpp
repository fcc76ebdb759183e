// The one OSMesa context of a test binary (test_util.h's osmesaContext): apart
// from the other fixtures so that only the tests that draw link lo_render.

#include <memory>

#include "render/context.h"
#include "test_util.h"

namespace lo::test {

GlContext* osmesaContext() {
  static std::unique_ptr<GlContext> context;
  static bool tried = false;
  if (!tried) {
    tried = true;
    try {
      context = createGlContext({GlBackend::OSMesa});
    } catch (const std::exception&) {
    }
  }
  if (context) context->makeCurrent();
  return context.get();
}

}  // namespace lo::test
