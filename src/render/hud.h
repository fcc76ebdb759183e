#pragma once
/// @file render/hud.h
/// @brief The view window's heads-up display: lines of text in the top-left
/// corner over a dark box (stb_easy_font's glyph quads, one draw), so that
/// frame time, mode, the octree's level and the progressive bake's progress
/// show in the window itself; `H` adds the keys.

#include <memory>
#include <string>
#include <vector>

#include "image/image.h"

namespace lo {

class HudOverlay {
 public:
  /// Needs a current GL 3.3+ context (compiles its program).
  HudOverlay();
  ~HudOverlay();
  HudOverlay(const HudOverlay&) = delete;
  HudOverlay& operator=(const HudOverlay&) = delete;

  /// Draws `lines` into the bound framebuffer of `width` x `height` pixels,
  /// over what is there (blended; depth test off), at `scale` pixels per
  /// font unit (glyphs are 7 units tall).
  void draw(const std::vector<std::string>& lines, int width, int height, float scale = 2.0f);

  /// The HUD alone over black in an offscreen `width` x `height` target, read
  /// back (row 0 at the top, values in [0, 1]): what the window shows in its
  /// corner, for tests and pictures.
  RgbImage drawOffscreen(const std::vector<std::string>& lines, int width, int height,
                         float scale = 2.0f);

  /// The HUD's box for `lines`, pixels: for tests and layout.
  static void extent(const std::vector<std::string>& lines, float scale, int& width, int& height);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lo
