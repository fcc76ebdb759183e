// Shader probes: the GLSL builds of the headers shared with C++ run on
// inputs (layout_probe.h, shader_probes.h), and the light block's GL layout.

#include "render/shader_probes.h"

#include <glad/gl.h>

#include "render/context.h"
#include "render/gl_resources.h"
#include "render/gl_util.h"
#include "render/layout_probe.h"

namespace lo {

using namespace render_internal;

namespace {

/// Draws `program` over a width x outRows RGBA32F target, with uInputs a
/// width x inRows RGBA32F texture of `inputs` (row-major) on unit 0, and
/// returns the target's texels, row-major. `setUniforms` runs with the
/// program in use.
template <class SetUniforms>
std::vector<float> runProbe(GLuint program, const std::vector<float>& inputs, int width, int inRows,
                            int outRows, const SetUniforms& setUniforms) {
  std::vector<float> out(size_t(width) * size_t(outRows) * 4);
  GlTexture input = GlTexture::create(), output = GlTexture::create();
  glBindTexture(GL_TEXTURE_2D, input.get());
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, inRows, 0, GL_RGBA, GL_FLOAT, inputs.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glBindTexture(GL_TEXTURE_2D, output.get());
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, outRows, 0, GL_RGBA, GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  GlFramebuffer fbo = GlFramebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, fbo.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, output.get(), 0);
  GLenum drawBuffer = GL_COLOR_ATTACHMENT0;
  glDrawBuffers(1, &drawBuffer);
  GlVertexArray vao = GlVertexArray::create();
  glBindVertexArray(vao.get());
  glViewport(0, 0, width, outRows);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(program);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, input.get());
  glUniform1i(glGetUniformLocation(program, "uInputs"), 0);
  setUniforms();
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, width, outRows, GL_RGBA, GL_FLOAT, out.data());
  glBindVertexArray(0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return out;
}

}  // namespace

std::vector<std::array<float, 4>> runLayoutProbe(LayoutProbe function,
                                                 const std::vector<std::array<float, 4>>& inputs) {
  const int n = int(inputs.size());
  std::vector<std::array<float, 4>> out(inputs.size());
  if (n == 0) return out;
  const GlProgram program(buildProgram({"render_fullscreen.vert", "render_layout_probe.frag"}));
  std::vector<float> texels(size_t(n) * 4);
  for (size_t i = 0; i < inputs.size(); ++i) {
    for (size_t c = 0; c < 4; ++c) texels[4 * i + c] = inputs[i][c];
  }
  const std::vector<float> result = runProbe(program.get(), texels, n, 1, 1, [&] {
    glUniform1i(glGetUniformLocation(program.get(), "uFunction"), int(function));
  });
  for (size_t i = 0; i < out.size(); ++i) {
    for (size_t c = 0; c < 4; ++c) out[i][c] = result[4 * i + c];
  }
  checkGl("layout probe");
  return out;
}

std::vector<BrdfProbeOutput> runBrdfProbe(const std::vector<BrdfProbeInput>& inputs) {
  const int n = int(inputs.size());
  std::vector<BrdfProbeOutput> out(inputs.size());
  if (n == 0) return out;
  const GlProgram program(buildProgram({"render_fullscreen.vert", "render_brdf_probe.frag"}));
  // Row r of the input texture holds texel r of every sample.
  std::vector<float> texels(size_t(n) * 20);
  auto put = [&](int row, size_t i, const Vec3& v, float w) {
    float* t = &texels[(size_t(row) * size_t(n) + i) * 4];
    t[0] = v.x;
    t[1] = v.y;
    t[2] = v.z;
    t[3] = w;
  };
  for (size_t i = 0; i < inputs.size(); ++i) {
    const BrdfProbeInput& in = inputs[i];
    put(0, i, in.n, in.metallic);
    put(1, i, in.v, in.roughness);
    put(2, i, in.l, in.transmission);
    put(3, i, in.baseColor, in.specularWeight);
    put(4, i, Vec3(in.dielectricF0, in.specular, 0), 0);
  }
  constexpr int kRows = 6;
  const std::vector<float> result = runProbe(program.get(), texels, n, 5, kRows, [] {});
  auto get = [&](int row, size_t i) {
    const float* t = &result[(size_t(row) * size_t(n) + i) * 4];
    return Vec3(t[0], t[1], t[2]);
  };
  for (size_t i = 0; i < out.size(); ++i) {
    out[i].cosWeighted = get(0, i);
    out[i].alpha = result[i * 4 + 3];
    out[i].diffuse = get(1, i);
    out[i].specular = get(2, i);
    out[i].environment = get(3, i);
    out[i].brdf = get(4, i);
    out[i].diffuseCos = get(5, i);
  }
  checkGl("BRDF probe");
  return out;
}

namespace {

GlProgram sceneProgramWithLights() {
  return GlProgram(buildProgram({"render_scene.vert", "render_scene.frag"}, {"LO_DIRECT_LIGHT"}));
}

}  // namespace

int lightBlockSize() {
  const GlProgram program = sceneProgramWithLights();
  const GLuint block = glGetUniformBlockIndex(program.get(), "LightBlock");
  if (block == GL_INVALID_INDEX) throw GlError("the scene program has no LightBlock");
  GLint size = 0;
  glGetActiveUniformBlockiv(program.get(), block, GL_UNIFORM_BLOCK_DATA_SIZE, &size);
  checkGl("querying the light block's size");
  return size;
}

std::vector<UniformLayout> lightBlockLayout(const std::vector<std::string>& names) {
  const GlProgram program = sceneProgramWithLights();
  std::vector<const char*> cNames;
  for (const std::string& name : names) cNames.push_back(name.c_str());
  std::vector<GLuint> indices(names.size(), GL_INVALID_INDEX);
  glGetUniformIndices(program.get(), GLsizei(names.size()), cNames.data(), indices.data());
  std::vector<UniformLayout> out(names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    out[i].name = names[i];
    if (indices[i] == GL_INVALID_INDEX) continue;
    glGetActiveUniformsiv(program.get(), 1, &indices[i], GL_UNIFORM_OFFSET, &out[i].offset);
    glGetActiveUniformsiv(program.get(), 1, &indices[i], GL_UNIFORM_ARRAY_STRIDE,
                          &out[i].arrayStride);
    glGetActiveUniformsiv(program.get(), 1, &indices[i], GL_UNIFORM_MATRIX_STRIDE,
                          &out[i].matrixStride);
  }
  checkGl("querying the light block's layout");
  return out;
}

}  // namespace lo
