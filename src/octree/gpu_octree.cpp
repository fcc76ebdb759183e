/// @file octree/gpu_octree.cpp
/// @brief The VDL grid as a GPU texture stack (paper §4.2.1, §4.2.2): a pool
/// of 2x2x2 RGBA8 node tiles and a 2D VDL texture; and the C++ reference of the
/// shader's descent. Every texel is written and read through the functions of
/// shaders/octree_layout.h, the header the GLSL includes, so that the C++
/// reference and the shader share one definition of the layout.

#include "octree/gpu_octree.h"

#include <octree_layout.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <sstream>

#include "core/error.h"
#include "lightgrid/light_grid_schema.h"
#include "octree/adaptive_leaves.h"
#include "octree/gpu_octree_internal.h"

namespace lo {

// The one VDL limit of the C++ side (lightgrid/vdl_grid.h) is the shader's.
static_assert(kMaxVdls == int(layout::LO_MAX_VDLS), "kMaxVdls and LO_MAX_VDLS disagree");

namespace gpu_octree_internal {

using namespace layout;

/// Interleaves the bits of a voxel coordinate, x lowest, so that the child
/// index inside a node (x | y << 1 | z << 2) is the code's lowest 3 bits and
/// the code of the ancestor at `k` levels up is code >> 3k.
uint64_t mortonCode(const Coord& c, int depth) {
  uint64_t code = 0;
  for (int b = depth - 1; b >= 0; --b) {
    code = (code << 3) | (uint64_t((c.z >> b) & 1) << 2) | (uint64_t((c.y >> b) & 1) << 1) |
           uint64_t((c.x >> b) & 1);
  }
  return code;
}

/// Smallest n with n^k >= value (k = 2 or 3), for near-cubic tile arrangements.
int64_t ceilRoot(int64_t value, int k) {
  int64_t n = std::max<int64_t>(1, int64_t(std::floor(std::pow(double(value), 1.0 / k))));
  auto power = [k](int64_t x) { return k == 2 ? x * x : x * x * x; };
  while (n > 1 && power(n - 1) >= value) --n;
  while (power(n) < value) ++n;
  return n;
}

void validate(const VdlGrid& grid, const GpuOctreeParams& params) {
  const GridFrame& f = grid.frame;
  if (f.depth < 1 || f.depth > 12) {
    throw InputError("GPU octree: grid depth " + std::to_string(f.depth) +
                     " is outside [1, 12] (the octree needs at least one level below the root)");
  }
  if (!(f.voxelSize > 0.0f) || !std::isfinite(f.voxelSize) || !isFinite(f.origin)) {
    throw InputError("GPU octree: grid frame has voxel size " + std::to_string(f.voxelSize) +
                     " and origin " + f.origin.ToString() + "; need a finite positive size");
  }
  if (grid.maxVdls < 1 || grid.maxVdls > int(LO_MAX_VDLS)) {
    throw InputError("GPU octree: maxVdls " + std::to_string(grid.maxVdls) + " is outside [1, " +
                     std::to_string(LO_MAX_VDLS) + "]");
  }
  if (grid.vdlCount.size() != grid.coords.size() ||
      grid.vdls.size() != grid.coords.size() * size_t(grid.maxVdls)) {
    throw InputError("GPU octree: VDL grid arrays disagree: " + std::to_string(grid.coords.size()) +
                     " voxels, " + std::to_string(grid.vdlCount.size()) + " VDL counts, " +
                     std::to_string(grid.vdls.size()) + " VDL slots (expected voxels * " +
                     std::to_string(grid.maxVdls) + ")");
  }
  if (grid.shTerms != 0 && grid.shTerms != 4 && grid.shTerms != 9) {
    throw InputError("GPU octree: " + std::to_string(grid.shTerms) +
                     " SH terms per voxel; expected 0 (VDLs), 4 or 9");
  }
  if (grid.sh.size() != grid.size() * size_t(grid.shTerms) ||
      grid.layers.sh.size() != grid.layers.size() * size_t(grid.shTerms)) {
    throw InputError("GPU octree: " + std::to_string(grid.sh.size()) + " SH terms for " +
                     std::to_string(grid.size()) + " voxels and " +
                     std::to_string(grid.layers.sh.size()) + " for " +
                     std::to_string(grid.layers.size()) + " layers, at " +
                     std::to_string(grid.shTerms) + " per voxel");
  }
  for (size_t i = 0; i < grid.sh.size(); ++i) {
    if (!isFinite(grid.sh[i])) {
      throw InputError("GPU octree: voxel " + std::to_string(i / size_t(grid.shTerms)) +
                       " SH term " + std::to_string(i % size_t(grid.shTerms)) + " is not finite");
    }
  }
  for (size_t i = 0; i < grid.layers.sh.size(); ++i) {
    if (!isFinite(grid.layers.sh[i])) {
      throw InputError("GPU octree: surface layer " + std::to_string(i / size_t(grid.shTerms)) +
                       " SH term " + std::to_string(i % size_t(grid.shTerms)) + " is not finite");
    }
  }
  if (params.max3DTextureSize < 2) {
    throw InputError("GPU octree: max 3D texture size " + std::to_string(params.max3DTextureSize) +
                     " cannot hold one 2x2x2 tile");
  }
  if (params.max2DTextureSize < 1) {
    throw InputError("GPU octree: max 2D texture size " + std::to_string(params.max2DTextureSize) +
                     " must be positive");
  }
  const VdlLayers& L = grid.layers;
  const size_t ne = L.size();
  if (L.normals.size() != ne || L.points.size() != ne || L.vdlCount.size() != ne ||
      L.vdls.size() != ne * size_t(grid.maxVdls)) {
    throw InputError("GPU octree: surface layer arrays disagree: " + std::to_string(ne) +
                     " layers, " + std::to_string(L.normals.size()) + " normals, " +
                     std::to_string(L.points.size()) + " points, " +
                     std::to_string(L.vdls.size()) + " VDL slots");
  }
  if (!grid.points.empty() && grid.points.size() != grid.size()) {
    throw InputError("GPU octree: " + std::to_string(grid.points.size()) + " layer points for " +
                     std::to_string(grid.size()) + " voxels");
  }
  for (size_t e = 0; e < ne; ++e) {
    const uint32_t v = L.voxel[e];
    int layer = 1;
    for (size_t b = e; b > 0 && L.voxel[b - 1] == v; --b) ++layer;
    if (v >= grid.size() || (e > 0 && L.voxel[e - 1] > v) || layer >= kMaxLayers) {
      throw InputError("GPU octree: surface layer " + std::to_string(e) + " names voxel " +
                       std::to_string(v) + " out of order, out of range or as its layer " +
                       std::to_string(layer) + " (at most " + std::to_string(kMaxLayers - 1) +
                       " extra layers per voxel)");
    }
    if (L.vdlCount[e] > grid.maxVdls || !isFinite(L.normals[e]) || !isFinite(L.points[e])) {
      throw InputError("GPU octree: surface layer " + std::to_string(e) + " of voxel " +
                       std::to_string(v) + " has " + std::to_string(L.vdlCount[e]) +
                       " VDLs, normal " + L.normals[e].ToString() + ", point " +
                       L.points[e].ToString());
    }
    for (int i = 0; i < L.vdlCount[e]; ++i) {
      const Vdl& vdl = L.vdls[e * size_t(grid.maxVdls) + size_t(i)];
      if (!isFinite(vdl.irradiance) || !isFinite(vdl.direction)) {
        throw InputError("GPU octree: surface layer " + std::to_string(e) + " of voxel " +
                         std::to_string(v) + " VDL " + std::to_string(i) + " is not finite");
      }
    }
  }
  const int res = f.resolution();
  for (size_t v = 0; v < grid.size(); ++v) {
    const Coord& c = grid.coords[v];
    if (c.x < 0 || c.y < 0 || c.z < 0 || c.x >= res || c.y >= res || c.z >= res) {
      throw InputError("GPU octree: voxel " + std::to_string(v) + " at " + c.ToString() +
                       " lies outside [0, " + std::to_string(res) + ")^3");
    }
    if (grid.vdlCount[v] > grid.maxVdls) {
      throw InputError("GPU octree: voxel " + std::to_string(v) + " has " +
                       std::to_string(grid.vdlCount[v]) + " VDLs, more than maxVdls " +
                       std::to_string(grid.maxVdls));
    }
    const Vdl* vdls = grid.vdlsOf(v);
    for (int i = 0; i < grid.vdlCount[v]; ++i) {
      if (!isFinite(vdls[i].irradiance) || !isFinite(vdls[i].direction)) {
        throw InputError("GPU octree: voxel " + std::to_string(v) + " VDL " + std::to_string(i) +
                         " is not finite (irradiance " + vdls[i].irradiance.ToString() +
                         ", direction " + vdls[i].direction.ToString() + ")");
      }
    }
  }
}

std::string kib(size_t bytes) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(1) << double(bytes) / 1024.0 << " KiB";
  return os.str();
}

}  // namespace gpu_octree_internal

uint16_t floatToHalf(float value) {
  uint32_t x;
  std::memcpy(&x, &value, 4);
  const uint32_t sign = (x >> 16) & 0x8000u;
  const uint32_t a = x & 0x7fffffffu;
  if (a > 0x7f800000u) return uint16_t(sign | 0x7e00u);  // NaN (quiet)
  // 65520 = 0x477ff000 is where round-to-nearest-even reaches infinity;
  // clamp from there (and for infinity itself) to the largest finite half.
  if (a >= 0x477ff000u) return uint16_t(sign | 0x7bffu);
  if (a >= 0x38800000u) {  // >= 2^-14: a normal half
    // Rebias the exponent (127 -> 15) and drop 13 mantissa bits; a carry out
    // of the mantissa correctly bumps the exponent.
    uint32_t h = (a >> 13) - (112u << 10);
    const uint32_t rest = a & 0x1fffu;
    if (rest > 0x1000u || (rest == 0x1000u && (h & 1u))) ++h;
    return uint16_t(sign | h);
  }
  // Denormal half: units of 2^-24. value = m * 2^(e - 150), so in those units
  // m * 2^(e - 126): shift the 24-bit significand right by 126 - e.
  const uint32_t e = a >> 23;
  const uint32_t shift = 126u - e;         // >= 14 here
  if (shift > 24u) return uint16_t(sign);  // below half the smallest denormal
  const uint32_t m = (a & 0x7fffffu) | 0x800000u;
  uint32_t q = m >> shift;
  const uint32_t rest = m & ((1u << shift) - 1u);
  const uint32_t halfway = 1u << (shift - 1u);
  if (rest > halfway || (rest == halfway && (q & 1u))) ++q;  // may become 0x400: smallest normal
  return uint16_t(sign | q);
}

uint32_t encodeRgb9e5(const Vec3& rgb) {
  // OpenGL 4.5 spec 8.5.2, the shared-exponent encoding of GL_RGB9_E5.
  constexpr int kMantissa = 9, kBias = 15, kMaxExponent = 31;
  const double maxValue = (511.0 / 512.0) * std::exp2(kMaxExponent - kBias);
  double c[3];
  for (int i = 0; i < 3; ++i) {
    const double v = double(rgb[i]);
    c[i] = std::isnan(v) ? 0.0 : std::clamp(v, 0.0, maxValue);
  }
  const double largest = std::max({c[0], c[1], c[2]});
  int exponent = largest > 0 ? std::max(-kBias - 1, int(std::floor(std::log2(largest)))) + 1 + kBias
                             : 0;
  if (largest > 0) {
    const double maxMantissa = std::floor(largest / std::exp2(exponent - kBias - kMantissa) + 0.5);
    if (maxMantissa == 512.0) ++exponent;
  }
  uint32_t bits = uint32_t(exponent) << 27;
  for (int i = 0; i < 3; ++i) {
    const double m = std::floor(c[i] / std::exp2(exponent - kBias - kMantissa) + 0.5);
    bits |= uint32_t(std::min(m, 511.0)) << (9 * i);
  }
  return bits;
}

float halfToFloat(uint16_t bits) {
  const uint32_t sign = uint32_t(bits & 0x8000u) << 16;
  const uint32_t exponent = (bits >> 10) & 0x1fu;
  const uint32_t mantissa = bits & 0x3ffu;
  uint32_t x;
  if (exponent == 0x1fu) {
    x = sign | 0x7f800000u | (mantissa << 13);
  } else if (exponent != 0) {
    x = sign | ((exponent + 112u) << 23) | (mantissa << 13);
  } else {
    // Zero or denormal: mantissa * 2^-24, exact in a float.
    float f = std::ldexp(float(mantissa), -24);
    return sign ? -f : f;
  }
  float f;
  std::memcpy(&f, &x, 4);
  return f;
}

namespace gpu_octree_internal {

/// buildGpuOctree in named steps, in the order it runs them: the leaves in
/// Morton order, the nodes per level and their tiles, the pool's and the
/// VDL texture's sizes, the compact scale, then every node's texel (and a
/// leaf's VDL texels) written level by level.
class OctreeBuilder {
 public:
  OctreeBuilder(const VdlGrid& grid, const GpuOctreeParams& params)
      : grid_(grid),
        params_(params),
        depth_(grid.frame.depth),
        sh_(grid.shTerms > 0),
        surfaces_(recordsReflectance(grid)),
        adaptive_(collapseLeaves(grid, params.tolerance, params.cosineCorrection)) {}
  /// A free-space octree: each leaf's light preceded by its header texel
  /// (octree_layout.h), headers[v] for voxel v; `adaptive` its merged leaves
  /// (collapseVolume), whose headers hold their joined boxes.
  OctreeBuilder(const VdlGrid& grid, const GpuOctreeParams& params, AdaptiveLeaves adaptive,
                std::vector<Vec3> headers)
      : grid_(grid),
        params_(params),
        depth_(grid.frame.depth),
        sh_(grid.shTerms > 0),
        surfaces_(false),
        adaptive_(std::move(adaptive)),
        headers_(std::move(headers)) {}

  GpuOctree build() {
    indexLayers();
    collectLeaves();
    buildLevels();
    arrangeTiles();
    sizeVdlTexture();
    chooseScale();
    allocate();
    for (int l = 1; l <= depth_; ++l) writeLevel(l);
    LO_CHECK_EQ(nextVdl_, vdlTotal_);
    out_.leafCount = leaves_.size();
    out_.collapsedLeaves = adaptive_.leaves.size();
    out_.collapsedVoxels = adaptive_.voxelsCollapsed;
    out_.nodeCount = tileCount_;
    out_.vdlCount = vdlTotal_;
    out_.surfaceTexels = surfaces_;
    return std::move(out_);
  }

 private:
  /// A leaf of the octree: a lit voxel at the grid's depth, or a collapsed
  /// leaf (adaptive leaves) higher up.
  struct Leaf {
    uint64_t code;   ///< Morton code at `depth` of the leaf's first voxel
    uint32_t voxel;  ///< grid voxel, or index into adaptive.leaves when collapsed
    int level;       ///< depth, or the collapsed leaf's level
  };

  /// Each voxel's extra surface layers: entries extraFirst[v] .. + extraCount[v]
  /// of grid.layers (validated: ascending by voxel).
  void indexLayers() {
    extraFirst_.assign(grid_.size(), 0);
    extraCount_.assign(grid_.size(), 0);
    for (size_t e = 0; e < grid_.layers.size(); ++e) {
      const uint32_t v = grid_.layers.voxel[e];
      if (extraCount_[v]++ == 0) extraFirst_[v] = uint32_t(e);
    }
  }

  /// Whether any voxel or layer of `grid` reflects light: only then do the
  /// leaves carry surface texels (octree_layout.h).
  static bool recordsReflectance(const VdlGrid& grid) {
    if (grid.reflectance.size() != grid.size() ||
        grid.layers.reflectance.size() != grid.layers.size()) {
      return false;
    }
    auto reflects = [](const Vec3& r) { return maxComponent(r) > 0; };
    return std::any_of(grid.reflectance.begin(), grid.reflectance.end(), reflects) ||
           std::any_of(grid.layers.reflectance.begin(), grid.layers.reflectance.end(), reflects);
  }

  /// Texels of one layer's light: its VDLs, or its SH terms, and its
  /// surface texel when the octree has them.
  size_t texelsOf(int vdlCount) const { return lightTexelsOf(vdlCount) + (surfaces_ ? 1 : 0); }
  /// The light's texels alone: what a layer block's header counts.
  size_t lightTexelsOf(int vdlCount) const {
    return sh_ ? size_t(grid_.shTerms) : size_t(vdlCount);
  }

  /// A surface texel (octree_layout.h): the reflectance of the surface the
  /// light before it was gathered on, and that surface's normal; zero
  /// where the surface has no normal.
  void writeSurface(const Vec3& reflectance, const Vec3& normal) {
    if (!surfaces_) return;
    const bool oriented = lengthSquared(normal) > 0.25f;
    const Vec3 n = oriented ? normalize(normal) : Vec3{0, 0, 1};
    writeTexel(nextVdl_++, oriented ? storedReflectance(reflectance) : Vec3{},
               loPackDirection(n.x, n.y, n.z));
  }
  const Vec3& reflectanceOf(size_t v) const { return grid_.reflectance[v]; }

  /// Texels of a voxel's leaf: its light, or a layer block (octree_layout.h).
  size_t voxelTexels(size_t v) const {
    if (!headers_.empty()) return 1 + texelsOf(grid_.vdlCount[v]);
    if (extraCount_[v] == 0) return texelsOf(grid_.vdlCount[v]);
    size_t n = 2 + texelsOf(grid_.vdlCount[v]);
    for (uint32_t e = extraFirst_[v]; e < extraFirst_[v] + extraCount_[v]; ++e) {
      n += 1 + texelsOf(grid_.layers.vdlCount[e]);
    }
    return n;
  }

  /// Texels of a leaf: a collapsed one holds its light's texels.
  size_t leafTexels(const Leaf& leaf) const {
    if (leaf.level == depth_) return voxelTexels(leaf.voxel);
    const CollapsedLeaf& c = adaptive_.leaves[leaf.voxel];
    return (headers_.empty() ? 0 : 1) + (sh_ ? c.sh.size() : c.vdls.size()) + (surfaces_ ? 1 : 0);
  }

  /// Lit voxels in Morton order. A voxel without VDLs is left out entirely:
  /// the flag cannot say "leaf with 0 VDLs" (0 = empty), and an empty branch
  /// reads as no indirect light, which is what a voxel without VDLs
  /// contributes. With adaptive leaves, voxels a collapsed leaf holds are
  /// replaced by it.
  void collectLeaves() {
    leaves_.reserve(grid_.size());
    for (size_t v = 0; v < grid_.size(); ++v) {
      if ((grid_.lit(v) || extraCount_[v] > 0) && !adaptive_.collapsed[v]) {
        leaves_.push_back({mortonCode(grid_.coords[v], depth_), uint32_t(v), depth_});
      }
    }
    for (size_t k = 0; k < adaptive_.leaves.size(); ++k) {
      const CollapsedLeaf& c = adaptive_.leaves[k];
      const uint64_t code = mortonCode(c.coord, c.level) << (3 * (depth_ - c.level));
      leaves_.push_back({code, uint32_t(k), c.level});
    }
    std::sort(leaves_.begin(), leaves_.end(),
              [](const Leaf& a, const Leaf& b) { return a.code < b.code; });
    for (size_t i = 1; i < leaves_.size(); ++i) {
      if (leaves_[i].code == leaves_[i - 1].code) {
        throw InputError("GPU octree: voxel " + grid_.coords[leaves_[i].voxel].ToString() +
                         " appears twice (indices " + std::to_string(leaves_[i - 1].voxel) +
                         " and " + std::to_string(leaves_[i].voxel) + ")");
      }
    }
  }

  /// Nodes per level, sorted: level l holds the distinct ancestors code >>
  /// 3(depth - l) of the leaves at level l or below; a node is a leaf
  /// (levelLeaf = its index in `leaves`) or inner (-1). Tiles are allocated
  /// breadth first: one tile per inner node, in level order, Morton order
  /// inside a level (= BFS with children visited in child-index order), so
  /// the layout does not depend on the input order.
  void buildLevels() {
    levels_.assign(size_t(depth_) + 1, {});
    levelLeaf_.assign(size_t(depth_) + 1, {});
    levels_[0].push_back(0);
    levelLeaf_[0].push_back(-1);
    for (int l = 1; l <= depth_; ++l) {
      std::vector<uint64_t>& nodes = levels_[size_t(l)];
      const int shift = 3 * (depth_ - l);
      for (size_t i = 0; i < leaves_.size(); ++i) {
        const Leaf& leaf = leaves_[i];
        if (leaf.level < l) continue;
        uint64_t code = leaf.code >> shift;
        if (nodes.empty() || nodes.back() != code) {
          nodes.push_back(code);
          levelLeaf_[size_t(l)].push_back(leaf.level == l ? int64_t(i) : -1);
        }
      }
    }
    // Tile of each inner node: levelTile[l][j] (unused for leaves).
    levelTile_.assign(size_t(depth_) + 1, {});
    for (int l = 0; l < depth_; ++l) {
      levelTile_[size_t(l)].assign(levels_[size_t(l)].size(), 0);
      for (size_t j = 0; j < levels_[size_t(l)].size(); ++j) {
        if (levelLeaf_[size_t(l)][j] < 0) levelTile_[size_t(l)][j] = tileCount_++;
      }
    }
  }

  /// Near-cubic tile arrangement within the 8-bit tile coordinates and the
  /// context's 3D texture size (2 texels per tile per axis).
  void arrangeTiles() {
    const int64_t maxPerAxis =
        std::min<int64_t>(LO_MAX_TILES_PER_AXIS, int64_t(params_.max3DTextureSize / 2));
    const int64_t maxTiles = maxPerAxis * maxPerAxis * maxPerAxis;
    if (int64_t(tileCount_) > maxTiles) {
      std::ostringstream os;
      os << "GPU octree: " << tileCount_ << " node tiles needed but the pool holds at most "
         << maxTiles << " (" << maxPerAxis << "^3 tiles: ";
      if (maxPerAxis < int64_t(LO_MAX_TILES_PER_AXIS)) {
        os << "3D texture size limit " << params_.max3DTextureSize << " texels / 2 per tile";
      } else {
        os << "8-bit tile coordinates, 256 per axis";
      }
      os << "); over by " << int64_t(tileCount_) - maxTiles << " tiles. Lower the grid depth "
         << depth_ << " or light fewer voxels";
      throw InputError(os.str());
    }
    out_.depth = depth_;
    out_.origin = grid_.frame.origin;
    out_.cubeSize = grid_.frame.voxelSize * float(grid_.frame.resolution());
    const int64_t n = int64_t(tileCount_);
    const int64_t tx = std::min(maxPerAxis, ceilRoot(n, 3));
    const int64_t rest = (n + tx - 1) / tx;
    const int64_t ty = std::min(maxPerAxis, ceilRoot(rest, 2));
    const int64_t tz = (n + tx * ty - 1) / (tx * ty);
    LO_CHECK_LE(tz, maxPerAxis);
    out_.tilesX = int(tx);
    out_.tilesY = int(ty);
    out_.tilesZ = int(tz);
  }

  /// VDL texture size and the 24-bit address space.
  void sizeVdlTexture() {
    for (const Leaf& leaf : leaves_) vdlTotal_ += leafTexels(leaf);
    const size_t addressSpace = size_t(LO_MAX_ADDRESS) + 1;
    if (vdlTotal_ > addressSpace) {
      throw InputError("GPU octree: " + std::to_string(vdlTotal_) +
                       " VDLs exceed the 24-bit VDL address space (" +
                       std::to_string(addressSpace) + ") by " +
                       std::to_string(vdlTotal_ - addressSpace));
    }
    width_ = std::max<size_t>(1, std::min<size_t>(LO_VDL_TEXTURE_WIDTH, vdlTotal_));
    const size_t height = std::max<size_t>(1, (vdlTotal_ + width_ - 1) / width_);
    const size_t limit = size_t(params_.max2DTextureSize);
    if (width_ > limit || height > limit) {
      const bool wide = width_ > limit;
      const size_t size = wide ? width_ : height;
      throw InputError(
          "GPU octree: the VDL texture needs " + std::to_string(width_) + " x " +
          std::to_string(height) + " texels for " + std::to_string(vdlTotal_) + " VDLs; its " +
          (wide ? "width" : "height") + " exceeds the 2D texture size " + "limit " +
          std::to_string(params_.max2DTextureSize) + " by " + std::to_string(size - limit));
    }
    out_.vdlWidth = int(width_);
    out_.vdlHeight = int(height);
    out_.halfFloat = params_.halfFloat || params_.compact;
    out_.compact = params_.compact;
    out_.shTerms = grid_.shTerms;
  }

  /// The compact texels' power-of-two scale.
  void chooseScale() {
    if (out_.compact && sh_) {
      // Signed SH terms ride as halves times the scale (octree_layout.h): the
      // largest magnitude fits under 2^14 of the half's 65504.
      float largest = 0;
      for (const Vec3& t : grid_.sh) {
        largest = std::max({largest, std::fabs(t.x), std::fabs(t.y), std::fabs(t.z)});
      }
      for (const Vec3& t : grid_.layers.sh) {
        largest = std::max({largest, std::fabs(t.x), std::fabs(t.y), std::fabs(t.z)});
      }
      out_.irradianceScale =
          largest > 0 ? std::exp2(std::ceil(std::log2(double(largest) / 16384.0))) : 1.0f;
    } else if (out_.compact) {
      // The brightest texel after the cosine correction (at most 1 / the
      // smallest cosine it divides by) fits under 2^15 of RGB9E5's 65408.
      float brightest = 0;
      for (const Vdl& v : grid_.vdls) {
        brightest = std::max({brightest, v.irradiance.x, v.irradiance.y, v.irradiance.z});
      }
      for (const Vdl& v : grid_.layers.vdls) {
        brightest = std::max({brightest, v.irradiance.x, v.irradiance.y, v.irradiance.z});
      }
      brightest /= kMinCorrectionCosine;
      out_.irradianceScale =
          brightest > 0 ? std::exp2(std::ceil(std::log2(double(brightest) / 32768.0))) : 1.0f;
    }
  }

  void allocate() {
    const size_t vdlFloats = size_t(out_.vdlWidth) * size_t(out_.vdlHeight) * 4;
    if (out_.halfFloat) {
      out_.vdlTexelsHalf.assign(vdlFloats, 0);
    } else {
      out_.vdlTexels.assign(vdlFloats, 0.0f);
    }
    out_.pool.assign(
        size_t(out_.poolWidth()) * size_t(out_.poolHeight()) * size_t(out_.poolDepth()) * 4, 0);
  }

  void tileCoord(size_t tile, uint32_t& tx, uint32_t& ty, uint32_t& tz) const {
    tx = uint32_t(tile % size_t(out_.tilesX));
    ty = uint32_t((tile / size_t(out_.tilesX)) % size_t(out_.tilesY));
    tz = uint32_t(tile / (size_t(out_.tilesX) * size_t(out_.tilesY)));
  }

  /// The pool texel of child `child` of tile `tile`.
  uint8_t* poolTexel(size_t tile, uint32_t child) {
    uint32_t tx, ty, tz;
    tileCoord(tile, tx, ty, tz);
    const size_t poolW = size_t(out_.poolWidth()), poolH = size_t(out_.poolHeight());
    const size_t x = 2 * tx + (child & 1u), y = 2 * ty + ((child >> 1) & 1u),
                 z = 2 * tz + ((child >> 2) & 1u);
    return &out_.pool[((z * poolH + y) * poolW + x) * 4];
  }

  size_t vdlOffset(size_t index) const {
    return (size_t(loVdlTexelY(uint(index))) * width_ + size_t(loVdlTexelX(uint(index)))) * 4;
  }

  /// One texel: rgb as floats (halves in the half texture), a as the float
  /// of an integer (the packed direction, a count).
  void writeTexel(size_t index, const Vec3& rgb, float a) {
    const size_t offset = vdlOffset(index);
    if (out_.compact && !sh_) {  // headers: without the scale
      const uint32_t bits = encodeRgb9e5(rgb);
      out_.vdlTexelsHalf[offset] = uint16_t(bits & 0xffffu);
      out_.vdlTexelsHalf[offset + 1] = uint16_t(bits >> 16);
      out_.vdlTexelsHalf[offset + 3] = uint16_t(a);
    } else if (out_.halfFloat) {
      for (int c = 0; c < 3; ++c) out_.vdlTexelsHalf[offset + size_t(c)] = floatToHalf(rgb[c]);
      out_.vdlTexelsHalf[offset + 3] = uint16_t(a);
    } else {
      for (int c = 0; c < 3; ++c) out_.vdlTexels[offset + size_t(c)] = rgb[c];
      out_.vdlTexels[offset + 3] = a;
    }
  }

  /// `normal`: the voxel's normal for params.cosineCorrection, else zero.
  void writeVdl(size_t index, const Vdl& vdl, const Vec3& normal) {
    const size_t offset = vdlOffset(index);
    const Vec3 d = normalize(vdl.direction);
    const float packed = loPackDirection(d.x, d.y, d.z);
    // The cosine the shader will apply, with the decoded direction (zero normal: none).
    const Vec3 irradiance = vdlIntensity(vdl, normal, true);
    if (out_.compact) {
      const uint32_t bits = encodeRgb9e5(irradiance / out_.irradianceScale);
      out_.vdlTexelsHalf[offset] = uint16_t(bits & 0xffffu);
      out_.vdlTexelsHalf[offset + 1] = uint16_t(bits >> 16);
      out_.vdlTexelsHalf[offset + 3] = uint16_t(packed);
    } else if (out_.halfFloat) {
      for (int c = 0; c < 3; ++c) {
        out_.vdlTexelsHalf[offset + size_t(c)] = floatToHalf(irradiance[c]);
      }
      out_.vdlTexelsHalf[offset + 3] = uint16_t(packed);
    } else {
      for (int c = 0; c < 3; ++c) out_.vdlTexels[offset + size_t(c)] = irradiance[c];
      out_.vdlTexels[offset + 3] = packed;
    }
  }

  /// One SH term: compact ones as halves divided by the scale.
  void writeSh(size_t index, const Vec3& term) {
    writeTexel(index, out_.compact ? term / out_.irradianceScale : term, 0.0f);
  }

  /// A leaf's pool texel: the address of its first VDL texel and `flag`.
  void writeLeafTexel(uint8_t* t, uint8_t flag) const {
    const uint address = uint(nextVdl_);
    t[0] = uint8_t(loPackAddressR(address));
    t[1] = uint8_t(loPackAddressG(address));
    t[2] = uint8_t(loPackAddressB(address));
    t[3] = flag;
  }

  /// Each node at level l >= 1 is one texel in its parent's tile. Parents
  /// are found by walking the sorted parent level alongside the sorted children.
  void writeLevel(int l) {
    const std::vector<uint64_t>& parents = levels_[size_t(l) - 1];
    const std::vector<uint64_t>& nodes = levels_[size_t(l)];
    size_t p = 0;
    for (size_t j = 0; j < nodes.size(); ++j) {
      const uint64_t code = nodes[j];
      while (parents[p] != code >> 3) ++p;
      uint8_t* t = poolTexel(levelTile_[size_t(l) - 1][p], uint32_t(code & 7u));
      const int64_t leafIndex = levelLeaf_[size_t(l)][j];
      if (leafIndex < 0) {
        uint32_t tx, ty, tz;
        tileCoord(levelTile_[size_t(l)][j], tx, ty, tz);
        t[0] = uint8_t(tx);
        t[1] = uint8_t(ty);
        t[2] = uint8_t(tz);
        t[3] = uint8_t(LO_FLAG_INNER);
      } else if (l < depth_) {
        writeCollapsedLeaf(t, adaptive_.leaves[leaves_[size_t(leafIndex)].voxel]);
      } else {
        const Leaf& leaf = leaves_[size_t(leafIndex)];
        LO_CHECK_EQ(leaf.code, code);
        writeVoxelLeaf(t, leaf.voxel);
      }
    }
  }

  /// A collapsed leaf: its texels, stored as they are (intensities, SH terms).
  void writeCollapsedLeaf(uint8_t* t, const CollapsedLeaf& c) {
    // A merged free-space leaf: the box its voxels' light filled together.
    if (!headers_.empty()) {
      Vec3 header;
      for (int a = 0; a < 3; ++a) header[a] = loPackVolumeBox(c.litLower[a], c.litUpper[a]);
      writeTexel(nextVdl_++, header, 0.0f);
    }
    writeLeafTexel(t, uint8_t(sh_ ? 1u : uint(c.vdls.size())));
    if (sh_) {
      for (const Vec3& term : c.sh) writeSh(nextVdl_++, term);
    } else {
      for (const Vdl& vdl : c.vdls) writeVdl(nextVdl_++, vdl, Vec3{0, 0, 0});
    }
    writeSurface(c.reflectance, c.normal);
  }

  /// A voxel's leaf: its VDLs (or SH terms), or a layer block.
  void writeVoxelLeaf(uint8_t* t, size_t v) {
    const int count = grid_.vdlCount[v];
    if (!headers_.empty()) writeTexel(nextVdl_++, headers_[v], 0.0f);
    // An SH leaf's flag is 1 (a leaf); its texel count is the octree's shTerms.
    writeLeafTexel(t, uint8_t(extraCount_[v] > 0 ? LO_FLAG_LAYERED : sh_ ? 1u : uint(count)));
    if (extraCount_[v] > 0) {
      writeLayerBlock(v);
      return;
    }
    const Vec3 surfaceNormal = grid_.normals.size() == grid_.size() ? grid_.normals[v] : Vec3{};
    if (sh_) {
      for (int i = 0; i < grid_.shTerms; ++i) writeSh(nextVdl_++, grid_.shOf(v)[i]);
    } else {
      const Vdl* vdls = grid_.vdlsOf(v);
      const Vec3 normal = params_.cosineCorrection && lengthSquared(surfaceNormal) > 0
                              ? normalize(surfaceNormal)
                              : Vec3{0, 0, 0};
      for (int i = 0; i < count; ++i) writeVdl(nextVdl_++, vdls[i], normal);
    }
    if (surfaces_) writeSurface(reflectanceOf(v), surfaceNormal);
  }

  /// A layer block (octree_layout.h): header, then per layer its header and VDLs.
  void writeLayerBlock(size_t v) {
    const int count = grid_.vdlCount[v];
    const uint32_t e0 = extraFirst_[v];
    const int layers = 1 + extraCount_[v];
    Vec3 counts{float(lightTexelsOf(count)), 0, 0};
    for (int l = 1; l < layers; ++l) {
      counts[l] = float(lightTexelsOf(grid_.layers.vdlCount[e0 + uint32_t(l) - 1]));
    }
    writeTexel(nextVdl_++, counts, float(layers));
    const Vec3 corner{float(grid_.coords[v].x), float(grid_.coords[v].y), float(grid_.coords[v].z)};
    auto local = [&](const Vec3& world) {
      return (world - grid_.frame.origin) / grid_.frame.voxelSize - corner;
    };
    auto writeLayer = [&](const Vec3& layerNormal, const Vec3& point, const Vdl* layerVdls,
                          int layerCount, const Vec3* layerSh, const Vec3& reflectance) {
      const Vec3 n = normalize(layerNormal);
      writeTexel(nextVdl_++, local(point), loPackDirection(n.x, n.y, n.z));
      if (sh_) {
        for (int i = 0; i < grid_.shTerms; ++i) writeSh(nextVdl_++, layerSh[i]);
      } else {
        const Vec3 correction = params_.cosineCorrection ? n : Vec3{0, 0, 0};
        for (int i = 0; i < layerCount; ++i) writeVdl(nextVdl_++, layerVdls[i], correction);
      }
      writeSurface(reflectance, n);
    };
    const Vec3 point0 = grid_.points.empty()
                            ? grid_.frame.origin + (corner + Vec3(0.5f)) * grid_.frame.voxelSize
                            : grid_.points[v];
    writeLayer(grid_.normals[v], point0, grid_.vdlsOf(v), count, sh_ ? grid_.shOf(v) : nullptr,
               surfaces_ ? reflectanceOf(v) : Vec3{});
    for (int l = 1; l < layers; ++l) {
      const uint32_t e = e0 + uint32_t(l) - 1;
      writeLayer(grid_.layers.normals[e], grid_.layers.points[e], grid_.layerVdlsOf(e),
                 grid_.layers.vdlCount[e], sh_ ? grid_.layerShOf(e) : nullptr,
                 surfaces_ ? grid_.layers.reflectance[e] : Vec3{});
    }
  }

  const VdlGrid& grid_;
  const GpuOctreeParams& params_;
  const int depth_;
  const bool sh_;
  const bool surfaces_;  ///< leaves and layers end in a surface texel
  const AdaptiveLeaves adaptive_;
  std::vector<Vec3> headers_;  ///< free-space octree: per voxel
  std::vector<uint32_t> extraFirst_;
  std::vector<uint8_t> extraCount_;
  std::vector<Leaf> leaves_;
  std::vector<std::vector<uint64_t>> levels_;
  std::vector<std::vector<int64_t>> levelLeaf_;
  std::vector<std::vector<size_t>> levelTile_;
  size_t tileCount_ = 0;
  size_t vdlTotal_ = 0;
  size_t width_ = 1;    ///< of the VDL texture
  size_t nextVdl_ = 0;  ///< the next VDL texel to write
  GpuOctree out_;
};

}  // namespace gpu_octree_internal

GpuOctree buildGpuOctree(const VdlGrid& grid, const GpuOctreeParams& params) {
  gpu_octree_internal::validate(grid, params);
  return gpu_octree_internal::OctreeBuilder(grid, params).build();
}

GpuOctree buildVolumeOctree(const VolumeLight& volume, const GpuOctreeParams& params) {
  using namespace layout;
  const size_t n = volume.size();
  if (volume.frame.depth < 1 || volume.irradiance.size() != n ||
      volume.sh.size() != n * size_t(volume.shTerms) || volume.litLower.size() != n ||
      volume.litUpper.size() != n) {
    throw InputError("free-space octree: depth " + std::to_string(volume.frame.depth) + ", " +
                     std::to_string(n) + " voxels and arrays of other lengths");
  }
  // The volume as a light grid of SH voxels without surfaces.
  VdlGrid grid;
  grid.frame = volume.frame;
  grid.coords = volume.coords;
  grid.shTerms = volume.shTerms;
  grid.maxVdls = 1;
  resizeVoxelArrays(grid);  // zero normals, counts and VDL slots beside them
  grid.irradiance = volume.irradiance;
  grid.sh = volume.sh;
  std::vector<Vec3> headers(n);
  for (size_t v = 0; v < n; ++v) {
    for (int a = 0; a < 3; ++a) {
      headers[v][a] = loPackVolumeBox(volume.litLower[v][a], volume.litUpper[v][a]);
    }
  }
  GpuOctreeParams p = params;
  p.cosineCorrection = false;
  gpu_octree_internal::validate(grid, p);
  AdaptiveLeaves adaptive = gpu_octree_internal::collapseVolume(volume, params.volumeTolerance);
  return gpu_octree_internal::OctreeBuilder(grid, p, std::move(adaptive), std::move(headers)).build();
}

std::string GpuOctree::ToString() const {
  using gpu_octree_internal::kib;
  std::ostringstream os;
  const double leaves = leafCount > 0 ? double(leafCount) : 1.0;
  os << "GpuOctree[depth " << depth << ", origin " << origin.ToString() << ", cube " << cubeSize
     << ", leaves " << leafCount
     << (collapsedLeaves > 0 ? " (" + std::to_string(collapsedLeaves) + " adaptive, for " +
                                   std::to_string(collapsedVoxels) + " voxels)"
                             : std::string())
     << ", tiles " << nodeCount << " in " << tilesX << "x" << tilesY
     << "x" << tilesZ << " (pool " << poolWidth() << "x" << poolHeight() << "x" << poolDepth()
     << " RGBA8, " << kib(poolBytes()) << "), VDLs " << vdlCount << " in " << vdlWidth << "x"
     << vdlHeight
     << (compact ? (shTerms > 0 ? " RGBA16UI(scaled half)" : " RGBA16UI(RGB9E5)")
                 : halfFloat ? " RGBA16UI(half)" : " RGBA32F")
     << (shTerms > 0 ? ", SH " + std::to_string(shTerms) + " terms" : std::string()) << " ("
     << kib(vdlBytes())
     << "), bytes/leaf: pool " << std::fixed << std::setprecision(2) << double(poolBytes()) / leaves
     << " + VDLs " << double(vdlBytes()) / leaves << "]";
  return os.str();
}

std::string octreeMemoryReport(const GpuOctree& octree) {
  // Paper §4.2.1: 512 KiB (octree) + 4 MiB (VDLs) for 100k leaves, depth 6, k = 4.
  constexpr double kPaperLeaves = 100000.0, kPaperVdlsPerLeaf = 4.0;
  constexpr double kPaperPoolBytes = 512.0 * 1024.0, kPaperVdlBytes = 4.0 * 1024.0 * 1024.0;
  const double leaves = octree.leafCount > 0 ? double(octree.leafCount) : 1.0;
  const double vdls = octree.vdlCount > 0 ? double(octree.vdlCount) : 1.0;
  std::ostringstream os;
  os << std::fixed << std::setprecision(2);
  os << "                 pool B/leaf  VDL B/leaf  B/VDL  VDLs/leaf\n";
  os << "paper (§4.2.1)   " << std::setw(11) << kPaperPoolBytes / kPaperLeaves << std::setw(12)
     << kPaperVdlBytes / kPaperLeaves << std::setw(7)
     << kPaperVdlBytes / (kPaperLeaves * kPaperVdlsPerLeaf) << std::setw(11) << kPaperVdlsPerLeaf
     << "\n";
  os << "this octree      " << std::setw(11) << double(octree.poolBytes()) / leaves << std::setw(12)
     << double(octree.vdlBytes()) / leaves << std::setw(7) << double(octree.vdlBytes()) / vdls
     << std::setw(11) << double(octree.vdlCount) / leaves << "\n";
  os << "(" << octree.leafCount << " leaves, " << octree.nodeCount << " tiles of 32 B used, "
     << octree.tilesX * octree.tilesY * octree.tilesZ << " allocated; "
     << double(octree.leafCount) / double(std::max<size_t>(1, octree.nodeCount))
     << " leaves per tile; " << (octree.halfFloat ? 8 : 16) << " B per VDL texel)\n";
  return os.str();
}

}  // namespace lo
