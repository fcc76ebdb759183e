#pragma once
// Small scenes and octrees for the lightmap atlas tests (CPU path in
// tests/lightmap, GPU path in tests/render): a dense depth-3 octree whose
// VDLs a function gives, planes as grids of quads, cubes of flat faces.

#include <functional>
#include <vector>

#include "lightgrid/vdl_grid.h"
#include "octree/gpu_octree.h"
#include "scene/scene.h"
#include "test_util.h"

namespace lo::atlas_test {

constexpr float kVoxel = 0.25f;  // world units; depth 3: the octree spans [0, 2]^3

inline Vdl vdl(const Vec3& irradiance, const Vec3& direction) {
  Vdl v;
  v.irradiance = irradiance;
  v.direction = normalize(direction);
  return v;
}

/// Every voxel of a depth-3 grid at the origin active, with the VDLs vdlsAt
/// gives for its coordinate.
inline GpuOctree denseOctree(const std::function<std::vector<Vdl>(const Coord&)>& vdlsAt) {
  VdlGrid g;
  g.frame.origin = {0, 0, 0};
  g.frame.voxelSize = kVoxel;
  g.frame.depth = 3;
  g.maxVdls = kMaxVdls;
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        const std::vector<Vdl> vdls = vdlsAt({x, y, z});
        g.coords.push_back({x, y, z});
        g.normals.push_back({0, 0, 1});
        g.vdlCount.push_back(uint8_t(vdls.size()));
        for (int i = 0; i < kMaxVdls; ++i)
          g.vdls.push_back(i < int(vdls.size()) ? vdls[size_t(i)] : Vdl{});
      }
  return buildGpuOctree(g, test::paperCosine());
}

inline Scene emptyScene() { return test::oneMaterialScene(); }

// An n x n grid of quads spanning origin + [0, 1] eu + [0, 1] ev, vertices
// shared, facing cross(eu, ev).
inline void addGrid(Scene& scene, int n, const Vec3& origin, const Vec3& eu, const Vec3& ev) {
  const uint32_t base = uint32_t(scene.positions.size());
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      scene.positions.push_back(origin + eu * (float(i) / n) + ev * (float(j) / n));
  auto id = [&](int i, int j) { return base + uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      scene.indices.insert(scene.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      scene.indices.insert(scene.indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      scene.triangleMaterial.insert(scene.triangleMaterial.end(), {0, 0});
    }
}

// Cube lo + [0, size]^3 of six outward-facing quads (separate vertices per
// face, no vertex normals: flat faces).
inline void addCube(Scene& scene, const Vec3& lo, float size) {
  const Vec3 ex{size, 0, 0}, ey{0, size, 0}, ez{0, 0, size};
  test::addQuad(scene, lo, ex, ez, {0, -1, 0}, 0);
  test::addQuad(scene, lo + ey, ex, ez, {0, 1, 0}, 0);
  test::addQuad(scene, lo, ey, ez, {-1, 0, 0}, 0);
  test::addQuad(scene, lo + ex, ey, ez, {1, 0, 0}, 0);
  test::addQuad(scene, lo, ex, ey, {0, 0, -1}, 0);
  test::addQuad(scene, lo + ez, ex, ey, {0, 0, 1}, 0);
}

// The unit cube [0, 1]^3 (addCube) in an otherwise empty scene.
inline Scene unitCube() {
  Scene scene = emptyScene();
  addCube(scene, Vec3(0.0f), 1.0f);
  return scene;
}

}  // namespace lo::atlas_test
