// Converting a VDL grid between depths and VDL counts (docs/convert.md):
// merging children into coarser voxels, interpolating parents onto finer
// voxels, re-clustering per voxel. TBB over voxels; each voxel writes only its
// own slots and seeds its K-means with its own index, so results do not depend
// on the thread count.

#include "cluster/resample.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "lightgrid/light_grid_schema.h"

namespace lo {
namespace resample_internal {

constexpr size_t kGrainVoxels = 64;

// The canonical voxel order of the project (docs/vdb-contract.md): 8^3 block
// (floor division) first, then the offset inside the block.
bool canonicalLess(const Coord& a, const Coord& b) {
  Coord ba{a.x >> 3, a.y >> 3, a.z >> 3}, bb{b.x >> 3, b.y >> 3, b.z >> 3};
  if (ba != bb) return ba < bb;
  return Coord{a.x & 7, a.y & 7, a.z & 7} < Coord{b.x & 7, b.y & 7, b.z & 7};
}

void checkClusterParams(const ClusterParams& params) {
  if (params.vdls < 1 || params.vdls > kMaxVdls) {
    throw InputError("VDL count " + std::to_string(params.vdls) + " is outside [1, " +
                     std::to_string(kMaxVdls) + "]");
  }
}

VdlGrid emptyLike(const GridFrame& frame, int maxVdls, size_t n) {
  VdlGrid out;
  out.frame = frame;
  out.maxVdls = maxVdls;
  out.coords.resize(n);
  resizeVoxelArrays(out);
  return out;
}

/// Weighted contributions of input voxels to one output voxel, accumulated in
/// double in the order given so that the result is independent of threads.
struct Mixer {
  std::vector<DirectionSample> samples;
  double irr[3] = {0, 0, 0};
  double reflected[3] = {0, 0, 0};  ///< sum of w E reflectance, per channel
  double photonCount = 0, radius = 0;
  // Variance of the weighted sum's luminance from the inputs' noise, taken
  // as independent (neighbouring gathers share some photons, so this
  // rather underestimates a coarse voxel's noise).
  double noiseVariance = 0;
  // Weighted variance of the input voxels' angular errors, weight = the
  // power (average irradiance) each brings, like the K-means weights.
  double varianceSum = 0, varianceWeight = 0;

  void reset() {
    samples.clear();
    irr[0] = irr[1] = irr[2] = 0;
    reflected[0] = reflected[1] = reflected[2] = 0;
    photonCount = radius = varianceSum = varianceWeight = noiseVariance = 0;
  }

  void add(const VdlGrid& g, size_t v, double w) {
    const Vec3& e = g.irradiance[v];
    irr[0] += w * e.x;
    irr[1] += w * e.y;
    irr[2] += w * e.z;
    if (!g.reflectance.empty()) {
      for (int c = 0; c < 3; ++c) reflected[c] += w * double(e[c]) * double(g.reflectance[v][c]);
    }
    photonCount += w * g.photonCount[v];
    radius += w * g.radius[v];
    if (!g.noise.empty()) {
      const double sigma = w * double(g.noise[v]) * double(luminance(e));
      noiseVariance += sigma * sigma;
    }
    const double power = w * std::max(0.0f, average(e));
    varianceSum += power * double(g.angularError[v]) * g.angularError[v];
    varianceWeight += power;
    const Vdl* vdls = g.vdlsOf(v);
    for (int i = 0; i < int(g.vdlCount[v]); ++i) {
      samples.push_back({vdls[i].direction, vdls[i].irradiance * float(w)});
    }
  }

  /// Clusters the samples and writes output voxel `o` (irradiance, VDLs,
  /// counts, radius, error); normal and area are the caller's.
  void finish(const ClusterParams& params, VdlGrid& out, size_t o) const {
    out.irradiance[o] = Vec3(float(irr[0]), float(irr[1]), float(irr[2]));
    for (int c = 0; c < 3; ++c) out.reflectance[o][c] = irr[c] > 0 ? float(reflected[c] / irr[c]) : 0.0f;
    out.photonCount[o] = float(photonCount);
    out.radius[o] = float(radius);
    const double y = double(luminance(out.irradiance[o]));
    out.noise[o] = y > 0 ? float(std::sqrt(noiseVariance) / y) : 0.0f;
    ClusterResult c = clusterDirections(samples.data(), samples.size(), params.vdls, params, o);
    // Law of total variance, approximately (chord lengths are not additive):
    // the spread of the photons around their old VDLs plus the spread of the
    // old VDLs around the new ones.
    const double inner = varianceWeight > 0 ? varianceSum / varianceWeight : 0.0;
    out.angularError[o] = float(std::sqrt(double(c.angularError) * c.angularError + inner));
    out.vdlCount[o] = uint8_t(c.count);
    Vdl* dst = out.vdls.data() + o * size_t(out.maxVdls);
    for (int i = 0; i < c.count; ++i) dst[i] = c.vdls[size_t(i)];
  }
};

using Mixers = tbb::enumerable_thread_specific<Mixer>;

struct CoarsenBody {
  const VdlGrid& in;
  const std::vector<size_t>& children;    // fine indices grouped by coarse voxel
  const std::vector<size_t>& groupStart;  // children[groupStart[o] .. groupStart[o+1])
  const ClusterParams& params;
  Mixers& mixers;
  VdlGrid& out;

  void operator()(const tbb::blocked_range<size_t>& range) const {
    Mixer& m = mixers.local();
    for (size_t o = range.begin(); o != range.end(); ++o) {
      const size_t b = groupStart[o], e = groupStart[o + 1];
      double area = 0;
      double normal[3] = {0, 0, 0};
      for (size_t i = b; i < e; ++i) area += in.areas[children[i]];
      // Area weights make Σ E·A over the coarse voxel equal the children's
      // sum. Without area (all children zero: a file with the optional area
      // grid dropped, or degenerate geometry) every child counts the same.
      const bool byArea = area > 0;
      m.reset();
      for (size_t i = b; i < e; ++i) {
        const size_t c = children[i];
        const double w = byArea ? in.areas[c] / area : 1.0 / double(e - b);
        m.add(in, c, w);
        const double a = byArea ? double(in.areas[c]) : 1.0;
        normal[0] += a * in.normals[c].x;
        normal[1] += a * in.normals[c].y;
        normal[2] += a * in.normals[c].z;
      }
      // photon_count is a sum, not a mean: the coarse estimate rests on all
      // the photons its children gathered.
      m.photonCount = 0;
      for (size_t i = b; i < e; ++i) m.photonCount += in.photonCount[children[i]];
      m.finish(params, out, o);
      out.areas[o] = float(area);
      out.normals[o] = normalize(Vec3(float(normal[0]), float(normal[1]), float(normal[2])));
    }
  }
};

struct RefineBody {
  const VdlGrid& in;
  const SurfaceGrid& fine;
  int levels;
  const ClusterParams& params;
  Mixers& mixers;
  VdlGrid& out;
  std::vector<uint8_t>& orphan;

  int64_t findParent(const Coord& c) const {
    auto it = std::lower_bound(in.coords.begin(), in.coords.end(), c, canonicalLess);
    return (it != in.coords.end() && *it == c) ? int64_t(it - in.coords.begin()) : -1;
  }

  void operator()(const tbb::blocked_range<size_t>& range) const {
    Mixer& m = mixers.local();
    const double scale = std::ldexp(1.0, -levels);  // parent voxels per fine voxel
    for (size_t o = range.begin(); o != range.end(); ++o) {
      const Coord& f = fine.coords[o];
      // Fine voxel centre in parent index space, where parent voxel p's centre
      // sits at p + 0.5: trilinear between the 8 nearest parent centres.
      double pos[3], t[3];
      int base[3];
      for (int a = 0; a < 3; ++a) {
        const int fa = a == 0 ? f.x : (a == 1 ? f.y : f.z);
        pos[a] = (fa + 0.5) * scale - 0.5;
        base[a] = int(std::floor(pos[a]));
        t[a] = pos[a] - base[a];
      }
      std::pair<int64_t, double> parents[8];
      int found = 0;
      double total = 0;
      for (int corner = 0; corner < 8; ++corner) {
        const int dx = corner & 1, dy = (corner >> 1) & 1, dz = (corner >> 2) & 1;
        const double w = (dx ? t[0] : 1 - t[0]) * (dy ? t[1] : 1 - t[1]) * (dz ? t[2] : 1 - t[2]);
        if (!(w > 0)) continue;
        const int64_t p = findParent(Coord{base[0] + dx, base[1] + dy, base[2] + dz});
        if (p < 0) continue;  // no geometry there at the coarse depth: not a sample
        parents[found++] = {p, w};
        total += w;
      }
      if (found == 0) {
        // Cannot happen for nested voxelizations of one scene (the parent
        // containing a fine voxel's box overlaps the same triangle), but a
        // file from another scene could get here.
        const int64_t p = findParent(Coord{f.x >> levels, f.y >> levels, f.z >> levels});
        if (p >= 0) {
          parents[found++] = {p, 1.0};
          total = 1.0;
        }
      }
      m.reset();
      for (int i = 0; i < found; ++i)
        m.add(in, size_t(parents[i].first), parents[i].second / total);
      m.finish(params, out, o);
      orphan[o] = found == 0;
      out.normals[o] = fine.normals[o];
      out.areas[o] = fine.areas[o];
    }
  }
};

struct ReclusterBody {
  const VdlGrid& in;
  const ClusterParams& params;
  Mixers& mixers;
  VdlGrid& out;

  void operator()(const tbb::blocked_range<size_t>& range) const {
    Mixer& m = mixers.local();
    for (size_t v = range.begin(); v != range.end(); ++v) {
      m.reset();
      m.add(in, v, 1.0);
      m.finish(params, out, v);
      // Keep the stored totals bit for bit: the mixer's double round trip is
      // exact for weight 1, but say so in code rather than rely on it.
      out.irradiance[v] = in.irradiance[v];
      out.reflectance[v] = in.reflectance.empty() ? Vec3{} : in.reflectance[v];
      out.photonCount[v] = in.photonCount[v];
      out.noise[v] = in.noise.empty() ? 0.0f : in.noise[v];
      out.radius[v] = in.radius[v];
    }
  }
};

}  // namespace resample_internal

void checkNestedFrames(const GridFrame& a, const GridFrame& b, const char* what) {
  const double expected = std::ldexp(double(a.voxelSize), a.depth - b.depth);
  const double tol = 1e-5 * std::max(expected, double(a.voxelSize));
  bool ok = std::abs(double(b.voxelSize) - expected) <= tol;
  for (int k = 0; k < 3; ++k) ok = ok && std::abs(double(a.origin[k]) - b.origin[k]) <= tol;
  if (!ok) {
    throw InputError(std::string(what) + ": the grid at depth " + std::to_string(b.depth) +
                     " (origin " + b.origin.ToString() + ", voxel size " +
                     std::to_string(b.voxelSize) + ") is not nested in the input's grid at depth " +
                     std::to_string(a.depth) + " (origin " + a.origin.ToString() + ", voxel size " +
                     std::to_string(a.voxelSize) + ", so expected " + std::to_string(expected) +
                     ") -- was the input baked from this scene?");
  }
}

VdlGrid coarsenVdlGrid(const VdlGrid& grid, int depth, const ClusterParams& params) {
  using namespace resample_internal;
  checkClusterParams(params);
  if (depth < 1 || depth >= grid.frame.depth) {
    throw InputError("coarser depth " + std::to_string(depth) + " must be in [1, " +
                     std::to_string(grid.frame.depth - 1) + "] for an input of depth " +
                     std::to_string(grid.frame.depth));
  }
  const int levels = grid.frame.depth - depth;
  const size_t n = grid.size();
  LO_CHECK_EQ(grid.vdls.size(), n * size_t(grid.maxVdls));

  // Group the fine voxels by coarse voxel, coarse voxels in canonical order,
  // children in input order (the order their contributions are summed in).
  std::vector<std::pair<Coord, size_t>> keyed(n);
  for (size_t v = 0; v < n; ++v) {
    const Coord& c = grid.coords[v];
    keyed[v] = {Coord{c.x >> levels, c.y >> levels, c.z >> levels}, v};
  }
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) {
    if (a.first != b.first) return canonicalLess(a.first, b.first);
    return a.second < b.second;
  });
  std::vector<size_t> children(n), groupStart;
  std::vector<Coord> coarseCoords;
  for (size_t i = 0; i < n; ++i) {
    if (i == 0 || keyed[i].first != keyed[i - 1].first) {
      groupStart.push_back(i);
      coarseCoords.push_back(keyed[i].first);
    }
    children[i] = keyed[i].second;
  }
  groupStart.push_back(n);

  GridFrame frame = grid.frame;
  frame.depth = depth;
  frame.voxelSize = float(std::ldexp(double(grid.frame.voxelSize), levels));
  VdlGrid out = emptyLike(frame, params.vdls, coarseCoords.size());
  out.coords = std::move(coarseCoords);
  Mixers mixers;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, out.size(), kGrainVoxels),
                    CoarsenBody{grid, children, groupStart, params, mixers, out});
  return out;
}

VdlGrid refineVdlGrid(const VdlGrid& grid, const SurfaceGrid& finerGeometry,
                      const ClusterParams& params, RefineStats* stats) {
  using namespace resample_internal;
  checkClusterParams(params);
  const GridFrame& fineFrame = finerGeometry.frame;
  if (fineFrame.depth <= grid.frame.depth) {
    throw InputError("finer depth " + std::to_string(fineFrame.depth) +
                     " must be greater than the input's depth " + std::to_string(grid.frame.depth));
  }
  checkNestedFrames(grid.frame, fineFrame, "refining");
  LO_CHECK_EQ(finerGeometry.normals.size(), finerGeometry.size());
  LO_CHECK_EQ(finerGeometry.areas.size(), finerGeometry.size());
  LO_CHECK(std::is_sorted(grid.coords.begin(), grid.coords.end(), canonicalLess));

  const size_t n = finerGeometry.size();
  VdlGrid out = emptyLike(fineFrame, params.vdls, n);
  out.coords = finerGeometry.coords;
  std::vector<uint8_t> orphan(n, 0);
  Mixers mixers;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrainVoxels),
                    RefineBody{grid, finerGeometry, fineFrame.depth - grid.frame.depth, params,
                               mixers, out, orphan});
  if (stats) {
    stats->voxels = n;
    stats->withoutParent = size_t(std::count(orphan.begin(), orphan.end(), uint8_t(1)));
  }
  return out;
}

VdlGrid reclusterVdlGrid(const VdlGrid& grid, const ClusterParams& params) {
  using namespace resample_internal;
  checkClusterParams(params);
  const size_t n = grid.size();
  LO_CHECK_EQ(grid.vdls.size(), n * size_t(grid.maxVdls));
  VdlGrid out = emptyLike(grid.frame, params.vdls, n);
  out.coords = grid.coords;
  // Re-clustering keeps the surface and the gathered totals of the voxels
  // and their layers (the field table's roles) and makes the light again.
  copyFieldsOfRole(grid, out, FieldRole::Surface);
  copyFieldsOfRole(grid, out, FieldRole::Gather);
  Mixers mixers;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrainVoxels),
                    ReclusterBody{grid, params, mixers, out});
  // Surface layers: the same, layer by layer (a few per cent of the voxels).
  const VdlLayers& in = grid.layers;
  VdlLayers& L = out.layers;
  L.voxel = in.voxel;
  resizeLayerArrays(out, in.size());  // the light's arrays, for the new VDL slots
  std::vector<DirectionSample> samples;
  for (size_t e = 0; e < in.size(); ++e) {
    samples.clear();
    const Vdl* vdls = grid.layerVdlsOf(e);
    for (int i = 0; i < in.vdlCount[e]; ++i) samples.push_back({vdls[i].direction, vdls[i].irradiance});
    const ClusterResult c =
        clusterDirections(samples.data(), samples.size(), params.vdls, params, uint64_t(n + e));
    L.vdlCount[e] = uint8_t(c.count);
    L.angularError[e] = std::sqrt(in.angularError[e] * in.angularError[e] +
                                  c.angularError * c.angularError);
    for (int i = 0; i < c.count; ++i) L.vdls[e * size_t(out.maxVdls) + size_t(i)] = c.vdls[size_t(i)];
  }
  return out;
}

}  // namespace lo
