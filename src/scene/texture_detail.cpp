/// @file scene/texture_detail.cpp
/// @brief textureLevelsFor: the finest mip level each texture shows in a set
/// of views; reducedTexture: a texture's mip level as its own texture.

#include "scene/texture_detail.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "image/image.h"

namespace lo {
namespace {

/// A texture a material reads, through which UV set and transform.
struct Slot {
  int texture;
  int texCoord;
  const TextureTransform* transform;
};

std::vector<Slot> slotsOf(const Material& m) {
  std::vector<Slot> slots;
  auto add = [&slots](int texture, int texCoord, const TextureTransform& transform) {
    if (texture >= 0) slots.push_back({texture, texCoord, &transform});
  };
  add(m.baseColorTexture, m.baseColorTexCoord, m.baseColorTransform);
  add(m.normalTexture, m.normalTexCoord, m.normalTransform);
  add(m.metallicRoughnessTexture, m.metallicRoughnessTexCoord, m.metallicRoughnessTransform);
  add(m.occlusionTexture, m.occlusionTexCoord, m.occlusionTransform);
  add(m.emissiveTexture, m.emissiveTexCoord, m.emissiveTransform);
  return slots;
}

/// The most pixels per scene unit that the views give triangle (a, b, c):
/// each view's image height over the frustum's height at the triangle's
/// nearest depth (no surface shows larger there); 0 when no view sees it.
double pixelsPerUnit(const Vec3& a, const Vec3& b, const Vec3& c, const TextureViews& views) {
  double most = 0;
  const Vec3 corners[3] = {a, b, c};
  for (const TextureViews::Pinhole& v : views.cameras) {
    if (v.width <= 0 || v.height <= 0) continue;
    const PinholeCamera& cam = v.camera;
    const Vec3 right = normalize(cross(cam.forward, cam.up));
    const double tanHalf = std::tan(0.5 * double(cam.yfov));
    const double tanWide = tanHalf * double(v.width) / double(v.height);
    const double nearPlane = std::max(double(cam.znear), 1e-6);
    // Outside the frustum when every corner lies beyond one of its planes.
    int behind = 0, left = 0, rightOut = 0, below = 0, above = 0;
    double nearest = std::numeric_limits<double>::infinity();
    for (const Vec3& p : corners) {
      const Vec3 d = p - cam.eye;
      const double x = dot(d, right), y = dot(d, cam.up), z = dot(d, cam.forward);
      behind += z < nearPlane;
      left += x < -z * tanWide;
      rightOut += x > z * tanWide;
      below += y < -z * tanHalf;
      above += y > z * tanHalf;
      nearest = std::min(nearest, z);
    }
    if (behind == 3 || left == 3 || rightOut == 3 || below == 3 || above == 3) continue;
    const double depth = std::max(nearest, nearPlane);
    most = std::max(most, double(v.height) / (2.0 * depth * tanHalf));
  }
  if (views.cubeFaceSize > 0) {
    // A cube face of 90 degrees: a point at distance d lies at depth at
    // least d / sqrt(3) in the face that sees it; d at least the distance to
    // the triangle's bounding sphere.
    const Vec3 centroid = (a + b + c) / 3.0f;
    const double radius =
        std::max({length(a - centroid), length(b - centroid), length(c - centroid)});
    const double distance = std::max(double(length(centroid - views.cubeCentre)) - radius, 0.0);
    const double depth = std::max(distance / std::sqrt(3.0), 1e-6);
    most = std::max(most, double(views.cubeFaceSize) / (2.0 * depth));
  }
  return most;
}

/// Texels per scene unit on triangle t for texture `tex` read through
/// `slot`: the square root of its texel area over its scene area (the
/// geometric mean of its densest and sparsest directions); 0 when the UVs
/// or the triangle are degenerate.
double texelsPerUnit(const Scene& scene, size_t t, const Texture& tex, const Slot& slot) {
  const std::vector<float>& uv = slot.texCoord == 1 ? scene.texcoords1 : scene.texcoords0;
  if (uv.size() != 2 * scene.positions.size()) return 0;
  double s[3][2];
  for (int k = 0; k < 3; ++k) {
    const uint32_t v = scene.indices[3 * t + size_t(k)];
    float u = uv[2 * v], w = uv[2 * v + 1];
    slot.transform->apply(u, w);
    s[k][0] = double(u) * tex.width;
    s[k][1] = double(w) * tex.height;
  }
  const double t1[2] = {s[1][0] - s[0][0], s[1][1] - s[0][1]};
  const double t2[2] = {s[2][0] - s[0][0], s[2][1] - s[0][1]};
  const double det = t1[0] * t2[1] - t1[1] * t2[0];
  if (!(std::fabs(det) > 1e-12)) return 0;
  const Vec3& p0 = scene.positions[scene.indices[3 * t]];
  const Vec3 e1 = scene.positions[scene.indices[3 * t + 1]] - p0;
  const Vec3 e2 = scene.positions[scene.indices[3 * t + 2]] - p0;
  // J = [e1 e2] [t1 t2]^-1: scene offset per texel offset.
  double j1[3], j2[3];
  for (int a = 0; a < 3; ++a) {
    j1[a] = (double(e1[a]) * t2[1] - double(e2[a]) * t1[1]) / det;
    j2[a] = (double(e2[a]) * t1[0] - double(e1[a]) * t2[0]) / det;
  }
  double g11 = 0, g12 = 0, g22 = 0;
  for (int a = 0; a < 3; ++a) {
    g11 += j1[a] * j1[a];
    g12 += j1[a] * j2[a];
    g22 += j2[a] * j2[a];
  }
  // det(J^T J) is the squared scene area per texel area.
  const double areaRatio = std::sqrt(std::max(g11 * g22 - g12 * g12, 0.0));
  return areaRatio > 0 && std::isfinite(areaRatio) ? 1.0 / std::sqrt(areaRatio) : 0.0;
}

int coarsestLevel(const Texture& t) {
  int level = 0;
  while ((std::max(t.width, t.height) >> level) > 1) ++level;
  return level;
}

/// `levels` levels down in one pass: each texel the mean of a block of
/// 2^levels x 2^levels (the last row and column of blocks reach the image's
/// edge), in linear light (Texture::texelAt decodes sRGB colour), stored
/// back in the texture's format.
Texture reduced(const Texture& t, int levels) {
  Texture out;
  out.name = t.name;
  out.sampler = t.sampler;
  out.channels = t.channels;
  out.format = t.format;
  out.srgb = t.srgb;
  out.width = std::max(1, t.width >> levels);
  out.height = std::max(1, t.height >> levels);
  const int block = 1 << levels;
  const int c = t.channels;
  const size_t values = out.texelCount() * size_t(c);
  switch (t.format) {
    case TexelFormat::Unorm8:
      out.unorm8.resize(values);
      break;
    case TexelFormat::Unorm16:
      out.unorm16.resize(values);
      break;
    default:
      out.floats.resize(values);
      break;
  }
  auto store = [&out, &t](size_t at, double linear, bool colour) {
    const double v = colour && t.srgb ? double(linearToSrgb(float(linear))) : linear;
    switch (t.format) {
      case TexelFormat::Unorm8:
        out.unorm8[at] = uint8_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
        break;
      case TexelFormat::Unorm16:
        out.unorm16[at] = uint16_t(std::lround(std::clamp(v, 0.0, 1.0) * 65535.0));
        break;
      default:
        out.floats[at] = float(linear);
        break;
    }
  };
  for (int y = 0; y < out.height; ++y) {
    const int y0 = std::min(y * block, t.height - 1);
    const int y1 = y == out.height - 1 ? t.height : std::min((y + 1) * block, t.height);
    for (int x = 0; x < out.width; ++x) {
      const int x0 = std::min(x * block, t.width - 1);
      const int x1 = x == out.width - 1 ? t.width : std::min((x + 1) * block, t.width);
      double sum[3] = {0, 0, 0}, alpha = 0;
      for (int yy = y0; yy < y1; ++yy) {
        for (int xx = x0; xx < x1; ++xx) {
          const size_t i = size_t(yy) * size_t(t.width) + size_t(xx);
          const Vec3 v = t.texelAt(i);
          for (int k = 0; k < 3; ++k) sum[k] += double(v[k]);
          alpha += double(t.alphaAt(i));
        }
      }
      const double n = double((y1 - y0) * (x1 - x0));
      const size_t at = (size_t(y) * size_t(out.width) + size_t(x)) * size_t(c);
      const int colour = c >= 3 ? 3 : 1;  // grey keeps one colour channel
      for (int k = 0; k < colour; ++k) store(at + size_t(k), sum[k] / n, true);
      if (t.hasAlpha()) store(at + size_t(c - 1), alpha / n, false);
    }
  }
  return out;
}

}  // namespace

TextureLevels textureLevelsFor(const Scene& scene, const TextureViews& views) {
  const size_t textures = scene.textures.size();
  std::vector<double> finest(textures, std::numeric_limits<double>::infinity());
  std::vector<std::vector<Slot>> slots(scene.materials.size());
  for (size_t m = 0; m < scene.materials.size(); ++m) slots[m] = slotsOf(scene.materials[m]);
  std::vector<bool> lights(textures, false);  // read by the lights or the shadow maps too
  for (const Material& m : scene.materials) {
    if (m.emissiveTexture >= 0 && size_t(m.emissiveTexture) < textures)
      lights[size_t(m.emissiveTexture)] = true;
    if (m.hasAlpha() && m.baseColorTexture >= 0 && size_t(m.baseColorTexture) < textures)
      lights[size_t(m.baseColorTexture)] = true;
  }
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const int m = t < scene.triangleMaterial.size() ? scene.triangleMaterial[t] : -1;
    if (m < 0 || size_t(m) >= slots.size() || slots[size_t(m)].empty()) continue;
    const Vec3& a = scene.positions[scene.indices[3 * t]];
    const Vec3& b = scene.positions[scene.indices[3 * t + 1]];
    const Vec3& c = scene.positions[scene.indices[3 * t + 2]];
    const double pixels = pixelsPerUnit(a, b, c, views);
    if (!(pixels > 0)) continue;
    for (const Slot& slot : slots[size_t(m)]) {
      if (slot.texture < 0 || size_t(slot.texture) >= textures) continue;
      const Texture& tex = scene.textures[size_t(slot.texture)];
      if (tex.empty()) continue;
      // A triangle whose UVs are degenerate shows a line of texels, the same
      // at any level: it asks for none.
      const double texels = texelsPerUnit(scene, t, tex, slot);
      if (!(texels > 0)) continue;
      finest[size_t(slot.texture)] =
          std::min(finest[size_t(slot.texture)], std::log2(texels / pixels));
    }
  }
  TextureLevels out;
  out.drawn.resize(textures);
  out.kept.resize(textures);
  for (size_t i = 0; i < textures; ++i) {
    const int coarsest = scene.textures[i].empty() ? 0 : coarsestLevel(scene.textures[i]);
    // Half a level finer than the bound: GL lets a GPU take the footprint's
    // larger axis from its texel offsets' components, up to sqrt(2) short.
    const double level = std::isinf(finest[i]) ? double(coarsest) : std::floor(finest[i] - 0.5);
    out.drawn[i] = int(std::clamp(level, 0.0, double(coarsest)));
    out.kept[i] = lights[i] ? 0 : out.drawn[i];
  }
  return out;
}

Texture reducedTexture(const Texture& t, int levels) {
  if (levels <= 0 || t.empty()) return t;
  return reduced(t, std::min(levels, coarsestLevel(t)));
}

void reduceTextures(Scene& scene, const std::vector<int>& levels) {
  for (size_t i = 0; i < scene.textures.size() && i < levels.size(); ++i) {
    if (levels[i] > 0) scene.textures[i] = reducedTexture(scene.textures[i], levels[i]);
  }
}

void releaseTexels(Scene& scene) {
  for (Texture& t : scene.textures) {
    Texture empty;
    empty.name = std::move(t.name);
    empty.sampler = t.sampler;
    t = std::move(empty);
  }
}

}  // namespace lo
