/// @file scene/sky_mesh.cpp
/// @brief A sky box mesh turned into the scene's sky (scene.h, skyFromMaterial):
/// its triangles drawn into an equirectangular image as seen from the
/// centre of the rest of the scene, then taken out of the geometry.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"

namespace lo {

namespace {

/// Where a ray from `o` along `d` meets triangle (a, b, c), either side:
/// the distance and barycentrics (Moller-Trumbore, in double: a sky box lies
/// far from its centre).
bool hitTriangle(const Vec3d& o, const Vec3d& d, const Vec3d& a, const Vec3d& b, const Vec3d& c,
                 double& t, double& b1, double& b2) {
  const Vec3d e1 = b - a, e2 = c - a;
  const Vec3d p = cross(d, e2);
  const double det = dot(e1, p);
  if (std::fabs(det) < 1e-300) return false;
  const double inv = 1.0 / det;
  const Vec3d s = o - a;
  b1 = dot(s, p) * inv;
  if (b1 < 0 || b1 > 1) return false;
  const Vec3d q = cross(s, e1);
  b2 = dot(d, q) * inv;
  if (b2 < 0 || b1 + b2 > 1) return false;
  t = dot(e2, q) * inv;
  return t > 0;
}

/// The texel rows and column span a spherical triangle can cover: a cap
/// around its vertices' mean direction that holds all three (the geodesic
/// triangle lies within it while the cap is under a hemisphere).
struct Footprint {
  int row0 = 0, row1 = 0;        ///< rows [row0, row1]
  int column0 = 0, columns = 0;  ///< `columns` columns from column0, wrapping
};

Footprint footprintOf(const Vec3d dirs[3], int w, int h) {
  Footprint f;
  Vec3d mean = normalize(dirs[0] + dirs[1] + dirs[2]);
  double radius = 0;
  for (int k = 0; k < 3; ++k) {
    radius = std::max(radius, std::acos(std::clamp(dot(mean, dirs[k]), -1.0, 1.0)));
  }
  radius += 2.0 * kPi / double(w);  // a texel of slack for the centres tested
  const double pi = double(kPi);
  if (length(mean) == 0 || radius >= 0.5 * pi) {
    f.row1 = h - 1;
    f.columns = w;
    return f;
  }
  const double polar = std::acos(std::clamp(mean.y, -1.0, 1.0));  // from the zenith
  const double top = polar - radius, bottom = polar + radius;
  f.row0 = std::clamp(int(std::floor(std::max(top, 0.0) / pi * h)), 0, h - 1);
  f.row1 = std::clamp(int(std::ceil(std::min(bottom, pi) / pi * h)), 0, h - 1);
  if (top <= 0 || bottom >= pi) {  // holds a pole: every azimuth
    f.columns = w;
    return f;
  }
  const double azimuth = std::atan2(mean.x, -mean.z);
  const double half = std::asin(std::min(1.0, std::sin(radius) / std::sin(polar)));
  const double u0 = 0.5 + (azimuth - half) / (2.0 * pi);
  f.column0 = int(std::floor(u0 * w));
  f.columns = std::min(w, int(std::ceil(2.0 * half / (2.0 * pi) * w)) + 2);
  return f;
}

/// Removes the triangles for which `drop` holds, and the vertices no other
/// triangle uses (with their attributes).
template <typename Drop>
void removeTriangles(Scene& scene, Drop drop) {
  const size_t vertices = scene.positions.size();
  std::vector<uint32_t> keptIndices;
  std::vector<int32_t> keptMaterials;
  std::vector<uint32_t> newIndex(vertices, std::numeric_limits<uint32_t>::max());
  uint32_t next = 0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    if (drop(t)) continue;
    keptMaterials.push_back(scene.triangleMaterial[t]);
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = scene.indices[3 * t + size_t(k)];
      if (newIndex[v] == std::numeric_limits<uint32_t>::max()) newIndex[v] = next++;
      keptIndices.push_back(newIndex[v]);
    }
  }
  auto compact = [&](auto& values, size_t per) {
    if (values.empty()) return;
    std::remove_reference_t<decltype(values)> out(size_t(next) * per);
    for (size_t v = 0; v < vertices; ++v) {
      if (newIndex[v] == std::numeric_limits<uint32_t>::max()) continue;
      for (size_t k = 0; k < per; ++k) out[size_t(newIndex[v]) * per + k] = values[v * per + k];
    }
    values = std::move(out);
  };
  compact(scene.positions, 1);
  compact(scene.normals, 1);
  compact(scene.texcoords0, 2);
  compact(scene.texcoords1, 2);
  compact(scene.tangents, 4);
  compact(scene.colors, 4);
  scene.indices = std::move(keptIndices);
  scene.triangleMaterial = std::move(keptMaterials);
}

}  // namespace

void skyFromMaterial(Scene& scene, const std::string& material, int width) {
  const std::string where = scene.sourcePath.empty() ? "scene" : scene.sourcePath;
  if (width < 8 || width > 16384 || width % 2 != 0) {
    throw InputError(where + ": sky mesh image width " + std::to_string(width) +
                     " must be even, from 8 to 16384");
  }
  int id = -1;
  std::string names;
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    if (scene.materials[m].name == material && id < 0) id = int(m);
    names += (names.empty() ? "" : ", ") + scene.materials[m].name;
  }
  if (id < 0) {
    throw InputError(where + ": no material named '" + material +
                     "' to take as the sky mesh (the scene's materials: " + names + ")");
  }
  std::vector<size_t> sky;
  Bounds3 rest;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    if (scene.triangleMaterial[t] == id) {
      sky.push_back(t);
    } else {
      for (int k = 0; k < 3; ++k) rest.extend(scene.positions[scene.indices[3 * t + size_t(k)]]);
    }
  }
  if (sky.empty()) {
    throw InputError(where + ": material '" + material + "' covers no triangle: no sky mesh");
  }
  if (rest.empty()) {
    throw InputError(where + ": every triangle is of material '" + material +
                     "': nothing would be left beside the sky mesh");
  }

  // The sky as the scene's centre sees it: per texel, the nearest sky
  // triangle along the texel's centre direction, its emission (or, for a
  // plain textured sky box, its base colour) as radiance.
  const int w = width, h = width / 2;
  const Vec3d centre = Vec3d(rest.center());
  std::vector<Vec3> radiance(size_t(w) * size_t(h), Vec3{0, 0, 0});
  std::vector<double> nearest(radiance.size(), std::numeric_limits<double>::infinity());
  const bool emissive = scene.materials[size_t(id)].isEmissive();
  for (size_t t : sky) {
    Vec3d v[3], dirs[3];
    for (int k = 0; k < 3; ++k) {
      v[k] = Vec3d(scene.positions[scene.indices[3 * t + size_t(k)]]);
      dirs[k] = normalize(v[k] - centre);
    }
    const Footprint f = footprintOf(dirs, w, h);
    for (int y = f.row0; y <= std::min(f.row1, h / 2 - 1); ++y) {  // the upper half is used
      for (int i = 0; i < f.columns; ++i) {
        const int x = ((f.column0 + i) % w + w) % w;
        const Vec3d d(skyPixelDirection(float(x) + 0.5f, float(y) + 0.5f, w, h));
        double distance = 0, b1 = 0, b2 = 0;
        const size_t texel = size_t(y) * size_t(w) + size_t(x);
        if (!hitTriangle(centre, d, v[0], v[1], v[2], distance, b1, b2) ||
            distance >= nearest[texel]) {
          continue;
        }
        nearest[texel] = distance;
        radiance[texel] = emissive ? scene.emission(t, float(b1), float(b2))
                                   : scene.albedo(t, float(b1), float(b2));
      }
    }
  }
  auto texture = std::make_shared<Texture>(Texture::fromLinear(w, h, radiance));
  texture->name = "sky mesh '" + material + "'";
  removeTriangles(scene, [&](size_t t) { return scene.triangleMaterial[t] == id; });
  scene.sky.image = std::move(texture);
  scene.sky.radiance = Vec3{1, 1, 1};
}

}  // namespace lo
