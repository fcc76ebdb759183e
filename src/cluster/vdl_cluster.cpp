// The bake's per-voxel loop: KNN gather (src/gather) then K-means into VDLs
// (paper §3.1.1 and §3.1.2), TBB-parallel over runs of consecutive voxels.

#include "cluster/vdl_cluster.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <octree_layout.h>

#include "core/error.h"

namespace lo {

void projectSh(const DirectionSample* samples, size_t n, const Vec3& normal, int terms, Vec3* out) {
  LO_CHECK(terms >= 1 && terms <= int(layout::LO_SH_MAX_TERMS));
  const bool oriented = lengthSquared(normal) > 0.5f;
  double sum[layout::LO_SH_MAX_TERMS][3] = {};
  double total[3] = {0, 0, 0};
  for (size_t k = 0; k < n; ++k) {
    const Vec3 d = samples[k].direction;
    const Vec3 c = samples[k].value;
    const float cosine = oriented ? std::fabs(dot(normal, d)) : 1.0f;
    const Vec3 intensity = c / std::max(cosine, kShMinCosine);
    for (int i = 0; i < terms; ++i) {
      const double y = double(layout::loShBasis(uint32_t(i), d.x, d.y, d.z));
      for (int a = 0; a < 3; ++a) sum[i][a] += y * double(intensity[a]);
    }
    for (int a = 0; a < 3; ++a) total[a] += double(c[a]);
  }
  double atNormal[3] = {0, 0, 0};
  for (int i = 0; i < terms; ++i) {
    const double band = double(layout::loShCosineBand(uint32_t(i)));
    const double y = oriented ? double(layout::loShBasis(uint32_t(i), normal.x, normal.y, normal.z)) : 0.0;
    for (int a = 0; a < 3; ++a) {
      sum[i][a] *= band;
      atNormal[a] += sum[i][a] * y;
    }
  }
  const double y0 = double(layout::loShBasis(0u, 0.0f, 0.0f, 1.0f));  // the constant term's basis
  for (int a = 0; a < 3; ++a) {
    if (oriented && total[a] > 0 && !(atNormal[a] > 0)) {
      // The truncated series is not positive at the normal (a few photons
      // from grazing directions ring below zero there): keep the estimate
      // as a constant, E(n) = the samples' sum in every direction.
      for (int i = 0; i < terms; ++i) out[i][a] = i == 0 ? float(total[a] / y0) : 0.0f;
      continue;
    }
    const double scale = oriented && atNormal[a] > 0 && total[a] > 0 ? total[a] / atNormal[a] : 1.0;
    for (int i = 0; i < terms; ++i) out[i][a] = float(sum[i][a] * scale);
  }
}

namespace vdl_grid_internal {

// Per-thread state: the gatherer holds candidate scratch; the sample buffer
// and result are reused from voxel to voxel so the loop does not allocate.
struct Worker {
  Worker(const SurfaceGrid& grid, const std::vector<Photon>& photons,
         std::shared_ptr<const BinnedPhotons> binned, const GatherParams& params)
      : gatherer(grid, photons, std::move(binned), params) {}
  Gatherer gatherer;
  GatherResult gathered;
  GatherResult caustic;  ///< the caustic photons of the same point (Gatherer::gatherCaustics)
  std::vector<DirectionSample> samples;
  double gatherSeconds = 0;
  double clusterSeconds = 0;
  /// Layers 1 and 2 of this thread's voxels, in no particular order
  /// (sorted by voxel and layer when merged).
  struct Layer {
    uint32_t voxel;
    int layer;
    Vec3 normal, point, irradiance, reflectance;
    float photonCount, noise, radius;
    ClusterResult vdls;
    std::array<Vec3, layout::LO_SH_MAX_TERMS> sh;
  };
  std::vector<Layer> layers;
};

using Clock = std::chrono::steady_clock;

inline double secondsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// Voxels in canonical order are grouped by 8^3 block, so a run of 64 indices
// mostly stays within one or two blocks: neighbouring gathers touch the same
// photon bins.
constexpr size_t kGrainVoxels = 64;

struct BakeBody {
  const SurfaceGrid& grid;
  const std::vector<Photon>& photons;
  const ClusterParams& cluster;
  const LayerParams* layerParams;
  const std::vector<uint32_t>* subset;
  tbb::enumerable_thread_specific<Worker>& workers;
  Progress& progress;
  VdlGrid& out;

  /// K-means of the gathered photons' directions. Each photon's share of the
  /// irradiance estimate E = sum(power) / (pi r_k^2 coverage) (W/m^2), so the
  /// VDLs sum to the estimate. Layer l of the voxel at c seeds its stream with
  /// canonicalVoxelKey(c) + l 2^36: the voxel's name whatever other voxels
  /// the grid holds (a tile of a distributed bake seeds as the whole grid).
  ClusterResult clusterGathered(Worker& w, uint64_t stream, Vec3* sh) const {
    const GatherResult& g = w.gathered;
    w.samples.clear();
    // The smooth light's photons, then the caustic ones, each share of its
    // own estimate: the VDLs sum to their total.
    for (const GatherResult* part : {&w.gathered, &w.caustic}) {
      const float r = part->radius;
      if (!(r > 0) || part->photons.empty()) continue;
      const float invArea = 1.0f / (kPi * r * r * part->coverage);
      for (uint32_t p : part->photons) {
        const Photon& ph = photons[p];
        w.samples.push_back({ph.direction, ph.power * invArea});
      }
    }
    const int terms = shTermsOf(cluster.representation);
    if (terms > 0) {
      projectSh(w.samples.data(), w.samples.size(), g.normal, terms, sh);
      return ClusterResult{};
    }
    return clusterDirections(w.samples.data(), w.samples.size(), cluster.vdls, cluster, stream);
  }

  /// The caustic photons of the point the smooth gather just read, on the
  /// side it found (w.caustic; empty without caustic photons).
  static void gatherCaustics(Worker& w, size_t v, const Vec3& point) {
    if (w.gatherer.hasCaustics()) {
      w.gatherer.gatherCaustics(v, point, w.gathered.normal, w.caustic);
    } else {
      w.caustic.photons.clear();
      w.caustic.irradiance = Vec3{0, 0, 0};
      w.caustic.noise = 0;
    }
  }

  /// The smooth and the caustic estimates together: their sum, photons,
  /// noise (independent photons: the standard deviations add in squares)
  /// and reflectance (weighted by each estimate's irradiance).
  struct Totals {
    Vec3 irradiance, reflectance;
    float photons, noise;
  };
  static Totals totals(const Worker& w) {
    const GatherResult &g = w.gathered, &c = w.caustic;
    Totals t{g.irradiance + c.irradiance, g.reflectance,
             float(g.photons.size() + c.photons.size()), g.noise};
    for (int k = 0; k < 3; ++k) {
      const float e = t.irradiance[k];
      if (e > 0) {
        t.reflectance[k] = (g.reflectance[k] * g.irradiance[k] + c.reflectance[k] * c.irradiance[k]) / e;
      }
    }
    if (!c.photons.empty()) {
      const double sg = double(g.noise) * double(luminance(g.irradiance)),
                   sc = double(c.noise) * double(luminance(c.irradiance));
      const double y = double(luminance(t.irradiance));
      t.noise = y > 0 ? float(std::sqrt(sg * sg + sc * sc) / y) : 0.0f;
    }
    return t;
  }

  void operator()(const tbb::blocked_range<size_t>& range) const {
    Worker& w = workers.local();
    double gatherSeconds = 0, clusterSeconds = 0;
    const size_t maxVdls = size_t(out.maxVdls);
    SurfaceLayer found[kMaxLayers];
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const size_t v = subset ? size_t((*subset)[i]) : i;
      const uint64_t stream = canonicalVoxelKey(grid.coords[v]);
      Clock::time_point t0 = Clock::now();
      const int layers = layerParams ? w.gatherer.findSurfaceLayers(v, *layerParams, found) : 0;
      // A voxel whose geometry faces several ways gathers along its layers'
      // normals even when one layer is lit: the area-weighted mean of
      // opposing faces (a ball resting on the floor) is a meaningless normal.
      const bool several = !grid.orientationStart.empty() &&
                           grid.orientationStart[v + 1] != grid.orientationStart[v];
      const bool layered = layers >= 2 || (layers == 1 && several);
      if (layered) {
        w.gatherer.gatherLayer(v, found[0].point, found[0].normal, w.gathered);
      } else {
        w.gatherer.gather(v, w.gathered);
      }
      gatherCaustics(w, v, layered ? found[0].point : grid.centroids[v]);
      const GatherResult& g = w.gathered;
      const Totals total = totals(w);
      Clock::time_point t1 = Clock::now();
      const size_t terms = size_t(out.shTerms);
      ClusterResult c = clusterGathered(w, stream, out.sh.data() + v * terms);
      Clock::time_point t2 = Clock::now();
      gatherSeconds += secondsBetween(t0, t1);
      clusterSeconds += secondsBetween(t1, t2);

      out.normals[v] = g.normal;
      out.points[v] = layered ? found[0].lit : grid.centroids[v];
      out.irradiance[v] = total.irradiance;
      out.reflectance[v] = total.reflectance;
      out.photonCount[v] = total.photons;
      out.noise[v] = total.noise;
      out.radius[v] = g.radius;
      out.angularError[v] = c.angularError;
      out.vdlCount[v] = uint8_t(c.count);
      Vdl* dst = out.vdls.data() + v * maxVdls;
      for (int i = 0; i < c.count; ++i) dst[i] = c.vdls[i];

      for (int l = 1; l < layers; ++l) {
        Clock::time_point t3 = Clock::now();
        w.gatherer.gatherLayer(v, found[l].point, found[l].normal, w.gathered);
        gatherCaustics(w, v, found[l].point);
        const Totals layerTotal = totals(w);
        Clock::time_point t4 = Clock::now();
        Worker::Layer layer{uint32_t(v), l, w.gathered.normal, found[l].lit,
                            layerTotal.irradiance, layerTotal.reflectance, layerTotal.photons,
                            layerTotal.noise, w.gathered.radius, ClusterResult{}, {}};
        layer.vdls = clusterGathered(w, stream + (uint64_t(l) << kCanonicalKeyBits), layer.sh.data());
        w.layers.push_back(layer);
        gatherSeconds += secondsBetween(t3, t4);
        clusterSeconds += secondsBetween(t4, Clock::now());
      }
    }
    w.gatherSeconds += gatherSeconds;
    w.clusterSeconds += clusterSeconds;
    progress.advance(range.size());
  }
};

}  // namespace vdl_grid_internal

VdlGrid buildVdlGrid(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                     const GatherParams& gather, const ClusterParams& cluster,
                     ProgressSink* progress, BakeTimings* timings, const LayerParams* layers,
                     const std::vector<uint32_t>* subset) {
  using namespace vdl_grid_internal;
  if (cluster.vdls < 1 || cluster.vdls > kMaxVdls) {
    throw InputError("VDL count " + std::to_string(cluster.vdls) + " is outside [1, " +
                     std::to_string(kMaxVdls) + "]");
  }
  const size_t n = grid.size();
  LO_CHECK_EQ(grid.areas.size(), n);

  VdlGrid out;
  out.frame = grid.frame;
  // In auto mode vdls is the cap, so it is also the slot count per voxel.
  out.maxVdls = cluster.vdls;
  out.coords = grid.coords;
  out.areas = grid.areas;
  out.normals.assign(n, Vec3{});
  out.irradiance.assign(n, Vec3{});
  out.reflectance.assign(n, Vec3{});
  out.photonCount.assign(n, 0.0f);
  out.noise.assign(n, 0.0f);
  out.radius.assign(n, 0.0f);
  out.angularError.assign(n, 0.0f);
  out.vdlCount.assign(n, 0);
  out.vdls.assign(n * size_t(out.maxVdls), Vdl{});  // unused slots stay zero
  out.points.assign(n, Vec3{});
  out.shTerms = shTermsOf(cluster.representation);
  out.sh.assign(n * size_t(out.shTerms), Vec3{});
  if (layers && (layers->maxLayers < 1 || layers->maxLayers > kMaxLayers)) {
    throw InputError("surface layers: at most " + std::to_string(layers->maxLayers) +
                     " per voxel is outside [1, " + std::to_string(kMaxLayers) + "]");
  }

  // One copy of the binned photons, read by every thread's gatherer.
  std::shared_ptr<const BinnedPhotons> binned = binPhotonsForGather(grid, photons);
  tbb::enumerable_thread_specific<Worker> workers(
      [&] { return Worker(grid, photons, binned, gather); });
  {
    const size_t count = subset ? subset->size() : n;
    if (subset) {
      for (size_t i = 0; i < count; ++i) {
        LO_CHECK_LT(size_t((*subset)[i]), n);
        if (i > 0) LO_CHECK_LT((*subset)[i - 1], (*subset)[i]);
      }
    }
    Progress bar(progress, "gather + cluster", count);
    // Every voxel writes only its own slots and seeds its K-means with its
    // coordinate, so the result does not depend on the partition, the thread
    // count or which other voxels the grid holds.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kGrainVoxels),
                      BakeBody{grid, photons, cluster, layers, subset, workers, bar, out});
  }

  // Layers 1 and 2, gathered by whichever thread, in voxel and layer order.
  std::vector<Worker::Layer> extra;
  for (Worker& w : workers) {
    extra.insert(extra.end(), w.layers.begin(), w.layers.end());
    w.layers.clear();
  }
  std::sort(extra.begin(), extra.end(), [](const Worker::Layer& a, const Worker::Layer& b) {
    return a.voxel < b.voxel || (a.voxel == b.voxel && a.layer < b.layer);
  });
  VdlLayers& L = out.layers;
  for (const Worker::Layer& e : extra) {
    L.voxel.push_back(e.voxel);
    L.normals.push_back(e.normal);
    L.points.push_back(e.point);
    L.irradiance.push_back(e.irradiance);
    L.reflectance.push_back(e.reflectance);
    L.photonCount.push_back(e.photonCount);
    L.noise.push_back(e.noise);
    L.radius.push_back(e.radius);
    L.angularError.push_back(e.vdls.angularError);
    L.vdlCount.push_back(uint8_t(e.vdls.count));
    for (int i = 0; i < out.maxVdls; ++i) L.vdls.push_back(i < e.vdls.count ? e.vdls.vdls[size_t(i)] : Vdl{});
    L.sh.insert(L.sh.end(), e.sh.begin(), e.sh.begin() + out.shTerms);
  }

  if (timings) {
    *timings = BakeTimings{};
    for (const Worker& w : workers) {
      timings->gatherSeconds += w.gatherSeconds;
      timings->clusterSeconds += w.clusterSeconds;
    }
  }
  return out;
}

namespace vdl_grid_internal {

/// Correlation of two gather estimates whose discs of radius r lie d apart
/// on one plane: the share of photons they have in common, the lens area of
/// the two discs over one disc's area (a Poisson process shares exactly
/// those photons).
double discOverlap(double d, double r) {
  if (!(r > 0) || d >= 2 * r) return 0.0;
  const double a = 2 * r * r * std::acos(d / (2 * r)) - 0.5 * d * std::sqrt(4 * r * r - d * d);
  return std::clamp(a / (kPi * r * r), 0.0, 1.0);
}

}  // namespace vdl_grid_internal

size_t smoothVdlGrid(const SurfaceGrid& grid, VdlGrid& out, const SmoothParams& params) {
  const size_t n = out.size();
  LO_CHECK_EQ(grid.size(), n);
  std::vector<char> layered(n, 0);
  for (uint32_t v : out.layers.voxel) layered[v] = 1;
  const float h = out.frame.voxelSize;
  const float inv2s2 = 1.0f / (2.0f * params.sigmaVoxels * params.sigmaVoxels * h * h);
  const bool hasNoise = out.noise.size() == n;
  // A voxel's photon noise as a standard deviation of luminance: the
  // recorded relative noise, else 1/sqrt(photons gathered).
  auto sigmaOf = [&](size_t v, float y) {
    if (hasNoise && out.noise[v] > 0) return out.noise[v] * y;
    return out.photonCount[v] > 0 ? y / std::sqrt(out.photonCount[v]) : 0.0f;
  };
  std::vector<Vec3> smoothed(out.irradiance);
  std::vector<float> smoothedNoise(hasNoise ? out.noise : std::vector<float>());
  std::vector<char> changed(n, 0);
  struct Member {
    size_t voxel;
    Vec3 point;
    double weight, sigma;
  };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<Member> members;
    for (size_t v = r.begin(); v != r.end(); ++v) {
      if (layered[v] || !out.lit(v)) continue;
      const Vec3 nv = out.normals[v];
      if (!(lengthSquared(nv) > 0.5f)) continue;
      const Vec3 pv = out.points.empty() ? grid.centroids[v] : out.points[v];
      const float yv = luminance(out.irradiance[v]);
      if (!(yv > 0) || !(out.photonCount[v] > 0)) continue;
      const float noise = params.rangeSigmas * sigmaOf(v, yv);
      if (!(noise > 0)) continue;
      const float invNoise2 = 1.0f / (2.0f * noise * noise);
      double sum[3] = {0, 0, 0}, weight = 0;
      members.clear();
      const Coord c = out.coords[v];
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int64_t w = grid.find({c.x + dx, c.y + dy, c.z + dz});
            if (w < 0 || layered[size_t(w)] || !out.lit(size_t(w))) continue;
            const size_t k = size_t(w);
            if (!(dot(out.normals[k], nv) > params.minCosine)) continue;
            const Vec3 pw = out.points.empty() ? grid.centroids[k] : out.points[k];
            if (std::fabs(dot(pw - pv, nv)) > params.planeVoxels * h) continue;
            const float yk = luminance(out.irradiance[k]);
            const float dy2 = yk - yv;
            const float wk = std::exp(-lengthSquared(pw - pv) * inv2s2 - dy2 * dy2 * invNoise2);
            for (int a = 0; a < 3; ++a) sum[a] += double(wk) * double(out.irradiance[k][a]);
            weight += double(wk);
            members.push_back({k, pw, double(wk), double(sigmaOf(k, yk))});
          }
        }
      }
      if (!(weight > 0)) continue;
      smoothed[v] = Vec3{float(sum[0] / weight), float(sum[1] / weight), float(sum[2] / weight)};
      changed[v] = 1;
      if (!hasNoise) continue;
      // The weighted mean's variance: neighbouring gathers share photons,
      // so each pair of estimates correlates by their discs' overlap.
      double variance = 0;
      for (const Member& a : members) {
        for (const Member& b : members) {
          const double rho =
              a.voxel == b.voxel
                  ? 1.0
                  : vdl_grid_internal::discOverlap(
                        double(length(a.point - b.point)),
                        0.5 * (double(out.radius[a.voxel]) + double(out.radius[b.voxel])));
          variance += a.weight * b.weight * a.sigma * b.sigma * rho;
        }
      }
      const double y = double(luminance(smoothed[v]));
      smoothedNoise[v] = y > 0 ? float(std::sqrt(variance) / weight / y) : 0.0f;
    }
  });
  if (hasNoise) out.noise = std::move(smoothedNoise);
  size_t count = 0;
  for (size_t v = 0; v < n; ++v) {
    if (!changed[v]) continue;
    ++count;
    if (out.shTerms > 0) {
      // SH is linear: scale every term's channel; E(n) follows exactly.
      Vec3* sh = out.sh.data() + v * size_t(out.shTerms);
      for (int a = 0; a < 3; ++a) {
        const float e = out.irradiance[v][a];
        if (!(e > 0)) continue;
        const float scale = smoothed[v][a] / e;
        for (int i = 0; i < out.shTerms; ++i) sh[i][a] *= scale;
        out.irradiance[v][a] = smoothed[v][a];
      }
      continue;
    }
    Vdl* vdls = out.vdls.data() + v * size_t(out.maxVdls);
    for (int a = 0; a < 3; ++a) {
      const float e = out.irradiance[v][a];
      if (!(e > 0)) continue;
      const float scale = smoothed[v][a] / e;
      for (int i = 0; i < out.vdlCount[v]; ++i) vdls[i].irradiance[a] *= scale;
    }
    // The VDLs' sum, rounded as stored.
    Vec3 total{0, 0, 0};
    for (int i = 0; i < out.vdlCount[v]; ++i) total += vdls[i].irradiance;
    out.irradiance[v] = total;
  }
  return count;
}

}  // namespace lo
