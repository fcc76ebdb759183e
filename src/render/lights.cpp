// The scene's lights for the scene shader: punctual lights, emissive
// triangles as area lights or VPLs, their shadow maps (cubes, spots, sun
// cascades). docs/render.md describes the shading.

#include "render/lights.h"

#include <glad/gl.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "core/resources.h"
#include "render/context.h"
#include "render/gl_util.h"

namespace lo::render_internal {
namespace {

constexpr int kMaxLights = shader::LO_MAX_LIGHTS;
constexpr int kMaxShadowLayers = shader::LO_MAX_SHADOW_LAYERS;
/// The most bytes the shadow maps take: 48 MiB, 24M texels of 16-bit
/// depth (2 B). The maps hold linear depth over the far plane
/// (render_shadow.frag), which 16 bits resolve to 1/65536, under the
/// lookup's bias of 1/size (one over the map's texels per side) at every
/// size up to 16384.
constexpr double kShadowMapBudget = 48.0 * 1024 * 1024;
constexpr int kCascades = shader::LO_SUN_CASCADES;
/// The most texels one drawing of every shadow map may cover, counted as the
/// scene's triangles projected into each layer: a scene of 5,000 copies of
/// a floor stacked under a lamp covered its maps 1,400 times over, 17.6 G
/// texels, and the software rasteriser took 85 s (H10-5-19). The scenes of
/// docs/results/public-scenes.md cover theirs 0.5 to 5.4 times over, at most
/// 91 M texels (the game level's 17 layers), a tenth of it. Beyond it the
/// maps are halved, down to kMinFillSize, and the report says why.
constexpr double kShadowFillBudget = 1024.0 * 1024 * 1024;
constexpr int kMinFillSize = 128;
/// At most this many triangle-layer pairs are projected to count the fill;
/// beyond, an even sample of the triangles, scaled up.
constexpr size_t kFillSamplePairs = size_t(1) << 22;
/// The sample of triangles the cascades' fill is counted on at each fit.
constexpr size_t kCascadeSampleTriangles = size_t(1) << 14;
/// The sample's triangles spread over the index range by a step coprime
/// with the count (a prime beyond any count): every second triangle, the
/// floors' halves all at odd indices, saw none of them (H13-5-3).
constexpr uint64_t kSampleStep = 2654435761u;

glm::vec3 toGlm(const Vec3& v) { return {v.x, v.y, v.z}; }
glm::vec4 toVec4(const Vec3& v, float w) { return {v.x, v.y, v.z, w}; }

/// Any unit vector orthogonal to unit d.
glm::vec3 perpendicular(const glm::vec3& d) {
  glm::vec3 a = std::fabs(d.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  return glm::normalize(glm::cross(d, glm::cross(a, d)));
}

/// A spot's shadow map: its outer cone and a little more, at most 172 degrees.
float spotShadowFov(const GpuLight& l) {
  return std::min(2.0f * std::acos(std::clamp(l.params[0], -1.0f, 1.0f)) + 0.05f, 3.0f);
}

/// The share of a layer that the triangle of clip-space corners `c` covers:
/// its part in front of the near plane (z >= -w), its area there, at most
/// the part of the layer its bounds span.
double coveredShare(const glm::vec4 (&c)[3]) {
  glm::vec4 kept[4];
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const glm::vec4& a = c[i];
    const glm::vec4& b = c[(i + 1) % 3];
    const float da = a.z + a.w, db = b.z + b.w;
    if (da >= 0) kept[n++] = a;
    if ((da >= 0) != (db >= 0) && n < 4) kept[n++] = a + (b - a) * (da / (da - db));
  }
  if (n < 3) return 0;
  double area2 = 0, lowX = 1, lowY = 1, highX = -1, highY = -1;
  for (int i = 0; i < n; ++i) {
    const glm::vec4& a = kept[i];
    const glm::vec4& b = kept[(i + 1) % n];
    if (!(a.w > 0) || !(b.w > 0)) return 0;
    const double ax = a.x / a.w, ay = a.y / a.w, bx = b.x / b.w, by = b.y / b.w;
    area2 += ax * by - bx * ay;
    lowX = std::min(lowX, ax);
    lowY = std::min(lowY, ay);
    highX = std::max(highX, ax);
    highY = std::max(highY, ay);
  }
  const double spanned = std::max(0.0, std::min(highX, 1.0) - std::max(lowX, -1.0)) *
                         std::max(0.0, std::min(highY, 1.0) - std::max(lowY, -1.0));
  return std::min(0.5 * std::fabs(area2), spanned) / 4.0;
}

/// How many times over the scene's triangles cover the shadow maps' first
/// `layers` layers, on average (the texels drawn per texel held).
double coveredTimesOver(const Scene& scene, const RenderSpace& space, const glm::mat4* matrices,
                        int layers) {
  const size_t triangles = scene.triangleCount();
  if (layers <= 0 || triangles == 0) return 0;
  const size_t pairs = triangles * size_t(layers);
  const size_t stride = (pairs + kFillSamplePairs - 1) / kFillSamplePairs;
  const size_t sampled = (triangles + stride - 1) / stride;
  double covered = 0;
  for (size_t s = 0; s < sampled; ++s) {
    const size_t t = sampledTriangle(s, sampled, triangles);
    glm::vec4 corner[3];
    for (int k = 0; k < 3; ++k) {
      corner[k] = toVec4(space.toRender(scene.positions[scene.indices[3 * t + size_t(k)]]), 1);
    }
    for (int layer = 0; layer < layers; ++layer) {
      const glm::vec4 clip[3] = {matrices[layer] * corner[0], matrices[layer] * corner[1],
                                 matrices[layer] * corner[2]};
      covered += coveredShare(clip);
    }
  }
  return covered * double(triangles) / double(sampled) / double(layers);
}

GpuLight punctualLight(const Light& light, const RenderSpace& space) {
  GpuLight l{};
  const Vec3 color = light.color * light.intensity;
  const int type = light.type == Light::Type::Point  ? shader::LO_LIGHT_POINT
                   : light.type == Light::Type::Spot ? shader::LO_LIGHT_SPOT
                                                     : shader::LO_LIGHT_DIRECTIONAL;
  l.positionType = toVec4(space.toRender(light.position), float(type));
  l.directionRange = toVec4(normalize(light.direction), light.range);
  l.colorFar = toVec4(color, 0);
  l.params = toVec4(Vec3(std::cos(light.outerConeAngle), std::cos(light.innerConeAngle), -1), 0);
  return l;
}

/// Why the lights do not fit in the shader's LO_MAX_LIGHTS, and what helps:
/// a flag where one lowers the count, the scene itself where its punctual
/// lights alone exceed it (no flag of `render` or `view` drops them).
InputError tooManyLights(const Scene& scene, size_t emitters, bool areaLights) {
  const std::string sceneSource = scene.sourcePath.empty() ? "the scene" : scene.sourcePath;
  const size_t punctual = scene.lights.size();
  const std::string most = std::to_string(kMaxLights);
  if (punctual > size_t(kMaxLights)) {
    return InputError(sceneSource + " has " + std::to_string(punctual) +
                      " punctual lights; the GL renderer draws at most " + most +
                      " lights: keep at most " + most +
                      " in the scene file (bake and reference take any number)");
  }
  const size_t left = size_t(kMaxLights) - punctual;
  const std::string room = std::to_string(left) + (left > 0 ? " or fewer" : "");
  const std::string what = std::to_string(punctual) + " punctual lights and " +
                           std::to_string(emitters) +
                           (areaLights ? " area lights (emissive triangles)" : " emitter lights");
  return InputError(sceneSource + " has " + what + ", more than the " + most +
                    " lights the GL renderer draws: " +
                    (areaLights ? "use --area-lights off with --emitter-lights " + room
                                : "use --emitter-lights " + room));
}

}  // namespace

int SceneLights::shadowLayersOf(int type) {
  if (type == shader::LO_LIGHT_DIRECTIONAL) return kCascades;
  return type == shader::LO_LIGHT_POINT || type == shader::LO_LIGHT_EMITTER ||
                 type == shader::LO_LIGHT_AREA
             ? 6
             : 1;
}

int SceneLights::layerCount() const {
  int layers = 0;
  for (int i = 0; i < block.uLightCount[0]; ++i) {
    const GpuLight& l = block.uLights[i];
    if (l.params[2] >= 0) layers += shadowLayersOf(int(l.positionType[3]));
  }
  return layers;
}

void SceneLights::build(const Scene& scene, const RenderSpace& space,
                        const RendererParams& params) {
  shadowMapSize = params.shadowMapSize;
  std::vector<GpuLight> lights;
  for (const Light& light : scene.lights) lights.push_back(punctualLight(light, space));
  const EmitterSampler sampler = buildEmitterSampler(scene);
  AreaLightSet area = params.areaLights ? areaLights(scene, sampler, space) : AreaLightSet{};
  std::vector<GpuLight> emitters = area.lights;
  if (emitters.empty()) {
    emitters = emitterVpls(scene, sampler, space, params.emitterLights);
    emitterLights = int(emitters.size());
  } else {
    areaLightCount = int(emitters.size());
    areaTriangleCount = int(area.triangleCount());
    std::copy(area.triangles.begin(), area.triangles.end(), block.uAreaTriangles);
  }
  lights.insert(lights.end(), emitters.begin(), emitters.end());
  if (lights.size() > size_t(kMaxLights)) {
    throw tooManyLights(scene, emitters.size(), !area.lights.empty());
  }

  // Shadow map layers: 6 per point light / emitter VPL (cube faces), 1 per
  // spot or directional light, while layers last (further lights unshadowed).
  int layers = 0;
  const glm::vec3 center = toGlm(space.bounds.center());
  const float sceneSize = space.sceneSize;
  const float radius = 0.5f * sceneSize;
  const float nearPlane = 1e-3f * sceneSize;
  for (GpuLight& l : lights) {
    const int type = int(l.positionType[3]);
    const int need = shadowLayersOf(type);
    if (layers + need > kMaxShadowLayers) continue;
    const glm::vec3 pos(l.positionType);
    const glm::vec3 dir(l.directionRange);
    const float far = glm::length(pos - center) + radius + nearPlane;
    l.params[2] = float(layers);
    if (need == 6) {
      const glm::vec3 axes[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                 {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
      const glm::mat4 proj = glm::perspective(glm::radians(90.0f), 1.0f, nearPlane, far);
      for (int f = 0; f < 6; ++f) {
        block.uShadowMatrices[layers + f] =
            proj * glm::lookAt(pos, pos + axes[f], perpendicular(axes[f]));
      }
      l.colorFar[3] = far;
    } else if (type == shader::LO_LIGHT_SPOT) {
      block.uShadowMatrices[layers] = glm::perspective(spotShadowFov(l), 1.0f, nearPlane, far) *
                                      glm::lookAt(pos, pos + dir, perpendicular(dir));
      l.colorFar[3] = far;
    } else {
      // Cascades fitted to the camera's view each frame (fitCascades); until
      // the first frame, every cascade covers the whole scene.
      const glm::vec3 eye = center - dir * (2.0f * radius);
      const glm::mat4 m = glm::ortho(-radius, radius, -radius, radius, 0.0f, 4.0f * radius) *
                          glm::lookAt(eye, center, perpendicular(dir));
      for (int c = 0; c < kCascades; ++c) block.uShadowMatrices[layers + c] = m;
      l.colorFar[3] = 0;
      sunLights.push_back(int(&l - lights.data()));
    }
    layers += need;
  }
  // The maps within a memory budget: a scene of many shadowed lights (an
  // emissive texture's VPLs take 6 layers each) gets smaller maps, halved
  // until they fit, but not below 256 texels.
  while (shadowMapSize > 256 &&
         double(shadowMapSize) * double(shadowMapSize) * 2.0 * double(layers) > kShadowMapBudget) {
    shadowMapSize = std::max(256, shadowMapSize / 2);
  }
  // The triangles the fitted cascades' fill is counted on.
  cascadeFillBudget = params.interactive ? kShadowFillBudget / 16 : kShadowFillBudget;
  if (!sunLights.empty()) {
    for (const glm::vec3& corner : sampledCorners(scene, space, kCascadeSampleTriangles)) {
      cascadeSample.emplace_back(corner, 1.0f);
    }
    const size_t sampled = cascadeSample.size() / 3;
    cascadeSampleScale = sampled > 0 ? double(scene.triangleCount()) / double(sampled) : 0;
  }
  // And within the fill budget (kShadowFillBudget).
  const double overlap = coveredTimesOver(scene, space, block.uShadowMatrices, layers);
  shadowOverlap = overlap;
  auto fill = [&](int size) { return overlap * double(size) * double(size) * double(layers); };
  const int asked = shadowMapSize;
  while (shadowMapSize > kMinFillSize && fill(shadowMapSize) > kShadowFillBudget) {
    shadowMapSize = std::max(kMinFillSize, shadowMapSize / 2);
  }
  if (shadowMapSize < asked) {
    shadowMapNote = "shadow maps of " + std::to_string(shadowMapSize) + "^2, not " +
                    std::to_string(asked) + "^2: the scene covers them " +
                    formatNumber(std::round(overlap)) +
                    " times over (surfaces stacked before its lights), and a drawing of them at " +
                    std::to_string(asked) + "^2 would cover " + formatCount(size_t(fill(asked))) +
                    " texels, more than " + formatCount(size_t(kShadowFillBudget)) +
                    "; --shadow-map-size sets a smaller size";
  }
  // Each shadowed light's tangent per texel (the shader's normal offset and
  // depth bias are texels at the receiver's distance, never scene units): a
  // cube face spans 90 degrees, a spot's map its field of view.
  for (GpuLight& l : lights) {
    if (l.params[2] < 0) continue;
    const int type = int(l.positionType[3]);
    const float tanHalf = type == shader::LO_LIGHT_SPOT ? std::tan(0.5f * spotShadowFov(l)) : 1.0f;
    if (type != shader::LO_LIGHT_DIRECTIONAL) l.corner1[3] = 2.0f * tanHalf / float(shadowMapSize);
  }
  block.uShadowParams[0] = 2.0f / 65535.0f;
  std::copy(lights.begin(), lights.end(), block.uLights);
  block.uLightCount[0] = int32_t(lights.size());
  block.uLightCount[1] = int32_t(areaLightCount);  // appended last

  ubo = GlBuffer::create();
  glBindBuffer(GL_UNIFORM_BUFFER, ubo.get());
  glBufferData(GL_UNIFORM_BUFFER, sizeof(LightBlock), &block, GL_STATIC_DRAW);
  glBindBuffer(GL_UNIFORM_BUFFER, 0);
}

void SceneLights::allocateShadowMaps() {
  const int layers = layerCount();
  shadowTexture = GlTexture::create();
  glBindTexture(GL_TEXTURE_2D_ARRAY, shadowTexture.get());
  const int size = layers > 0 ? shadowMapSize : 1;
  glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_DEPTH_COMPONENT16, size, size, std::max(layers, 1), 0,
               GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  checkGl("allocating the shadow maps");

  // The same maps read as plain depths (PCSS's blocker search): a sampler
  // object without comparison, bound to its own unit.
  depthSampler = GlSampler::create();
  glSamplerParameteri(depthSampler.get(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glSamplerParameteri(depthSampler.get(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glSamplerParameteri(depthSampler.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(depthSampler.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(depthSampler.get(), GL_TEXTURE_COMPARE_MODE, GL_NONE);

  shadowFbo = GlFramebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, shadowFbo.get());
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  shadowProgram =
      GlProgram(buildProgram({"render_shadow.vert", "render_shadow.geom", "render_shadow.frag"}));
}

GLint SceneLights::beginShadowPass(GLuint vao) {
  GLint previous = 0;
  glGetIntegerv(GL_FRAMEBUFFER_BINDING, &previous);
  glBindFramebuffer(GL_FRAMEBUFFER, shadowFbo.get());
  glViewport(0, 0, shadowMapSize, shadowMapSize);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glUseProgram(shadowProgram.get());
  glBindVertexArray(vao);
  return previous;
}

void SceneLights::endShadowPass(GLint previous, const char* what) {
  glBindVertexArray(0);
  glBindFramebuffer(GL_FRAMEBUFFER, GLuint(previous));
  checkGl(what);
}

void SceneLights::beginLayer(int layer, bool checkComplete) {
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, shadowTexture.get(), 0, layer);
  if (checkComplete && glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw GlError("shadow map framebuffer incomplete");
  }
  glClear(GL_DEPTH_BUFFER_BIT);
  glUniformMatrix4fv(glGetUniformLocation(shadowProgram.get(), "uViewProj"), 1, GL_FALSE,
                     glm::value_ptr(block.uShadowMatrices[layer]));
}

/// Cascaded shadow maps of the directional lights (Engel 2006; Zhang et
/// al. 2006, parallel-split): the camera's view depth up to the scene's far
/// end is split into kCascades slices, half logarithmic and half uniform,
/// and each slice's frustum gets its own orthographic map around the
/// slice's bounding sphere (a square of the sphere's diameter, so the
/// texel size does not change as the camera turns), its centre snapped to
/// whole texels (no shimmer as the camera moves), its depth range the
/// whole scene's along the light (casters outside the slice still cast).
bool SceneLights::fitCascadeMatrices(const RenderSpace& space, const glm::vec3& eye,
                                     const glm::vec3& forward, float yfov, float aspect,
                                     float znear, float zfar, int fits) {
  std::vector<glm::mat4> before;
  for (int light : sunLights) {
    const int first = int(block.uLights[light].params[2]);
    before.insert(before.end(), block.uShadowMatrices + first,
                  block.uShadowMatrices + first + kCascades);
  }
  fitCascadeSlices(space, eye, forward, yfov, aspect, znear, zfar, false);
  cascadesWhole = cascadeFill() * double(fits) > cascadeFillBudget;
  if (cascadesWhole) fitCascadeSlices(space, eye, forward, yfov, aspect, znear, zfar, true);
  bool changed = false;
  glBindBuffer(GL_UNIFORM_BUFFER, ubo.get());
  for (size_t i = 0; i < sunLights.size(); ++i) {
    const int first = int(block.uLights[sunLights[i]].params[2]);
    for (int c = 0; c < kCascades; ++c) {
      const glm::mat4& m = block.uShadowMatrices[first + c];
      if (m == before[i * kCascades + size_t(c)]) continue;
      changed = true;
      glBufferSubData(
          GL_UNIFORM_BUFFER,
          GLintptr(offsetof(LightBlock, uShadowMatrices) + sizeof(glm::mat4) * size_t(first + c)),
          sizeof(glm::mat4), glm::value_ptr(m));
    }
  }
  glBindBuffer(GL_UNIFORM_BUFFER, 0);
  return changed;
}

double SceneLights::cascadeFill() const {
  double covered = 0;
  for (size_t t = 0; t + 2 < cascadeSample.size(); t += 3) {
    for (int light : sunLights) {
      const int first = int(block.uLights[light].params[2]);
      for (int c = 0; c < kCascades; ++c) {
        const glm::mat4& m = block.uShadowMatrices[first + c];
        const glm::vec4 clip[3] = {m * cascadeSample[t], m * cascadeSample[t + 1],
                                   m * cascadeSample[t + 2]};
        covered += coveredShare(clip);
      }
    }
  }
  return covered * cascadeSampleScale * double(shadowMapSize) * double(shadowMapSize);
}

void SceneLights::fitCascadeSlices(const RenderSpace& space, const glm::vec3& eye,
                                   const glm::vec3& forward, float yfov, float aspect, float znear,
                                   float zfar, bool whole) {
  const Bounds3& bounds = space.bounds;
  const float sceneSize = space.sceneSize;
  const glm::vec3 center = toGlm(bounds.center());
  const float sceneRadius = 0.5f * sceneSize;
  // The slices end where the scene ends along the view.
  float farthest = 0;
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? bounds.upper.x : bounds.lower.x,
                           (c & 2) ? bounds.upper.y : bounds.lower.y,
                           (c & 4) ? bounds.upper.z : bounds.lower.z);
    farthest = std::max(farthest, glm::dot(corner - eye, forward));
  }
  const float n = std::max(znear, 1e-4f * sceneSize);
  const float f = std::max(std::min(zfar, farthest), 2.0f * n);
  float splits[kCascades + 1];
  splits[0] = n;
  for (int i = 1; i <= kCascades; ++i) {
    const float t = float(i) / float(kCascades);
    splits[i] = 0.5f * n * std::pow(f / n, t) + 0.5f * (n + (f - n) * t);
  }
  const float th = std::tan(0.5f * yfov), tw = th * aspect;
  for (int c = 0; c < kCascades; ++c) {
    // The slice's bounding sphere: centred on the view axis where it is
    // equidistant from the near and far corners.
    const float d0 = splits[c], d1 = splits[c + 1];
    const float k2 = tw * tw + th * th;
    float z = 0.5f * (d0 + d1) * (1.0f + k2);
    z = std::min(z, d1);
    const float r0 = std::sqrt((z - d0) * (z - d0) + d0 * d0 * k2);
    const float r1 = std::sqrt((d1 - z) * (d1 - z) + d1 * d1 * k2);
    float radius = std::max(r0, r1);
    glm::vec3 sphere = eye + forward * z;
    if (whole || radius >= sceneRadius) {
      radius = sceneRadius;
      sphere = center;
    }
    cascadeFar[c] = c + 1 == kCascades ? 1e30f : d1;
    cascadeTexel[c] = 2.0f * radius / float(shadowMapSize);
    for (int light : sunLights) {
      const GpuLight& l = block.uLights[light];
      const glm::vec3 dir(l.directionRange);
      const glm::mat4 view0 = glm::lookAt(glm::vec3(0.0f), dir, perpendicular(dir));
      // Snap the centre to whole texels in the light's view plane.
      glm::vec3 ls = glm::vec3(view0 * glm::vec4(sphere, 1.0f));
      ls.x = std::floor(ls.x / cascadeTexel[c]) * cascadeTexel[c];
      ls.y = std::floor(ls.y / cascadeTexel[c]) * cascadeTexel[c];
      const glm::vec3 snapped = glm::vec3(glm::inverse(view0) * glm::vec4(ls, 1.0f));
      // Depth: the whole scene along the light, from the map's centre.
      float before = 0, after = 0;
      for (int k = 0; k < 8; ++k) {
        const glm::vec3 corner((k & 1) ? bounds.upper.x : bounds.lower.x,
                               (k & 2) ? bounds.upper.y : bounds.lower.y,
                               (k & 4) ? bounds.upper.z : bounds.lower.z);
        const float along = glm::dot(corner - snapped, dir);
        before = std::max(before, -along);
        after = std::max(after, along);
      }
      const float margin = 1e-3f * sceneSize;
      const glm::vec3 lightEye = snapped - dir * (before + margin);
      cascadeDepth[c] = before + after + 2.0f * margin;
      const int layer = int(l.params[2]) + c;
      block.uShadowMatrices[layer] =
          glm::ortho(-radius, radius, -radius, radius, 0.0f, cascadeDepth[c]) *
          glm::lookAt(lightEye, snapped, perpendicular(dir));
    }
  }
}

size_t sampledTriangle(size_t s, size_t sampled, size_t triangles) {
  return sampled == triangles ? s : size_t((uint64_t(s) * kSampleStep) % uint64_t(triangles));
}

std::vector<glm::vec3> sampledCorners(const Scene& scene, const RenderSpace& space, size_t most) {
  const size_t triangles = scene.triangleCount();
  const size_t sampled = std::min(triangles, most);
  std::vector<glm::vec3> corners;
  corners.reserve(3 * sampled);
  for (size_t s = 0; s < sampled; ++s) {
    const size_t t = sampledTriangle(s, sampled, triangles);
    for (int k = 0; k < 3; ++k) {
      corners.push_back(toGlm(space.toRender(scene.positions[scene.indices[3 * t + size_t(k)]])));
    }
  }
  return corners;
}

}  // namespace lo::render_internal
