/// @file render/hud.cpp
/// @brief HudOverlay: stb_easy_font (Debian's libstb-dev) turns text into
/// quads; they are drawn as triangles with the HUD program.

#include "render/hud.h"

#include <algorithm>
#include <cstdint>
#include <cstddef>
#include <cstring>

#include "render/gl_resources.h"
#include "render/gl_util.h"

// stb_easy_font's functions are static: this file is its one user.
#include <stb_easy_font.h>

namespace lo {

namespace {

struct HudVertex {
  float x, y;
  uint8_t rgba[4];
};

constexpr float kMargin = 6.0f;        // pixels around the text
constexpr float kLineUnits = 10.0f;    // font units per line (7 tall + spacing)

/// stb_easy_font's quads (4 vertices of x, y, z, RGBA8 each) as triangles,
/// scaled and moved by `origin`.
void appendText(const std::string& text, float x, float y, float scale, const uint8_t rgba[4],
                std::vector<HudVertex>& out) {
  static thread_local std::vector<char> buffer(1 << 16);
  unsigned char colour[4] = {rgba[0], rgba[1], rgba[2], rgba[3]};
  const int quads = stb_easy_font_print(0, 0, const_cast<char*>(text.c_str()), colour, buffer.data(),
                                        int(buffer.size()));
  struct Corner {
    float x, y, z;
    uint8_t c[4];
  };
  const auto* corners = reinterpret_cast<const Corner*>(buffer.data());
  for (int q = 0; q < quads; ++q) {
    const Corner* k = corners + 4 * q;
    for (int i : {0, 1, 2, 0, 2, 3}) {
      out.push_back({x + k[i].x * scale, y + k[i].y * scale, {k[i].c[0], k[i].c[1], k[i].c[2], k[i].c[3]}});
    }
  }
}

void appendBox(float x0, float y0, float x1, float y1, const uint8_t rgba[4], std::vector<HudVertex>& out) {
  const HudVertex a{x0, y0, {rgba[0], rgba[1], rgba[2], rgba[3]}}, b{x1, y0, {rgba[0], rgba[1], rgba[2], rgba[3]}},
      c{x1, y1, {rgba[0], rgba[1], rgba[2], rgba[3]}}, d{x0, y1, {rgba[0], rgba[1], rgba[2], rgba[3]}};
  for (const HudVertex& v : {a, b, c, a, c, d}) out.push_back(v);
}

}  // namespace

struct HudOverlay::Impl {
  render_internal::GlProgram program{render_internal::buildProgram({"hud.vert", "hud.frag"})};
  render_internal::GlVertexArray vao = render_internal::GlVertexArray::create();
  render_internal::GlBuffer vbo = render_internal::GlBuffer::create();
  GLint viewport = glGetUniformLocation(program.get(), "viewport");

  Impl() {
    glBindVertexArray(vao.get());
    glBindBuffer(GL_ARRAY_BUFFER, vbo.get());
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(HudVertex), nullptr);
    glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(HudVertex),
                          reinterpret_cast<const void*>(offsetof(HudVertex, rgba)));
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glBindVertexArray(0);
    render_internal::checkGl("HUD set-up");
  }
};

HudOverlay::HudOverlay() : impl_(std::make_unique<Impl>()) {}
HudOverlay::~HudOverlay() = default;

void HudOverlay::extent(const std::vector<std::string>& lines, float scale, int& width, int& height) {
  int widest = 0;
  for (const std::string& line : lines) widest = std::max(widest, stb_easy_font_width(const_cast<char*>(line.c_str())));
  width = int(float(widest) * scale + 2 * kMargin);
  height = int(float(lines.size()) * kLineUnits * scale + 2 * kMargin);
}

void HudOverlay::draw(const std::vector<std::string>& lines, int width, int height, float scale) {
  if (lines.empty() || width <= 0 || height <= 0) return;
  std::vector<HudVertex> vertices;
  int boxW = 0, boxH = 0;
  extent(lines, scale, boxW, boxH);
  const uint8_t box[4] = {0, 0, 0, 170}, text[4] = {235, 235, 235, 255};
  appendBox(0, 0, float(boxW), float(boxH), box, vertices);
  for (size_t i = 0; i < lines.size(); ++i) {
    appendText(lines[i], kMargin, kMargin + float(i) * kLineUnits * scale, scale, text, vertices);
  }
  Impl& h = *impl_;
  glViewport(0, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glUseProgram(h.program.get());
  glUniform2f(h.viewport, float(width), float(height));
  glBindVertexArray(h.vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, h.vbo.get());
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(HudVertex)), vertices.data(),
               GL_STREAM_DRAW);
  glDrawArrays(GL_TRIANGLES, 0, GLsizei(vertices.size()));
  glBindVertexArray(0);
  glUseProgram(0);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  render_internal::checkGl("HUD draw");
}

RgbImage HudOverlay::drawOffscreen(const std::vector<std::string>& lines, int width, int height,
                                   float scale) {
  using namespace render_internal;
  GlTexture colour = GlTexture::create();
  glBindTexture(GL_TEXTURE_2D, colour.get());
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  GlFramebuffer fbo = GlFramebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, fbo.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colour.get(), 0);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  draw(lines, width, height, scale);
  std::vector<uint8_t> raw(size_t(width) * size_t(height) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, raw.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  checkGl("reading back the HUD");
  RgbImage image(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const uint8_t* p = raw.data() + (size_t(height - 1 - y) * size_t(width) + size_t(x)) * 4;
      for (int c = 0; c < 3; ++c) image.rgb[(size_t(y) * size_t(width) + size_t(x)) * 3 + size_t(c)] = p[c] / 255.0f;
    }
  }
  return image;
}

}  // namespace lo
