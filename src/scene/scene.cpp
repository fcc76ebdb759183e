#include "scene/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "core/error.h"
#include "core/file.h"
#include "core/fnv.h"
#include "core/resources.h"
#include "image/image.h"
#include "scene/scene_files.h"
#include "scene/scene_internal.h"

namespace lo {

namespace {

/// Texel index i (any integer) of a row of n texels, wrapped by the glTF mode.
int wrapTexel(int i, int n, int mode) {
  if (mode == TextureSampler::kClampToEdge) return std::clamp(i, 0, n - 1);
  if (mode == TextureSampler::kMirroredRepeat) {
    const int period = 2 * n;
    int k = i % period;
    if (k < 0) k += period;
    return k < n ? k : period - 1 - k;
  }
  int k = i % n;
  return k < 0 ? k + n : k;
}

/// Texel coordinate (in texels, centres at .5) of u, kept finite and within
/// int range for any float u: repeating modes fold u by their period (2
/// covers both), clamping keeps it within a texture's width of [0, 1].
float texelCoordinate(float u, int n, int mode) {
  if (!std::isfinite(u)) return 0.5f;
  if (mode == TextureSampler::kClampToEdge) return std::clamp(u, -1.0f, 2.0f) * float(n);
  return (u - 2.0f * std::floor(0.5f * u)) * float(n);
}

/// `fetch(x, y)` filtered at (u, v) by `sampler`.
template <typename T, typename Fetch>
T sampleTexels(const TextureSampler& sampler, int width, int height, float u, float v,
               const Fetch& fetch) {
  const float x = texelCoordinate(u, width, sampler.wrapS);
  const float y = texelCoordinate(v, height, sampler.wrapT);
  if (sampler.magFilter == TextureSampler::kNearest) {
    return fetch(wrapTexel(int(std::floor(x)), width, sampler.wrapS),
                 wrapTexel(int(std::floor(y)), height, sampler.wrapT));
  }
  const float fx = x - 0.5f, fy = y - 0.5f;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  const float tx = fx - float(x0), ty = fy - float(y0);
  const int xa = wrapTexel(x0, width, sampler.wrapS), xb = wrapTexel(x0 + 1, width, sampler.wrapS);
  const int ya = wrapTexel(y0, height, sampler.wrapT), yb = wrapTexel(y0 + 1, height, sampler.wrapT);
  return (fetch(xa, ya) * (1.0f - tx) + fetch(xb, ya) * tx) * (1.0f - ty) +
         (fetch(xa, yb) * (1.0f - tx) + fetch(xb, yb) * tx) * ty;
}

}  // namespace

Texture Texture::fromLinear(int width, int height, const std::vector<Vec3>& rgb,
                            const std::vector<float>& alpha) {
  Texture t;
  t.width = width;
  t.height = height;
  t.format = TexelFormat::Float32;
  t.channels = alpha.empty() ? 3 : 4;
  t.floats.resize(rgb.size() * size_t(t.channels));
  for (size_t i = 0; i < rgb.size(); ++i) {
    float* out = t.floats.data() + i * size_t(t.channels);
    out[0] = rgb[i].x;
    out[1] = rgb[i].y;
    out[2] = rgb[i].z;
    if (t.channels == 4) out[3] = i < alpha.size() ? alpha[i] : 1.0f;
  }
  return t;
}

namespace {


}  // namespace

Vec3 Texture::texelAt(size_t i) const {
  const size_t c = size_t(channels);
  const size_t at = i * c;
  const size_t g = c >= 3 ? 1 : 0, b = c >= 3 ? 2 : 0;  // grey: R = G = B
  switch (format) {
    case TexelFormat::Unorm8: {
      const uint8_t* p = unorm8.data() + at;
      if (srgb) {
        const std::array<float, 256>& lut = srgb8ToLinear();
        return {lut[p[0]], lut[p[g]], lut[p[b]]};
      }
      constexpr float k = 1.0f / 255.0f;
      return {float(p[0]) * k, float(p[g]) * k, float(p[b]) * k};
    }
    case TexelFormat::Unorm16: {
      const uint16_t* p = unorm16.data() + at;
      constexpr float k = 1.0f / 65535.0f;
      const Vec3 v{float(p[0]) * k, float(p[g]) * k, float(p[b]) * k};
      return srgb ? Vec3{srgbToLinear(v.x), srgbToLinear(v.y), srgbToLinear(v.z)} : v;
    }
    case TexelFormat::Float32:
    default: {
      const float* p = floats.data() + at;
      return {p[0], p[g], p[b]};
    }
  }
}

float Texture::alphaAt(size_t i) const {
  if (!hasAlpha()) return 1.0f;
  const size_t at = i * size_t(channels) + size_t(channels) - 1;
  switch (format) {
    case TexelFormat::Unorm8: return float(unorm8[at]) * (1.0f / 255.0f);
    case TexelFormat::Unorm16: return float(unorm16[at]) * (1.0f / 65535.0f);
    case TexelFormat::Float32:
    default: return floats[at];
  }
}

Vec3 Texture::lookup(float u, float v) const {
  if (empty()) return Vec3{1, 1, 1};
  return sampleTexels<Vec3>(sampler, width, height, u, v,
                            [this](int x, int y) { return texel(x, y); });
}

float Texture::lookupAlpha(float u, float v) const {
  if (empty() || !hasAlpha()) return 1.0f;
  return sampleTexels<float>(sampler, width, height, u, v,
                             [this](int x, int y) { return texelAlpha(x, y); });
}

void TextureTransform::apply(float& u, float& v) const {
  const float c = std::cos(rotation), s = std::sin(rotation);
  const float su = scale[0] * u, sv = scale[1] * v;
  const float ru = c * su + s * sv, rv = -s * su + c * sv;
  u = ru + offset[0];
  v = rv + offset[1];
}

std::string Material::ToString() const {
  std::ostringstream os;
  os << "Material{" << name << " base " << baseColor.ToString() << " tex " << baseColorTexture
     << " metallic " << metallic << " roughness " << roughness << " emission "
     << emission.ToString() << " transmission " << transmission << " ior " << ior << "}";
  return os.str();
}

Vec3 Light::power(const Bounds3& sceneBounds) const {
  Vec3 radiant = color * intensity;
  switch (type) {
    case Type::Point:
      return radiant * (4.0f * kPi);
    case Type::Spot: {
      // Emitted uniformly inside the outer cone (the smooth falloff between the
      // inner and outer cone is ignored for the power estimate).
      float solidAngle = 2.0f * kPi * (1.0f - std::cos(outerConeAngle));
      return radiant * solidAngle;
    }
    case Type::Directional: {
      // The flux through the box's silhouette seen from the light: the
      // projected areas of the three faces the light enters through.
      const Vec3 d = normalize(direction), e = sceneBounds.extent();
      const float area = std::fabs(d.x) * e.y * e.z + std::fabs(d.y) * e.x * e.z +
                         std::fabs(d.z) * e.x * e.y;
      return radiant * area;
    }
  }
  return {};
}

void skyPixelOf(const Vec3& towards, int w, int h, int& x, int& y) {
  const float u = 0.5f + std::atan2(towards.x, -towards.z) / (2.0f * kPi);
  const float v = std::acos(std::clamp(towards.y, -1.0f, 1.0f)) / kPi;
  x = std::clamp(int(u * float(w)), 0, w - 1);
  y = std::clamp(int(v * float(h)), 0, h - 1);
}

Vec3 skyPixelDirection(float x, float y, int w, int h) {
  const float theta = kPi * y / float(h), phi = 2.0f * kPi * (x / float(w) - 0.5f);
  const float s = std::sin(theta);
  return {s * std::sin(phi), std::cos(theta), -s * std::cos(phi)};
}

float skyPixelSolidAngle(int y, int w, int h) {
  const float top = kPi * float(y) / float(h);
  const float bottom = std::min(kPi * float(y + 1) / float(h), 0.5f * kPi);
  if (!(bottom > top)) return 0.0f;
  return 2.0f * kPi / float(w) * (std::cos(top) - std::cos(bottom));
}

std::shared_ptr<const Texture> loadSkyImage(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext != ".exr" && ext != ".hdr") {
    throw InputError(path + ": a sky image must be linear radiance: .exr or .hdr, not '" + ext +
                     "'");
  }
  const RgbImage image = readImage(path);
  if (image.width < 2 || image.height < 2 || image.width > 16384 || image.height > 8192) {
    throw InputError(path + ": a sky image must be 2 x 2 to 16384 x 8192 texels, not " +
                     std::to_string(image.width) + " x " + std::to_string(image.height));
  }
  for (size_t i = 0; i < image.pixelCount(); ++i) {
    const Vec3 v{image.rgb[3 * i], image.rgb[3 * i + 1], image.rgb[3 * i + 2]};
    if (!isFinite(v) || v.x < 0 || v.y < 0 || v.z < 0) {
      throw InputError(path + ": texel " + std::to_string(i % size_t(image.width)) + ", " +
                       std::to_string(i / size_t(image.width)) + " is " + v.ToString() +
                       ": a radiance is finite and not negative");
    }
  }
  // Floats, 3 channels (RGB32F on the GPU): a sun's radiance needs them.
  auto texture = std::make_shared<Texture>();
  texture->name = path;
  texture->width = image.width;
  texture->height = image.height;
  texture->channels = 3;
  texture->format = TexelFormat::Float32;
  texture->floats = image.rgb;
  return texture;
}

std::string Sky::fingerprint() const {
  if (!present()) return "none";
  Fnv1a64 h;
  h.bytes(&radiance, sizeof radiance);
  if (image) {
    const Texture& t = *image;
    const int header[4] = {t.width, t.height, t.channels, int(t.format)};
    h.bytes(header, sizeof header);
    h.bytes(t.unorm8.data(), t.unorm8.size());
    h.bytes(t.unorm16.data(), t.unorm16.size() * sizeof(uint16_t));
    h.bytes(t.floats.data(), t.floats.size() * sizeof(float));
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h.value()));
  return text;
}

Vec3 Sky::radianceFrom(const Vec3& towards) const {
  if (!(towards.y > 0)) return {0, 0, 0};
  if (!image) return radiance;
  int x = 0, y = 0;
  skyPixelOf(towards, image->width, image->height, x, y);
  return radiance * image->texel(x, y);
}

Vec3 Sky::power(const Bounds3& box) const {
  if (box.empty()) return {0, 0, 0};
  const Vec3 e = box.extent();
  if (!image) {
    const float surface = 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
    return radiance * (0.5f * kPi * surface);
  }
  // The box's silhouette area seen from each texel's centre, times its
  // radiance and solid angle.
  const int w = image->width, h = image->height;
  Vec3d sum(0, 0, 0);
  for (int y = 0; y < h; ++y) {
    const float omega = skyPixelSolidAngle(y, w, h);
    if (!(omega > 0)) break;
    for (int x = 0; x < w; ++x) {
      const Vec3 d = skyPixelDirection(float(x) + 0.5f, float(y) + 0.5f, w, h);
      const float area = std::fabs(d.x) * e.y * e.z + std::fabs(d.y) * e.x * e.z +
                         std::fabs(d.z) * e.x * e.y;
      sum = sum + Vec3d(image->texel(x, y) * (area * omega));
    }
  }
  return radiance * Vec3{float(sum.x), float(sum.y), float(sum.z)};
}

std::string Light::ToString() const {
  static const char* names[] = {"point", "spot", "directional"};
  std::ostringstream os;
  os << "Light{" << names[int(type)] << " '" << name << "' pos " << position.ToString() << " dir "
     << direction.ToString() << " color " << color.ToString() << " intensity " << intensity << "}";
  return os.str();
}

Bounds3 Scene::bounds() const {
  Bounds3 b;
  for (uint32_t i : indices) b.extend(positions[i]);
  return b;
}

Vec3 Scene::tracingOrigin() const {
  const Bounds3 b = bounds();
  if (b.empty()) return {0, 0, 0};
  const Vec3 c = b.center();
  const float distance = std::max({std::fabs(c.x), std::fabs(c.y), std::fabs(c.z)});
  return distance > 4.0f * length(b.extent()) ? c : Vec3{0, 0, 0};
}

Scene Scene::translated(const Vec3& offset) const {
  Scene out = *this;
  for (Vec3& p : out.positions) p += offset;
  for (Light& light : out.lights) light.position += offset;
  for (Camera& camera : out.cameras) camera.position += offset;
  return out;
}

Vec3 Scene::faceNormal(size_t t) const {
  const Vec3& a = positions[indices[3 * t]];
  const Vec3& b = positions[indices[3 * t + 1]];
  const Vec3& c = positions[indices[3 * t + 2]];
  return normalize(cross(b - a, c - a));
}

float Scene::triangleArea(size_t t) const {
  const Vec3& a = positions[indices[3 * t]];
  const Vec3& b = positions[indices[3 * t + 1]];
  const Vec3& c = positions[indices[3 * t + 2]];
  return 0.5f * length(cross(b - a, c - a));
}

bool Scene::texcoord(size_t t, float b1, float b2, int texCoord, const TextureTransform& transform,
                     float& u, float& v) const {
  const std::vector<float>& uv = texCoord == 1 ? texcoords1 : texcoords0;
  if (uv.size() != 2 * positions.size()) return false;
  float b0 = 1.0f - b1 - b2;
  uint32_t i0 = indices[3 * t], i1 = indices[3 * t + 1], i2 = indices[3 * t + 2];
  u = b0 * uv[2 * i0] + b1 * uv[2 * i1] + b2 * uv[2 * i2];
  v = b0 * uv[2 * i0 + 1] + b1 * uv[2 * i1 + 1] + b2 * uv[2 * i2 + 1];
  transform.apply(u, v);
  return true;
}

Vec3 Scene::albedo(size_t t, float b1, float b2) const {
  const Material& m = materials[size_t(triangleMaterial[t])];
  const Vec3 factor = m.baseColor * vertexColor(t, b1, b2);
  float u, v;
  if (m.baseColorTexture < 0 || !texcoord(t, b1, b2, m.baseColorTexCoord, m.baseColorTransform, u, v))
    return factor;
  return factor * textures[size_t(m.baseColorTexture)].lookup(u, v);
}

Vec3 Scene::vertexColor(size_t t, float b1, float b2, float* alpha) const {
  if (alpha) *alpha = 1.0f;
  if (colors.size() != 4 * positions.size()) return Vec3(1.0f);
  const float w[3] = {1.0f - b1 - b2, b1, b2};
  float c[4] = {0, 0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const float* corner = &colors[4 * size_t(indices[3 * t + size_t(k)])];
    for (int a = 0; a < 4; ++a) c[a] += w[k] * corner[a];
  }
  if (alpha) *alpha = c[3];
  return Vec3(c[0], c[1], c[2]);
}

float Scene::coverage(size_t t, float b1, float b2) const {
  const Material& m = materials[size_t(triangleMaterial[t])];
  if (m.alphaMode == AlphaMode::Opaque) return 1.0f;
  float vertexAlpha;
  vertexColor(t, b1, b2, &vertexAlpha);
  float alpha = m.baseAlpha * vertexAlpha;
  float u, v;
  if (m.baseColorTexture >= 0 &&
      texcoord(t, b1, b2, m.baseColorTexCoord, m.baseColorTransform, u, v)) {
    alpha *= textures[size_t(m.baseColorTexture)].lookupAlpha(u, v);
  }
  if (m.alphaMode == AlphaMode::Mask) return alpha >= m.alphaCutoff ? 1.0f : 0.0f;
  return std::clamp(alpha, 0.0f, 1.0f);
}

Vec3 Scene::shadingNormal(size_t t, float b1, float b2, const Vec3& geometric) const {
  Vec3 n = geometric;
  if (normals.size() == positions.size()) {
    const float b0 = 1.0f - b1 - b2;
    const Vec3 smooth = normals[indices[3 * t]] * b0 + normals[indices[3 * t + 1]] * b1 +
                        normals[indices[3 * t + 2]] * b2;
    if (lengthSquared(smooth) > 1e-12f) {
      n = normalize(smooth);
      if (dot(n, geometric) < 0) n = -n;
    }
  }
  const Material& m = materials[size_t(triangleMaterial[t])];
  if (m.normalTexture < 0) return n;
  float u, v, u0, v0, u1, v1, u2, v2;
  if (!texcoord(t, b1, b2, m.normalTexCoord, m.normalTransform, u, v)) return n;
  // The map's tangent-space normal, x and y scaled by normalTexture.scale.
  auto mappedNormal = [&] {
    Vec3 mapped = textures[size_t(m.normalTexture)].lookup(u, v) * 2.0f - Vec3{1, 1, 1};
    mapped.x *= m.normalScale;
    mapped.y *= m.normalScale;
    return mapped;
  };
  // The file's tangents (glTF TANGENT) where all three corners have one.
  if (tangents.size() == 4 * positions.size()) {
    const uint32_t i0 = indices[3 * t], i1 = indices[3 * t + 1], i2 = indices[3 * t + 2];
    const float w0 = tangents[4 * i0 + 3];
    if (w0 != 0 && tangents[4 * i1 + 3] != 0 && tangents[4 * i2 + 3] != 0) {
      const float b0 = 1.0f - b1 - b2;
      auto corner = [&](uint32_t i) {
        return Vec3{tangents[4 * i], tangents[4 * i + 1], tangents[4 * i + 2]};
      };
      // The vertex normal's own side: the frame follows the surface, then
      // turns with the normal to the side being shaded (as glTF viewers
      // negate t and b on back faces).
      const float side = normals.size() == positions.size() &&
                                 dot(normals[i0] * b0 + normals[i1] * b1 + normals[i2] * b2, n) < 0
                             ? -1.0f
                             : 1.0f;
      const Vec3 n0 = n * side;
      Vec3 tangent = corner(i0) * b0 + corner(i1) * b1 + corner(i2) * b2;
      tangent = tangent - n0 * dot(n0, tangent);
      if (lengthSquared(tangent) > 1e-20f) {
        tangent = normalize(tangent);
        const Vec3 bitangent = cross(n0, tangent) * w0;
        const Vec3 mapped = mappedNormal();
        const Vec3 out = (tangent * mapped.x + bitangent * mapped.y) * side + n * mapped.z;
        return lengthSquared(out) > 0 ? normalize(out) : n;
      }
    }
  }
  texcoord(t, 0, 0, m.normalTexCoord, m.normalTransform, u0, v0);
  texcoord(t, 1, 0, m.normalTexCoord, m.normalTransform, u1, v1);
  texcoord(t, 0, 1, m.normalTexCoord, m.normalTransform, u2, v2);
  // dp/du from the triangle's edges: e1 = du1 T + dv1 B', e2 = du2 T + dv2 B'.
  const Vec3 p0 = positions[indices[3 * t]];
  const Vec3 e1 = positions[indices[3 * t + 1]] - p0, e2 = positions[indices[3 * t + 2]] - p0;
  const float du1 = u1 - u0, dv1 = v1 - v0, du2 = u2 - u0, dv2 = v2 - v0;
  const float det = du1 * dv2 - du2 * dv1;
  if (!(std::fabs(det) > 1e-20f)) return n;
  Vec3 tangent = (e1 * dv2 - e2 * dv1) / det;
  tangent = tangent - n * dot(n, tangent);
  if (!(lengthSquared(tangent) > 1e-20f)) return n;
  tangent = normalize(tangent);
  const Vec3 bitangent = cross(n, tangent);
  const Vec3 mapped = mappedNormal();
  const Vec3 out = tangent * mapped.x + bitangent * mapped.y + n * mapped.z;
  return lengthSquared(out) > 0 ? normalize(out) : n;
}

void Scene::metallicRoughness(size_t t, float b1, float b2, float& metallic,
                              float& roughness) const {
  const Material& m = materials[size_t(triangleMaterial[t])];
  metallic = m.metallic;
  roughness = m.roughness;
  float u, v;
  if (m.metallicRoughnessTexture < 0 ||
      !texcoord(t, b1, b2, m.metallicRoughnessTexCoord, m.metallicRoughnessTransform, u, v))
    return;
  const Vec3 texel = textures[size_t(m.metallicRoughnessTexture)].lookup(u, v);
  roughness *= texel.y;
  metallic *= texel.z;
}

Vec3 Scene::emission(size_t t, float b1, float b2) const {
  const Material& m = materials[size_t(triangleMaterial[t])];
  float u, v;
  if (m.emissiveTexture < 0 || !texcoord(t, b1, b2, m.emissiveTexCoord, m.emissiveTransform, u, v))
    return m.emission;
  return m.emission * textures[size_t(m.emissiveTexture)].lookup(u, v);
}

void Scene::releaseTexels() {
  for (size_t i = 0; i < textures.size(); ++i) releaseTexels(i);
}

void Scene::releaseTexels(size_t index) {
  Texture& t = textures.at(index);
  Texture empty;
  empty.name = std::move(t.name);
  empty.sampler = t.sampler;
  t = std::move(empty);
}

Vec3 Scene::triangleEmission(size_t t) const {
  const Material& m = materials[size_t(triangleMaterial[t])];
  if (m.emissiveTexture < 0 || !m.isEmissive()) return m.emission;
  // 256 stratified points: the centroids of the 16 x 16 sub-triangles
  // (four in each of the emitter sampler's 64 cells).
  constexpr int kSplit = 16;
  Vec3 sum{0, 0, 0};
  int count = 0;
  for (int i = 0; i < kSplit; ++i) {
    for (int j = 0; j + i < kSplit; ++j) {
      // Upward sub-triangle (i, j) and, where it exists, the downward one.
      sum += emission(t, (i + 1.0f / 3.0f) / kSplit, (j + 1.0f / 3.0f) / kSplit);
      ++count;
      if (i + j + 1 < kSplit) {
        sum += emission(t, (i + 2.0f / 3.0f) / kSplit, (j + 2.0f / 3.0f) / kSplit);
        ++count;
      }
    }
  }
  return sum / float(count);
}

std::string Scene::ToString() const {
  std::ostringstream os;
  os << triangleCount() << " triangles, " << positions.size() << " vertices, " << materials.size()
     << " materials, " << lights.size() << " punctual lights, " << cameras.size()
     << " cameras, bounds " << bounds().ToString();
  return os.str();
}

Scene loadScene(const std::string& path, const std::string& skyMesh) {
  namespace fs = std::filesystem;
  const std::string ext = lowerExtension(path);
  bool gltf = ext == ".gltf" || ext == ".glb";
  if (!gltf && ext != ".obj") {
    scene_internal::fail(path, "unknown extension '" + ext + "' (expected .gltf, .glb or .obj)");
  }
  std::error_code ec;
  if (!fs::exists(path, ec)) scene_internal::fail(path, "missing file (not found)");
  requireRegularFile(path, "the scene");
  // The files as the file system has them before the read and after the
  // hash: a file written meanwhile would make a scene of both versions, and
  // a hash of neither (H16-7-4).
  const std::vector<std::string> files = sceneFiles(path);
  const std::string before = sceneFilesStamp(files);
  Scene scene;
  try {
    if (gltf) {
      scene = scene_internal::loadGltf(path, skyMesh);
    } else {
      scene = scene_internal::loadObj(path);
      scene.sourcePath = path;
      if (!skyMesh.empty()) skyFromMaterial(scene, skyMesh);
    }
  } catch (const std::bad_alloc&) {
    scene_internal::fail(path, "out of memory while loading (corrupt sizes?)");
  }
  scene.sourcePath = path;
  scene.contentHash = sceneContentHash(path, files);
  if (sceneFilesStamp(files) != before) {
    scene_internal::fail(path,
                         "a file of the scene was written while it was read: read it again "
                         "once the writer is done");
  }
  scene_internal::validateScene(scene);
  scene_internal::dropRepeatedTriangles(scene);
  return scene;
}

namespace scene_internal {

void fail(const std::string& path, const std::string& problem) {
  throw InputError(path + ": " + problem);
}

std::string percentDecode(const std::string& uri) {
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  std::string out;
  out.reserve(uri.size());
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      out.push_back(char(hex(uri[i + 1]) * 16 + hex(uri[i + 2])));
      i += 2;
    } else {
      out.push_back(uri[i]);
    }
  }
  return out;
}

std::string resolveInsideFolder(const std::string& scenePath, const std::string& baseDir,
                                const std::string& uri, const std::string& what) {
  namespace fs = std::filesystem;
  if (uri.empty()) fail(scenePath, what + " has an empty uri");
  if (uri.find('\0') != std::string::npos) fail(scenePath, what + " uri contains a NUL byte");
  bool absolute = uri[0] == '/' || uri[0] == '\\' || (uri.size() > 1 && uri[1] == ':');
  bool dotdot = false;
  size_t start = 0;
  while (start <= uri.size()) {
    size_t end = uri.find_first_of("/\\", start);
    if (end == std::string::npos) end = uri.size();
    if (uri.compare(start, end - start, "..") == 0 && end - start == 2) dotdot = true;
    start = end + 1;
  }
  if (absolute || dotdot) {
    fail(scenePath, what + " uri '" + uri +
                        "' is outside the scene folder (absolute paths and '..' are rejected)");
  }
  fs::path base = baseDir.empty() ? fs::path(".") : fs::path(baseDir);
  fs::path full = base / fs::path(uri);
  // A symlink inside the folder may still point outside it: compare the
  // resolved paths too.
  std::error_code ec1, ec2;
  fs::path canonBase = fs::weakly_canonical(base, ec1);
  fs::path canonFull = fs::weakly_canonical(full, ec2);
  if (!ec1 && !ec2) {
    auto b = canonBase.begin(), f = canonFull.begin();
    for (; b != canonBase.end() && f != canonFull.end(); ++b, ++f) {
      if (b->empty()) continue;
      if (*b != *f) break;
    }
    if (b != canonBase.end()) {
      fail(scenePath, what + " uri '" + uri + "' resolves outside the scene folder");
    }
  }
  return full.string();
}

std::string triangleBudgetProblem(uint64_t triangles) {
  const double bytes = double(triangles) * kSceneBytesPerTriangle;
  const size_t available = availableMemoryBytes();
  if (triangles <= (uint64_t(1) << 32) / 3 && !(available > 0 && bytes > 0.5 * double(available))) {
    return "";
  }
  return std::to_string(triangles) + " triangles (" +
         formatBytes(size_t(std::min(bytes, 1e18))) + " to hold), beyond " +
         (available > 0 ? "half the " + formatBytes(available) + " of memory available"
                        : std::string("32-bit indices"));
}

std::vector<unsigned char> readFileBytes(const std::string& scenePath, const std::string& file,
                                         const std::string& what) {
  const std::string problem = notRegularFile(file);
  if (problem == "missing") fail(scenePath, "missing " + what + " '" + file + "' (not found)");
  if (!problem.empty()) fail(scenePath, what + " '" + file + "' is " + problem + ", not a file");
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(scenePath, "cannot open " + what + " '" + file + "'");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  if (in.bad()) fail(scenePath, "cannot read " + what + " '" + file + "'");
  return bytes;
}

Texture decodeImage(const std::string& scenePath,
                    const std::shared_ptr<const std::vector<uint8_t>>& bytes,
                    const std::string& what, bool srgb) {
  StoredImage d;
  try {
    d = decodeStoredImage(bytes->data(), bytes->size());
  } catch (const InputError& e) {
    fail(scenePath, "unreadable image " + what + ": " + e.what());
  }
  Texture t;
  t.width = d.width;
  t.height = d.height;
  t.channels = d.channels;
  // Alpha is linear in glTF whatever the colour encoding (Texture::srgb
  // leaves it alone).
  t.srgb = srgb;
  if (!d.unorm16.empty()) {
    t.format = TexelFormat::Unorm16;
    t.unorm16 = std::move(d.unorm16);
  } else {
    t.format = TexelFormat::Unorm8;
    t.unorm8 = std::move(d.unorm8);
  }
  if (!d.mimeType.empty()) {
    t.encoded = bytes;
    t.mimeType = d.mimeType;
  }
  return t;
}

void decodeTextures(Scene& scene, const std::string& scenePath,
                    const std::vector<PendingTexture>& pending) {
  // From the images' headers, before any is decoded.
  double total = 0, largest = 0;
  const PendingTexture* largestOne = nullptr;
  for (const PendingTexture& p : pending) {
    const double bytes = double(storedImageBytes(p.bytes->data(), p.bytes->size()));
    total += bytes;
    if (bytes > largest) {
      largest = bytes;
      largestOne = &p;
    }
  }
  // One texture alone: decodeImage's own check, which counts its working copies too.
  const size_t available = pending.size() > 1 ? availableMemoryBytes() : 0;
  if (available > 0 && total > 0.5 * double(available)) {
    fail(scenePath, "its " + std::to_string(pending.size()) + " textures would take " +
                        formatBytes(size_t(total)) + " decoded (the largest, " +
                        largestOne->what + ", " + formatBytes(size_t(largest)) +
                        "), more than " + formatBytes(available / 2) + ", half the " +
                        formatBytes(available) + " of memory available");
  }
  for (const PendingTexture& p : pending) {
    Texture& t = scene.textures[size_t(p.index)];
    Texture decoded = decodeImage(scenePath, p.bytes, p.what, p.srgb);
    decoded.name = std::move(t.name);
    decoded.sampler = t.sampler;
    t = std::move(decoded);
  }
}

std::string formatLimit(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

namespace {

/// A factor glTF defines on [0, 1] (metallic, roughness, transmission, an
/// emissive or light colour channel): clamped into it, with a warning naming
/// `what`; not finite: refused.
void clampUnit(Scene& scene, float& value, const std::string& what) {
  if (!std::isfinite(value)) fail(scene.sourcePath, what + " is not a finite number");
  const float clamped = std::clamp(value, 0.0f, 1.0f);
  if (clamped != value) {
    scene.warnings.push_back(scene.sourcePath + ": " + what + " is " + formatLimit(value) +
                             ", outside [0, 1]: clamped to " + formatLimit(clamped));
    value = clamped;
  }
}

void clampUnit(Scene& scene, Vec3& value, const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    clampUnit(scene, value[c], what + " channel " + std::to_string(c));
  }
}

}  // namespace

void checkLightAndMaterialValues(Scene& scene) {
  // The ranges the bake can carry in float without overflow or negative
  // light (docs/scene.md, "Limits"): emission up to kMaxRadiance, light
  // intensities up to kMaxLightIntensity; glTF's [0, 1] factors clamped.
  for (Material& m : scene.materials) {
    const std::string name = "material '" + m.name + "'";
    clampUnit(scene, m.metallic, name + " metallic");
    clampUnit(scene, m.roughness, name + " roughness");
    clampUnit(scene, m.transmission, name + " transmission");
    clampUnit(scene, m.specular, name + " specular");
    for (int c = 0; c < 3; ++c) {
      float& e = m.emission[c];
      if (!std::isfinite(e) || e > kMaxRadiance) {
        fail(scene.sourcePath, name + " emits " + formatLimit(e) + " W/(m^2 sr) in channel " +
                                   std::to_string(c) + ", beyond " + formatLimit(kMaxRadiance) +
                                   " (emissive factor x strength)");
      }
      if (e < 0) {
        scene.warnings.push_back(scene.sourcePath + ": " + name + " has a negative emission (" +
                                 formatLimit(e) + " in channel " + std::to_string(c) +
                                 "): taken as 0");
        e = 0;
      }
    }
  }
  for (Light& light : scene.lights) {
    const std::string name = "light '" + light.name + "'";
    clampUnit(scene, light.color, name + " colour");
    if (!std::isfinite(light.intensity) || light.intensity < 0 ||
        light.intensity > kMaxLightIntensity) {
      fail(scene.sourcePath, name + " has intensity " + formatLimit(light.intensity) +
                                 ", outside [0, " + formatLimit(kMaxLightIntensity) +
                                 "] (cd or lx, as W/sr or W/m^2)");
    }
    // glTF asks 0 < outer <= pi/2 and 0 <= inner < outer. A spot of no cone
    // sends nothing (it was taken without a word, and dark); negative angles
    // lit the whole room (cos of a negative angle is that of a positive one).
    if (light.type == Light::Type::Spot &&
        !(light.outerConeAngle > 0 && std::isfinite(light.outerConeAngle))) {
      fail(scene.sourcePath, name + " has outerConeAngle " + formatLimit(light.outerConeAngle) +
                                 " (radians): a spot's cone must be wider than 0 and at most "
                                 "pi/2 (glTF: 0 < outerConeAngle <= pi/2)");
    }
    if (light.type == Light::Type::Spot && light.outerConeAngle > kPi / 2) {
      scene.warnings.push_back(scene.sourcePath + ": " + name + " has outerConeAngle " +
                               formatLimit(light.outerConeAngle) +
                               " (radians), beyond pi/2: clamped to pi/2");
      light.outerConeAngle = kPi / 2;
    }
    if (light.type == Light::Type::Spot && !(light.innerConeAngle >= 0)) {
      scene.warnings.push_back(scene.sourcePath + ": " + name + " has innerConeAngle " +
                               formatLimit(light.innerConeAngle) +
                               " (radians), below 0: clamped to 0");
      light.innerConeAngle = 0;
    }
    // glTF asks inner < outer; an inner cone beyond the outer one was drawn
    // by the renderer and the tracers each their own way.
    if (light.type == Light::Type::Spot && light.innerConeAngle > light.outerConeAngle) {
      scene.warnings.push_back(scene.sourcePath + ": " + name + " has innerConeAngle " +
                               formatLimit(light.innerConeAngle) + " beyond its outerConeAngle " +
                               formatLimit(light.outerConeAngle) + " (radians): clamped to " +
                               formatLimit(light.outerConeAngle));
      light.innerConeAngle = light.outerConeAngle;
    }
    const Vec3d world = scene.toWorld(light.position);
    const double reach = std::max({std::fabs(world.x), std::fabs(world.y), std::fabs(world.z)});
    if (!std::isfinite(reach) || reach > double(kMaxCoordinate)) {
      fail(scene.sourcePath, name + " lies at " + world.toVec3().ToString() + ", beyond " +
                                 formatLimit(kMaxCoordinate) + " scene units from the origin");
    }
  }
}

Vec3d RebaseBounds::origin() const {
  if (!(lower.x <= upper.x && lower.y <= upper.y && lower.z <= upper.z)) return {};
  const Vec3d centre = (lower + upper) * 0.5;
  const double distance = std::max({std::fabs(centre.x), std::fabs(centre.y), std::fabs(centre.z)});
  return distance > kRebaseDistance * length(upper - lower) ? centre : Vec3d{};
}

/// Cameras within the coordinates a scene may have (kMaxCoordinate), as
/// lights are: a camera at 1e19 would abort the tracers. A near plane
/// beyond the whole scene would clip all of it: the renderer leaves it out,
/// as the tracers (which have none), with a warning here.
void checkCameras(Scene& scene) {
  const Bounds3 box = scene.bounds();
  for (const Camera& c : scene.cameras) {
    const Vec3d w = scene.toWorld(c.position);
    const double reach = std::max({std::fabs(w.x), std::fabs(w.y), std::fabs(w.z)});
    if (!std::isfinite(reach) || reach > double(kMaxCoordinate)) {
      fail(scene.sourcePath, "camera '" + c.name + "' lies at " + w.toVec3().ToString() +
                                 ", beyond " + formatLimit(kMaxCoordinate) +
                                 " scene units from the origin");
    }
    double farthest = 0;
    for (int a = 0; a < 3; ++a) {
      const double d = std::max(std::fabs(double(c.position[a]) - box.lower[a]),
                                std::fabs(double(box.upper[a]) - c.position[a]));
      farthest += d * d;
    }
    farthest = std::sqrt(farthest);
    if (double(c.znear) >= farthest) {
      scene.warnings.push_back(scene.sourcePath + ": camera '" + c.name + "' has znear " +
                               formatLimit(c.znear) +
                               ", beyond the whole scene (its farthest point is " +
                               formatLimit(farthest) +
                               " scene units away): left out, as a near plane that would clip "
                               "everything");
    }
  }
}

/// Triangle sizes single precision can hold, and rays that leave small
/// parts where they are. A triangle wider than kMaxTriangleSpan has an area
/// that overflows a float (the Cornell box scaled by 1e11 was refused as
/// "emits non-finite power"). The tracers offset a ray from its surface by
/// kRayEpsilonScale of the scene's size (its diagonal and reach): beside a
/// ground far larger than the rest, that offset passes small parts by and
/// their light is lost (the Cornell box on a floor stretched 3e4 times lost
/// its indirect light without a word): warned.
void checkTriangleSizes(Scene& scene) {
  constexpr double kMaxTriangleSpan = 1e9;
  std::vector<float> longest;
  longest.reserve(scene.triangleCount());
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const Vec3& a = scene.positions[scene.indices[3 * t]];
    const Vec3& b = scene.positions[scene.indices[3 * t + 1]];
    const Vec3& c = scene.positions[scene.indices[3 * t + 2]];
    auto span = [](const Vec3& p, const Vec3& q) {
      const double x = double(p.x) - q.x, y = double(p.y) - q.y, z = double(p.z) - q.z;
      return std::sqrt(x * x + y * y + z * z);
    };
    const double edge = std::max({span(a, b), span(b, c), span(c, a)});
    if (edge > kMaxTriangleSpan) {
      fail(scene.sourcePath, "triangle " + std::to_string(t) + " spans " + formatLimit(edge) +
                                 " scene units, beyond " + formatLimit(kMaxTriangleSpan) +
                                 ": its area overflows single precision; give the scene in "
                                 "larger units (a node scale)");
    }
    if (edge > 0) longest.push_back(float(edge));  // a point of a triangle draws nothing
  }
  const Bounds3 box = scene.bounds();
  if (longest.empty() || box.empty()) return;
  // A quarter of the triangles, not half: twenty large ground quads beside
  // a room's 32 triangles hid the room from a median (H12-5-34).
  auto quarter = longest.begin() + ptrdiff_t(longest.size() / 4);
  std::nth_element(longest.begin(), quarter, longest.end());
  // The offset in the tracers' frame (centred on the scene: its reach is
  // half its size), as photon_map.cpp and path_tracer.cpp take it.
  const double diagonal = double(length(box.extent()));
  const double offset = double(kRayEpsilonScale) * 1.5 * diagonal;
  // Or a small part among many large triangles: 2% of them narrower than
  // the offset itself (the living room of ../shared has 1.25%, slivers).
  const size_t narrower = size_t(
      std::count_if(longest.begin(), longest.end(), [&](float e) { return double(e) < offset; }));
  if (offset > 0.1 * double(*quarter) || double(narrower) >= 0.02 * double(longest.size())) {
    scene.warnings.push_back(
        scene.sourcePath + ": the scene spans " + formatLimit(diagonal) +
        " scene units (its box's diagonal) while a quarter of its triangles are under " +
        formatLimit(*quarter) + " across and " + std::to_string(narrower) + " of " +
        std::to_string(longest.size()) + " under " + formatLimit(offset) +
        ": rays leave a surface about " + formatLimit(offset) +
        " units off it (1e-5 of the scene's size, for single precision), and light between "
        "small parts is lost. Leave out or cut the large parts (a ground far wider than the "
        "rest)");
  }
}

void validateScene(Scene& scene) {
  if (scene.triangleCount() == 0) fail(scene.sourcePath, "no triangles in the scene");
  checkSkyRadiance(scene.sky, scene.sourcePath);
  checkSceneIndices(scene);
  // Coordinates the tracers can hold: Embree and the bake work in single
  // precision, in a frame centred on the scene; beyond kMaxCoordinate a
  // float has not a millimetre left (docs/scene.md, "Limits").
  const double originReach =
      std::max({std::fabs(scene.origin.x), std::fabs(scene.origin.y), std::fabs(scene.origin.z)});
  for (size_t i = 0; i < scene.positions.size(); ++i) {
    const Vec3& p = scene.positions[i];
    if (std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) + originReach >
        double(kMaxCoordinate)) {
      const Vec3d w = scene.toWorld(p);
      fail(scene.sourcePath, "vertex " + std::to_string(i) + " lies at " +
                                 Vec3{float(w.x), float(w.y), float(w.z)}.ToString() +
                                 ", beyond " + formatLimit(kMaxCoordinate) +
                                 " scene units from the origin (a node transform or unit "
                                 "scale out of range?)");
    }
  }
  // Energy conservation: a diffuse albedo above 1 creates light. glTF says
  // base colour factors lie in [0, 1]; larger ones are clamped, with a warning.
  for (Material& m : scene.materials) {
    const Vec3 clamped = min(max(m.baseColor, Vec3{0, 0, 0}), Vec3{1, 1, 1});
    if (!(clamped == m.baseColor)) {
      scene.warnings.push_back(scene.sourcePath + ": material '" + m.name + "' has base colour " +
                               m.baseColor.ToString() +
                               ", outside [0, 1] (an albedo above 1 creates energy): clamped to " +
                               clamped.ToString());
      m.baseColor = clamped;
    }
  }
  checkTriangleSizes(scene);
  checkLightAndMaterialValues(scene);
  checkCameras(scene);
  LO_CHECK(scene.normals.empty() || scene.normals.size() == scene.positions.size());
  LO_CHECK(scene.texcoords0.empty() || scene.texcoords0.size() == 2 * scene.positions.size());
  LO_CHECK(scene.texcoords1.empty() || scene.texcoords1.size() == 2 * scene.positions.size());
}

}  // namespace scene_internal

void checkSkyRadiance(const Sky& sky, const std::string& what) {
  // The brightest texel above the horizon (the rows Sky::power sums), per channel.
  Vec3 brightest{1, 1, 1};
  if (sky.image) {
    brightest = Vec3{0, 0, 0};
    const int w = sky.image->width, h = sky.image->height;
    for (int y = 0; y < h && skyPixelSolidAngle(y, w, h) > 0; ++y) {
      for (int x = 0; x < w; ++x) brightest = max(brightest, sky.image->texel(x, y));
    }
  }
  for (int c = 0; c < 3; ++c) {
    const double radiance = double(sky.radiance[c]) * double(brightest[c]);
    if (!(radiance >= 0 && radiance <= double(kMaxRadiance))) {
      throw InputError(what + ": the sky's radiance reaches " +
                       scene_internal::formatLimit(radiance) + " W/(m^2 sr) in channel " +
                       std::to_string(c) +
                       (sky.image ? " (its scale " + scene_internal::formatLimit(sky.radiance[c]) +
                                        " times its brightest texel above the horizon, " +
                                        scene_internal::formatLimit(brightest[c]) + ")"
                                  : "") +
                       ", outside [0, " + scene_internal::formatLimit(kMaxRadiance) + "]");
    }
  }
}

void checkSceneIndices(const Scene& scene) {
  const std::string where = scene.sourcePath.empty() ? "scene" : scene.sourcePath;
  if (scene.indices.size() % 3 != 0) {
    throw InputError(where + ": index count " + std::to_string(scene.indices.size()) +
                     " is not a multiple of 3");
  }
  const size_t triangles = scene.triangleCount();
  if (triangles >= size_t(UINT32_MAX)) {
    throw InputError(where + ": too many triangles (" + std::to_string(triangles) + ")");
  }
  for (size_t i = 0; i < scene.positions.size(); ++i) {
    if (!isFinite(scene.positions[i])) {
      throw InputError(where + ": non-finite vertex position (vertex " + std::to_string(i) +
                       " is " + scene.positions[i].ToString() + ")");
    }
  }
  for (size_t i = 0; i < scene.indices.size(); ++i) {
    if (scene.indices[i] >= scene.positions.size()) {
      throw InputError(where + ": triangle " + std::to_string(i / 3) + " has vertex index " +
                       std::to_string(scene.indices[i]) + " outside [0, " +
                       std::to_string(scene.positions.size()) + ")");
    }
  }
  if (scene.triangleMaterial.size() != triangles) {
    throw InputError(where + ": " + std::to_string(scene.triangleMaterial.size()) +
                     " material indices for " + std::to_string(triangles) + " triangles");
  }
  for (size_t t = 0; t < triangles; ++t) {
    const int32_t m = scene.triangleMaterial[t];
    if (m < 0 || size_t(m) >= scene.materials.size()) {
      throw InputError(where + ": triangle " + std::to_string(t) + " has material index " +
                       std::to_string(m) + " outside [0, " +
                       std::to_string(scene.materials.size()) + ")");
    }
  }
}

}  // namespace lo
