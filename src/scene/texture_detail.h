#pragma once
/// @file scene/texture_detail.h
/// @brief The texture detail a fixed set of views can show. A GPU samples a
/// texture at the mip level where one pixel covers about one texel; for a
/// known camera and image size (a `render`), the levels finer than the
/// finest any visible triangle reaches are never read. Engines stream
/// textures by this rule; `render` uses it to keep and upload only the
/// levels a frame shows (docs/render.md, "Textures a frame can show").

#include <vector>

#include "core/math.h"
#include "scene/pinhole_camera.h"
#include "scene/scene.h"

namespace lo {

/// The views whose texture detail is asked for.
struct TextureViews {
  /// A pinhole view and its image's size in pixels (supersampling
  /// included): `yfov` spans the height.
  struct Pinhole {
    PinholeCamera camera;
    int width = 0, height = 0;
  };
  std::vector<Pinhole> cameras;
  /// A cube map seen from `cubeCentre` (the reflection probe), `cubeFaceSize`
  /// texels per face side; none when 0.
  Vec3 cubeCentre;
  int cubeFaceSize = 0;
};

/// Per texture of a scene, how many mip levels may be left out.
struct TextureLevels {
  /// The views sample level `drawn[t]` and coarser of texture t, never a
  /// finer one (0: the full image is needed).
  std::vector<int> drawn;
  /// What may be left out of the scene's own copy: `drawn`, but 0 for the
  /// textures the lights and shadows read as well as the views (emissive
  /// maps, whose texels place the emitters' lights, and the alpha of masked
  /// and blended materials, which the shadow maps cut).
  std::vector<int> kept;
};

/// The levels `views` can sample, one level finer than the bound says for
/// the GPU's approximate level of detail. For each triangle that reads a
/// texture and lies at least partly in a view's frustum, the bound is
/// log2(rho / pi), rho the texels per scene unit along the triangle's
/// sparsest direction (UVs as the material's transform maps them) and pi
/// the pixels per scene unit at the triangle's nearest depth; a texture no
/// view sees goes down to 1 x 1. Anisotropic filtering reads no finer
/// level than the footprint's short axis, which the bound already uses.
TextureLevels textureLevelsFor(const Scene& scene, const TextureViews& views);

/// Texture `t` box-filtered down `levels` levels (each level half the size,
/// at least 1 texel; each texel the mean of its 2^levels x 2^levels block, in
/// linear light for sRGB colour, as GL builds mipmaps), in its own format. The file's
/// bytes (`encoded`) are dropped from a reduced texture: they no longer
/// describe its texels.
Texture reducedTexture(const Texture& t, int levels);

/// Each texture of `scene` reduced by `levels[t]` (`TextureLevels::kept`).
void reduceTextures(Scene& scene, const std::vector<int>& levels);

/// Frees every texture's texels and file bytes: each becomes empty (a
/// lookup reads white), its name and sampler kept. For a caller that has
/// handed the texels to the GPU and reads them no more.
void releaseTexels(Scene& scene);

}  // namespace lo
