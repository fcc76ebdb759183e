#pragma once
// Internal GL helpers of src/render (not part of the stage's API): shader
// programs built from the embedded shaders/ files, with errors that name the file.

#include <glad/gl.h>

#include <string>
#include <vector>

namespace lo::render_internal {

/// Text of shaders/<name> compiled into the library, or nullptr.
const char* embeddedShader(const char* name);

/// Source of shaders/<name> as compiled: for fragment and compute shaders, the
/// text of shaders/octree_layout.h is inserted after the #version line so that
/// the C++ and GLSL layout functions are the same text. `defines` go there too
/// ("NAME VALUE" pairs become #define lines).
std::string shaderSource(const std::string& name, const std::vector<std::string>& defines = {});

/// Compiles and links the named shader files (stage from the extension:
/// .vert .frag .geom .comp). @throws GlError with the file name and the log.
GLuint buildProgram(const std::vector<std::string>& files,
                    const std::vector<std::string>& defines = {});

/// Every shader file the renderer ships, for the compile test.
std::vector<std::vector<std::string>> allPrograms();

/// Throws GlError naming `what` if glGetError() reports an error.
void checkGl(const char* what);

}  // namespace lo::render_internal
