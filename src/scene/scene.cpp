#include <sstream>

#include "core/error.h"
#include "scene/scene.h"

namespace lo {

Vec3 Texture::lookup(float u, float v) const {
  if (width <= 0 || height <= 0) return Vec3{1, 1, 1};
  float fu = u - std::floor(u), fv = v - std::floor(v);
  int x = std::min(width - 1, std::max(0, int(fu * float(width))));
  int y = std::min(height - 1, std::max(0, int(fv * float(height))));
  return texels[size_t(y) * size_t(width) + size_t(x)];
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
      float r = 0.5f * length(sceneBounds.extent());
      return radiant * (kPi * r * r);
    }
  }
  return {};
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

Vec3 Scene::albedo(size_t t, float b1, float b2) const {
  const Material& m = materials[size_t(triangleMaterial[t])];
  if (m.baseColorTexture < 0) return m.baseColor;
  const std::vector<float>& uv = m.baseColorTexCoord == 1 ? texcoords1 : texcoords0;
  if (uv.empty()) return m.baseColor;
  float b0 = 1.0f - b1 - b2;
  uint32_t i0 = indices[3 * t], i1 = indices[3 * t + 1], i2 = indices[3 * t + 2];
  float u = b0 * uv[2 * i0] + b1 * uv[2 * i1] + b2 * uv[2 * i2];
  float v = b0 * uv[2 * i0 + 1] + b1 * uv[2 * i1 + 1] + b2 * uv[2 * i2 + 1];
  return m.baseColor * textures[size_t(m.baseColorTexture)].lookup(u, v);
}

std::string Scene::ToString() const {
  std::ostringstream os;
  os << triangleCount() << " triangles, " << positions.size() << " vertices, " << materials.size()
     << " materials, " << lights.size() << " punctual lights, " << cameras.size()
     << " cameras, bounds " << bounds().ToString();
  return os.str();
}

}  // namespace lo
