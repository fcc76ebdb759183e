#include "render/gl_util.h"

#include <cstdio>

#include "core/resources.h"
#include "render/context.h"
#include "render/gl_resources.h"

namespace lo::render_internal {
namespace {

GLenum stageOf(const std::string& file) {
  auto ends = [&](const char* ext) {
    std::string e(ext);
    return file.size() >= e.size() && file.compare(file.size() - e.size(), e.size(), e) == 0;
  };
  if (ends(".vert")) return GL_VERTEX_SHADER;
  if (ends(".frag")) return GL_FRAGMENT_SHADER;
  if (ends(".geom")) return GL_GEOMETRY_SHADER;
  if (ends(".comp")) return GL_COMPUTE_SHADER;
  throw GlError("shader '" + file + "': unknown stage extension");
}

std::string infoLog(GLuint object, bool program) {
  GLint length = 0;
  if (program) {
    glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
  } else {
    glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
  }
  std::string log(size_t(length > 0 ? length : 1), '\0');
  if (program) {
    glGetProgramInfoLog(object, length, nullptr, log.data());
  } else {
    glGetShaderInfoLog(object, length, nullptr, log.data());
  }
  return log.c_str();
}

}  // namespace

namespace {

/// Replaces each line `#include "NAME"` of `text` (a file of shaders/) by the
/// embedded file NAME, followed by a #line directive that restores the
/// includer's numbering. One level: included files include nothing.
std::string expandIncludes(const std::string& name, const std::string& text) {
  std::string out;
  size_t pos = 0;
  int line = 1;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    const std::string l = text.substr(pos, end - pos);
    if (l.rfind("#include \"", 0) == 0) {
      const size_t close = l.find('"', 10);
      if (close == std::string::npos) throw GlError("shader '" + name + "': malformed " + l);
      const std::string file = l.substr(10, close - 10);
      const char* included = embeddedShader(file.c_str());
      if (!included) {
        throw GlError("shader '" + name + "' includes '" + file +
                      "', which is not among the embedded shaders/");
      }
      out += included;
      out += "\n#line " + std::to_string(line + 1) + "\n";
    } else {
      out += l + "\n";
    }
    pos = end + 1;
    ++line;
  }
  return out;
}

}  // namespace

std::string shaderSource(const std::string& name, const std::vector<std::string>& defines) {
  const char* text = embeddedShader(name.c_str());
  if (!text) throw GlError("shader '" + name + "' is not among the embedded shaders/");
  std::string source = expandIncludes(name, text);
  size_t versionEnd = source.find('\n', source.find("#version"));
  if (source.find("#version") == std::string::npos || versionEnd == std::string::npos) {
    throw GlError("shader '" + name + "': no #version line");
  }
  std::string inserted;
  for (const std::string& d : defines) inserted += "#define " + d + "\n";
  // Keep the shader's own line numbers in compiler messages.
  inserted += "#line 2\n";
  source.insert(versionEnd + 1, inserted);
  return source;
}

GLuint buildProgram(const std::vector<std::string>& files,
                    const std::vector<std::string>& defines) {
  GlProgram program = GlProgram::create();
  std::vector<GlShader> shaders;  // deleted on return: the linked program keeps its code
  for (const std::string& file : files) {
    std::string source = shaderSource(file, defines);
    shaders.emplace_back(glCreateShader(stageOf(file)));
    const GLuint shader = shaders.back().get();
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) throw GlError("shaders/" + file + " does not compile:\n" + infoLog(shader, false));
    glAttachShader(program.get(), shader);
  }
  glLinkProgram(program.get());
  GLint ok = 0;
  glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
  if (!ok) {
    std::string log = infoLog(program.get(), true);
    std::string names;
    for (const std::string& f : files) names += (names.empty() ? "" : " + ") + f;
    throw GlError("program " + names + " does not link:\n" + log);
  }
  return program.release();
}

std::vector<std::vector<std::string>> allPrograms() {
  return {{"render_scene.vert", "render_scene.frag"},
          {"render_shadow.vert", "render_shadow.geom", "render_shadow.frag"},
          {"render_depth.vert", "render_depth.frag"},
          {"render_fullscreen.vert", "render_layout_probe.frag"},
          {"render_fullscreen.vert", "render_brdf_probe.frag"},
          {"render_fullscreen.vert", "render_sky.frag"},
          {"atlas_bake.vert", "atlas_bake.geom", "atlas_bake.frag"},
          {"hud.vert", "hud.frag"}};
}

void checkGl(const char* what) {
  GLenum e = glGetError();
  if (e == GL_OUT_OF_MEMORY) {
    // The driver's memory, not a defect: said as memory (H16-2-1: `view`
    // under `ulimit -v` 900 MiB said "GL error 0x0505").
    throw GlError(std::string(what) +
                  ": out of memory in the GL driver (GL_OUT_OF_MEMORY): " + memoryShortfall());
  }
  if (e != GL_NO_ERROR) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04x", e);
    throw GlError(std::string(what) + ": GL error " + buf);
  }
}

}  // namespace lo::render_internal
