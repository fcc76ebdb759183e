#include "render/render_fixture.h"

#include <octree_layout.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "vdb/vdb_io.h"

namespace lo::test {

GpuOctree makeOctree(int depth, const Vec3& origin, float cubeSize, const VdlsOf& vdlsOf) {
  namespace L = layout;
  struct Tile {
    uint8_t texels[8][4];
  };
  std::vector<Tile> tiles;
  std::vector<float> vdls;  // RGBA per VDL
  size_t leaves = 0;
  std::function<int(int, Coord)> build = [&](int level, Coord base) -> int {
    int index = int(tiles.size());
    tiles.push_back({});
    bool any = false;
    for (int child = 0; child < 8; ++child) {
      int cx = child & 1, cy = (child >> 1) & 1, cz = (child >> 2) & 1;
      Coord c{base.x * 2 + cx, base.y * 2 + cy, base.z * 2 + cz};
      uint8_t texel[4] = {0, 0, 0, uint8_t(L::LO_FLAG_EMPTY)};
      if (level + 1 == depth) {
        Vdl v[kMaxVdls];
        int n = vdlsOf(c, v);
        if (n > 0) {
          uint32_t address = uint32_t(vdls.size() / 4);
          for (int i = 0; i < n; ++i) {
            const Vdl& d = v[i];
            vdls.insert(vdls.end(),
                        {d.irradiance.x, d.irradiance.y, d.irradiance.z,
                         L::loPackDirection(d.direction.x, d.direction.y, d.direction.z)});
          }
          texel[0] = uint8_t(L::loPackAddressR(address));
          texel[1] = uint8_t(L::loPackAddressG(address));
          texel[2] = uint8_t(L::loPackAddressB(address));
          texel[3] = uint8_t(n);
          ++leaves;
        }
      } else {
        int t = build(level + 1, c);
        if (t >= 0) {
          texel[0] = uint8_t(t);
          texel[3] = uint8_t(L::LO_FLAG_INNER);
        }
      }
      if (texel[3] != L::LO_FLAG_EMPTY) any = true;
      int slot = cx + 2 * cy + 4 * cz;
      std::copy(texel, texel + 4, tiles[size_t(index)].texels[slot]);
    }
    if (!any && level > 0) {
      tiles.pop_back();  // only the last-built tile can be empty here
      return -1;
    }
    return index;
  };
  build(0, Coord{0, 0, 0});
  GpuOctree o;
  o.depth = depth;
  o.origin = origin;
  o.cubeSize = cubeSize;
  o.tilesX = int(tiles.size());
  o.tilesY = o.tilesZ = 1;
  int w = o.poolWidth();
  o.pool.assign(size_t(w) * 2 * 2 * 4, 0);
  for (size_t t = 0; t < tiles.size(); ++t) {
    for (int slot = 0; slot < 8; ++slot) {
      int x = int(t) * 2 + (slot & 1), y = (slot >> 1) & 1, z = (slot >> 2) & 1;
      std::copy(tiles[t].texels[slot], tiles[t].texels[slot] + 4,
                o.pool.begin() + ((size_t(z) * 2 + y) * w + x) * 4);
    }
  }
  size_t count = vdls.size() / 4;
  o.vdlWidth = int(std::min<size_t>(std::max<size_t>(count, 1), L::LO_VDL_TEXTURE_WIDTH));
  o.vdlHeight =
      int((std::max<size_t>(count, 1) + L::LO_VDL_TEXTURE_WIDTH - 1) / L::LO_VDL_TEXTURE_WIDTH);
  o.vdlTexels.assign(size_t(o.vdlWidth) * o.vdlHeight * 4, 0.0f);
  std::copy(vdls.begin(), vdls.end(), o.vdlTexels.begin());
  o.leafCount = leaves;
  o.nodeCount = tiles.size();
  o.vdlCount = count;
  return o;
}

GpuOctree quadOctree(const VdlsOf& vdlsOf) {
  return makeOctree(2, {-1.5f, -1.5f, -1.5f}, 3.0f, vdlsOf);
}

GpuOctree emptyOctree() {
  return quadOctree([](const Coord&, Vdl*) { return 0; });
}

GpuOctree constantOctree() {
  return quadOctree([](const Coord&, Vdl* v) {
    v[0].irradiance = {1, 1, 1};
    v[0].direction = {0, 0, 1};
    return 1;
  });
}

GpuOctree goldenCornellOctree() {
  return buildGpuOctree(readVdlGrid(dataDir() + "/../tests/golden/cornell-box-d4.vdb").grid);
}

Vec3 latticeDirection(uint32_t thetaQ, uint32_t phiQ) {
  float packed = float(thetaQ * 256u + phiQ);
  return {layout::loUnpackDirectionX(packed), layout::loUnpackDirectionY(packed),
          layout::loUnpackDirectionZ(packed)};
}

QuadSetup::QuadSetup() {
  Material m;
  m.baseColor = albedo;
  m.roughness = 1.0f;
  scene.materials.push_back(m);
  addQuad(scene, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, 0);
}

RenderParams QuadSetup::params(bool interpolation) {
  RenderParams p;
  p.width = 64;
  p.height = 48;
  p.mode = RenderMode::Indirect;
  p.specular = false;
  p.interpolation = interpolation;
  return p;
}

RenderParams QuadSetup::directParams() {
  RenderParams p = params(false);
  p.mode = RenderMode::Direct;
  return p;
}

RgbImage QuadSetup::render(const GpuOctree& octree, const RenderParams& p) const {
  return Renderer(scene, octree).render(camera, p);
}

float QuadSetup::worldPerPixel(const RenderParams& p, float distance) const {
  return 2.0f * distance * std::tan(0.5f * camera.yfov) / float(p.height);
}

int columnAt(const QuadSetup& s, const RenderParams& p, float x, float z) {
  return p.width / 2 + int(std::floor((x - 0.1f) / s.worldPerPixel(p, 2.0f - z)));
}

}  // namespace lo::test
