#include "sweep/sweep.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bake/bake.h"
#include "core/error.h"
#include "core/file.h"
#include "core/resources.h"
#include "core/threads.h"
#include "image/compare.h"
#include "image/image.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "reference/first_hit.h"
#include "reference/path_tracer.h"
#include "render/context.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "vdb/vdb_io.h"

namespace fs = std::filesystem;

namespace lo {
namespace sweep_internal {

std::string photonsText(size_t n) {
  if (n >= 1000000 && n % 100000 == 0) {
    std::ostringstream os;
    os << double(n) / 1e6 << "M";
    return os.str();
  }
  if (n >= 1000 && n % 1000 == 0) return std::to_string(n / 1000) + "k";
  return std::to_string(n);
}

/// A fraction as a percentage rounded to 2 decimals.
double percent2(double fraction) { return std::round(10000.0 * fraction) / 100.0; }

/// Runs `gnuplot SCRIPT` with `dir` as its working folder (no shell: the
/// folder and script are arguments), output discarded. False when gnuplot is
/// missing or fails.
bool runGnuplot(const std::string& dir, const std::string& script) {
  std::string quoted;  // gnuplot single-quoted string: '' stands for '
  for (char c : dir) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  const std::string cd = "cd '" + quoted + "'";
  const std::string absolute = fs::absolute(script).string();
  std::vector<char*> argv = {const_cast<char*>("gnuplot"), const_cast<char*>("-e"),
                             const_cast<char*>(cd.c_str()), const_cast<char*>(absolute.c_str()),
                             nullptr};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return false;
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

std::string readText(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw IoError(path + ": cannot open");
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

/// Luminance standard error relative to the reference's RMS luminance: the
/// noise floor of any relative RMSE measured against it. Channels of one
/// path are correlated, so the luminance error is bounded by the weighted sum.
double relativeNoise(const ReferenceImage& ref) {
  double se2 = 0, y2 = 0;
  for (size_t i = 0; i < ref.image.pixelCount(); ++i) {
    const Vec3 v = ref.image.at(i), s = ref.stdError.at(i);
    const double y = 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z;
    const double se = 0.2126 * s.x + 0.7152 * s.y + 0.0722 * s.z;
    if (v.x == 0 && v.y == 0 && v.z == 0) continue;  // background, left out as in compare
    se2 += se * se;
    y2 += y * y;
  }
  return y2 > 0 ? std::sqrt(se2 / y2) : 0.0;
}

struct References {
  RgbImage irradiance, indirect;
  double irradianceNoise = 0, indirectNoise = 0;
  double seconds = 0;
};

/// Path-traced references, cached in cacheDir with the settings they were
/// rendered with; re-rendered when those differ.
References loadOrRenderReferences(const SweepParams& params, const Scene& scene,
                                  const PinholeCamera& camera, const std::string& cacheDir,
                                  std::FILE* log) {
  nlohmann::json key = {{"scene", fs::path(params.scene).filename().string()},
                        {"width", params.width},
                        {"height", params.height},
                        {"spp", params.referenceSpp},
                        {"seed", params.seed},
                        {"indirect", params.frames > 0}};
  const std::string keyFile = cacheDir + "/reference.json";
  const std::string irrFile = cacheDir + "/reference-irradiance.exr";
  const std::string indFile = cacheDir + "/reference-indirect.exr";
  References refs;
  if (fs::exists(keyFile) && fs::exists(irrFile) && (params.frames == 0 || fs::exists(indFile))) {
    nlohmann::json cached = nlohmann::json::parse(readText(keyFile));
    if (cached["key"] == key) {
      refs.irradiance = readImage(irrFile);
      if (params.frames > 0) refs.indirect = readImage(indFile);
      refs.irradianceNoise = cached.value("irradiance_noise", 0.0);
      refs.indirectNoise = cached.value("indirect_noise", 0.0);
      refs.seconds = cached.value("seconds", 0.0);
      if (log) std::fprintf(log, "reference: cached in %s\n", cacheDir.c_str());
      return refs;
    }
  }
  ReferenceParams rp;
  rp.width = params.width;
  rp.height = params.height;
  rp.samplesPerPixel = params.referenceSpp;
  rp.seed = params.seed;
  rp.part = ReferencePart::Irradiance;
  ReferenceImage irr = renderReference(scene, camera, rp, params.progress);
  refs.irradiance = irr.image;
  refs.irradianceNoise = relativeNoise(irr);
  refs.seconds = irr.seconds;
  writeExr(irrFile, irr.image);
  if (params.frames > 0) {
    rp.part = ReferencePart::Indirect;
    ReferenceImage ind = renderReference(scene, camera, rp, params.progress);
    refs.indirect = ind.image;
    refs.indirectNoise = relativeNoise(ind);
    refs.seconds += ind.seconds;
    writeExr(indFile, ind.image);
  }
  nlohmann::json j = {{"key", key},
                      {"irradiance_noise", refs.irradianceNoise},
                      {"indirect_noise", refs.indirectNoise},
                      {"seconds", refs.seconds}};
  writeTextAtomically(keyFile, j.dump(2) + "\n");
  if (log) {
    std::fprintf(log,
                 "reference: %d x %d, %d spp, %.1f s; noise (rel. RMS std. error) "
                 "irradiance %.2f%%, indirect %.2f%%\n",
                 params.width, params.height, params.referenceSpp, refs.seconds,
                 100 * refs.irradianceNoise, 100 * refs.indirectNoise);
  }
  return refs;
}

nlohmann::json pointJson(const SweepPoint& p) {
  return {{"group", p.group},
          {"depth", p.depth},
          {"photons", p.photons},
          {"knn", p.knn},
          {"radius_voxels", p.radiusVoxels},
          {"vdls", p.vdls},
          {"interpolation", p.interpolation},
          {"half_float", p.halfFloat},
          {"cosine_correction", p.cosineCorrection},
          {"layers", p.layers},
          {"occlusion", p.occlusion},
          {"edge_correction", p.edgeCorrection},
          {"smoothing", p.smoothing},
          {"representation", p.representation},
          {"tolerance", p.tolerance}};
}

nlohmann::json resultJson(const SweepResult& r) {
  return {{"point", pointJson(r.point)},
          {"trace_s", r.traceSeconds},
          {"voxelize_s", r.voxelizeSeconds},
          {"splat_s", r.splatSeconds},
          {"cluster_s", r.clusterSeconds},
          {"bake_s", r.bakeSeconds},
          {"peak_rss_bytes", r.peakRssBytes},
          {"vdb_bytes", r.vdbBytes},
          {"gpu_bytes", r.gpuBytes},
          {"active_voxels", r.activeVoxels},
          {"dense_voxels", r.denseVoxels},
          {"vdl_texels", r.vdlTexels},
          {"gpu_leaves", r.gpuLeaves},
          {"frame_ms", r.frameMs},
          {"irradiance_rel_rmse", r.irradianceRelRmse},
          {"irradiance_rel_mae", r.irradianceRelMae},
          {"indirect_rel_rmse", r.indirectRelRmse}};
}

SweepResult resultFromJson(const nlohmann::json& j, const SweepPoint& point) {
  SweepResult r;
  r.point = point;
  r.traceSeconds = j.at("trace_s");
  r.voxelizeSeconds = j.at("voxelize_s");
  r.splatSeconds = j.at("splat_s");
  r.clusterSeconds = j.at("cluster_s");
  r.bakeSeconds = j.at("bake_s");
  r.peakRssBytes = j.at("peak_rss_bytes");
  r.vdbBytes = j.at("vdb_bytes");
  r.gpuBytes = j.at("gpu_bytes");
  r.activeVoxels = j.at("active_voxels");
  r.denseVoxels = j.at("dense_voxels");
  r.vdlTexels = j.at("vdl_texels");
  r.gpuLeaves = j.value("gpu_leaves", -1.0);
  r.frameMs = j.at("frame_ms");
  r.irradianceRelRmse = j.at("irradiance_rel_rmse");
  r.irradianceRelMae = j.at("irradiance_rel_mae");
  r.indirectRelRmse = j.at("indirect_rel_rmse");
  return r;
}

/// Puts images side by side with a gap of `gap` black pixels.
RgbImage sideBySide(const std::vector<const RgbImage*>& images, int gap) {
  int width = 0, height = 0;
  for (const RgbImage* im : images) {
    width += im->width + (width > 0 ? gap : 0);
    height = std::max(height, im->height);
  }
  RgbImage out(width, height);
  int x0 = 0;
  for (const RgbImage* im : images) {
    for (int y = 0; y < im->height; ++y)
      for (int x = 0; x < im->width; ++x)
        out.set(size_t(y) * size_t(width) + size_t(x0 + x), im->at(size_t(y) * im->width + x));
    x0 += im->width + gap;
  }
  return out;
}

/// PNG exposure that puts the reference's mean luminance near mid grey.
float exposureFor(const RgbImage& reference) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < reference.pixelCount(); ++i) {
    const Vec3 v = reference.at(i);
    const double y = 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z;
    if (y > 0) {
      sum += y;
      ++n;
    }
  }
  return n && sum > 0 ? float(std::log2(0.3 * double(n) / sum)) : 0.0f;
}

}  // namespace sweep_internal

std::string SweepPoint::label() const {
  using namespace sweep_internal;
  std::string s = "d" + std::to_string(depth) + " " + photonsText(photons) + " k" +
                  std::to_string(knn) + " r" + formatNumber(radiusVoxels) + " v" + vdls;
  if (!interpolation) s += " no-interp";
  if (halfFloat) s += " half";
  if (!cosineCorrection) s += " paper-cosine";
  if (!layers) s += " no-layers";
  if (!occlusion) s += " no-occlusion";
  if (!edgeCorrection) s += " no-edge";
  if (smoothing != BakeParams{}.smoothing) s += smoothing ? " smooth" : " no-smooth";
  if (representation != representationName(LightRepresentation::Vdl)) s += " " + representation;
  if (tolerance > 0) s += " tol" + formatNumber(tolerance);
  return s;
}

std::string SweepPoint::bakeKey() const {
  using namespace sweep_internal;
  return "d" + std::to_string(depth) + "-p" + std::to_string(photons) + "-k" + std::to_string(knn) +
         "-r" + formatNumber(radiusVoxels) + "-v" + vdls + (layers ? "" : "-l0") +
         (occlusion ? "" : "-o0") + (edgeCorrection ? "" : "-e0") +
         (smoothing == BakeParams{}.smoothing ? "" : (smoothing ? "-s1" : "-s0")) +
         (representation == representationName(LightRepresentation::Vdl) ? "" : "-" + representation);
}

std::string SweepPoint::key() const {
  return bakeKey() + (interpolation ? "-i1" : "-i0") + (halfFloat ? "-h1" : "-h0") +
         (cosineCorrection ? "" : "-c0") +
         (tolerance > 0 ? "-t" + formatNumber(tolerance) : "");
}

SweepPoint paperPoint() { return SweepPoint{}; }

std::vector<SweepPoint> sweepPoints(SweepScale scale) {
  std::vector<SweepPoint> points;
  auto add = [&points](SweepPoint p) {
    for (const SweepPoint& q : points)
      if (q.sameSettings(p)) return;
    points.push_back(p);
  };
  auto vary = [&](const char* group, auto setter) {
    SweepPoint p = paperPoint();
    p.group = group;
    setter(p);
    add(p);
  };
  if (scale == SweepScale::Tiny) {
    SweepPoint p;
    p.group = "depth";
    p.photons = 20000;
    p.knn = 20;
    p.depth = 3;
    add(p);
    p.depth = 4;
    add(p);
    p.group = "interpolation";
    p.interpolation = false;
    add(p);
    return points;
  }
  add(paperPoint());
  const bool full = scale == SweepScale::Full;
  const std::vector<int> depths = full ? std::vector<int>{3, 4, 5, 7, 8} : std::vector<int>{4, 5};
  const std::vector<size_t> photons =
      full ? std::vector<size_t>{50000, 150000, 300000, 1200000, 2500000, 5000000}
           : std::vector<size_t>{150000, 300000};
  const std::vector<int> knns =
      full ? std::vector<int>{10, 30, 100, 150, 600, 1000} : std::vector<int>{30, 100};
  const std::vector<float> radii = full ? std::vector<float>{1, 2, 3, 4, 6} : std::vector<float>{};
  const std::vector<std::string> vdls = full ? std::vector<std::string>{"1", "2", "8", "auto"}
                                             : std::vector<std::string>{"1", "auto"};
  for (int d : depths) vary("depth", [d](SweepPoint& p) { p.depth = d; });
  for (size_t n : photons) vary("photons", [n](SweepPoint& p) { p.photons = n; });
  for (int k : knns) vary("knn", [k](SweepPoint& p) { p.knn = k; });
  for (float r : radii) vary("radius", [r](SweepPoint& p) { p.radiusVoxels = r; });
  for (const std::string& v : vdls) vary("vdls", [v](SweepPoint& p) { p.vdls = v; });
  vary("interpolation", [](SweepPoint& p) { p.interpolation = false; });
  vary("texels", [](SweepPoint& p) { p.halfFloat = true; });
  vary("cosine", [](SweepPoint& p) { p.cosineCorrection = false; });
  // The accuracy options (docs/accuracy.md), one off at a time, and all off:
  // the gather as it was before them.
  vary("accuracy", [](SweepPoint& p) { p.layers = false; });
  vary("accuracy", [](SweepPoint& p) { p.occlusion = false; });
  vary("accuracy", [](SweepPoint& p) { p.edgeCorrection = false; });
  vary("accuracy", [](SweepPoint& p) { p.smoothing = !p.smoothing; });
  vary("accuracy", [](SweepPoint& p) {
    p.layers = false;
    p.occlusion = false;
    p.edgeCorrection = false;
    p.smoothing = false;
  });
  // Spherical harmonics beside the VDLs (the paper's future work).
  vary("representation", [](SweepPoint& p) { p.representation = representationName(LightRepresentation::Sh1); });
  vary("representation", [](SweepPoint& p) { p.representation = representationName(LightRepresentation::Sh2); });
  // Adaptive leaves (docs/octree.md): the same bake, coarser leaves where the light agrees.
  for (float t : {0.05f, 0.1f, 0.2f, 0.4f}) vary("tolerance", [t](SweepPoint& p) { p.tolerance = t; });
  vary("tolerance", [](SweepPoint& p) {
    p.representation = representationName(LightRepresentation::Sh1);
    p.tolerance = 0.1f;
  });
  // Combined points: cheaper photon maps with a matching k (the photon
  // density per voxel falls with the count), coarser and finer grids.
  vary("combined", [](SweepPoint& p) {
    p.photons = 300000;
    p.knn = 150;
  });
  vary("combined", [](SweepPoint& p) {
    p.depth = 5;
    p.photons = 300000;
    p.knn = 300;
  });
  if (full) {
    vary("combined", [](SweepPoint& p) {
      p.photons = 150000;
      p.knn = 100;
      p.vdls = "2";
      p.halfFloat = true;
    });
    vary("combined", [](SweepPoint& p) {
      p.depth = 5;
      p.photons = 1200000;
      p.knn = 600;
    });
    vary("combined", [](SweepPoint& p) {
      p.depth = 7;
      p.photons = 2500000;
      p.knn = 300;
    });
  }
  return points;
}

std::vector<bool> paretoFront(const std::vector<double>& cost, const std::vector<double>& error) {
  LO_CHECK_EQ(cost.size(), error.size());
  std::vector<bool> front(cost.size(), true);
  for (size_t i = 0; i < cost.size(); ++i) {
    for (size_t j = 0; j < cost.size() && front[i]; ++j) {
      const bool noWorse = cost[j] <= cost[i] && error[j] <= error[i];
      const bool better = cost[j] < cost[i] || error[j] < error[i];
      if (j != i && noWorse && better) front[i] = false;
    }
  }
  return front;
}

void markParetoFronts(std::vector<SweepResult>& results) {
  std::vector<double> time, memory, error;
  for (const SweepResult& r : results) {
    time.push_back(r.bakeSeconds);
    memory.push_back(r.gpuBytes);
    error.push_back(r.irradianceRelRmse);
  }
  std::vector<bool> t = paretoFront(time, error), m = paretoFront(memory, error);
  for (size_t i = 0; i < results.size(); ++i) {
    results[i].paretoTime = t[i];
    results[i].paretoMemory = m[i];
  }
}

SweepParams sweepDefaults(SweepScale scale) {
  SweepParams p;
  p.scale = scale;
  switch (scale) {
    case SweepScale::Full:
      p.width = 160, p.height = 120, p.referenceSpp = 8192, p.frames = 5;
      break;
    case SweepScale::Quick:
      p.width = 96, p.height = 72, p.referenceSpp = 2048, p.frames = 2;
      break;
    case SweepScale::Tiny:
      p.width = 24, p.height = 18, p.referenceSpp = 8, p.frames = 1;
      break;
  }
  return p;
}

namespace sweep_internal {

/// The light octree's figures of one bake, as cached beside its .vdb.
struct BakeFigures {
  double traceSeconds = 0, voxelizeSeconds = 0, splatSeconds = 0, clusterSeconds = 0;
  double bakeSeconds = 0, peakRssBytes = 0, vdbBytes = 0, activeVoxels = 0, denseVoxels = 0;
};

nlohmann::json toJson(const BakeFigures& f) {
  return {{"trace_seconds", f.traceSeconds},   {"voxelize_seconds", f.voxelizeSeconds},
          {"splat_seconds", f.splatSeconds},   {"cluster_seconds", f.clusterSeconds},
          {"bake_seconds", f.bakeSeconds},     {"peak_rss_bytes", f.peakRssBytes},
          {"vdb_bytes", f.vdbBytes},           {"active_voxels", f.activeVoxels},
          {"dense_voxels", f.denseVoxels}};
}

BakeFigures bakeFiguresFromJson(const nlohmann::json& j) {
  BakeFigures f;
  f.traceSeconds = j.at("trace_seconds");
  f.voxelizeSeconds = j.at("voxelize_seconds");
  f.splatSeconds = j.at("splat_seconds");
  f.clusterSeconds = j.at("cluster_seconds");
  f.bakeSeconds = j.at("bake_seconds");
  f.peakRssBytes = j.at("peak_rss_bytes");
  f.vdbBytes = j.at("vdb_bytes");
  f.activeVoxels = j.at("active_voxels");
  f.denseVoxels = j.at("dense_voxels");
  return f;
}

/// The bake parameters of a point; every default comes from the bake module.
BakeParams bakeParamsOf(const SweepPoint& point, const Scene& scene, uint64_t seed) {
  BakeParams b;
  b.depth = point.depth;
  b.photons = point.photons;
  b.knn = point.knn;
  b.vdls = parseVdlCount(point.vdls, "sweep point --vdls");
  b.seed = seed;
  b.layers = point.layers;
  b.occlusion = point.occlusion;
  b.edgeCorrection = point.edgeCorrection;
  b.smoothing = point.smoothing;
  if (!parseRepresentation(point.representation, &b.representation)) {
    throw InputError("sweep point representation '" + point.representation +
                     "': expected " + representationChoices());
  }
  // 0 lets the gather apply its own default (kDefaultRadiusVoxels voxels).
  if (point.radiusVoxels != kDefaultRadiusVoxels) {
    b.radius = point.radiusVoxels * makeGridFrame(scene.bounds(), point.depth).voxelSize;
  }
  return b;
}

/// Bakes in this process and writes the .vdb; memory is the peak resident
/// set during the bake above the resident set before it.
BakeFigures bakeAndWrite(const Scene& scene, const std::string& scenePath, const BakeParams& b,
                         const std::string& vdb) {
  const size_t before = currentRssBytes();
  const bool reset = resetPeakRss();
  Stopwatch clock;
  BakeResult baked = bake(scene, b);
  baked.metadata.sourceScene = fs::path(scenePath).filename().string();
  writeVdlGrid(vdb, baked.grid, baked.metadata);
  BakeFigures f;
  f.bakeSeconds = clock.seconds();
  const size_t peak = reset ? peakRssSinceResetBytes() : peakRssBytes();
  f.peakRssBytes = double(peak > before ? peak - before : 0);
  const BakeStats& st = baked.stats;
  f.traceSeconds = st.traceSeconds;
  f.voxelizeSeconds = st.level.voxelizeSeconds;
  f.splatSeconds = st.level.splatSeconds;
  f.clusterSeconds = st.level.gatherClusterSeconds;
  f.vdbBytes = double(fs::file_size(vdb));
  f.activeVoxels = double(st.level.activeVoxels);
  f.denseVoxels = double(st.denseVoxels);
  return f;
}

/// The GL renderer of the indirect images: one context and one set of scene
/// resources for the whole sweep (the renderer is made on first use).
struct IndirectRenderer {
  std::unique_ptr<GlContext> context;
  std::unique_ptr<Renderer> renderer;

  /// The indirect image of `octree` and its mean frame time over `frames`.
  RgbImage render(const Scene& scene, const GpuOctree& octree, const SweepPoint& point,
                  const PinholeCamera& camera, int width, int height, int frames, double& frameMs) {
    if (!renderer) {
      renderer = std::make_unique<Renderer>(scene, octree, RendererParams{});
    } else {
      renderer->setOctree(octree);
    }
    RenderParams rp;
    rp.width = width;
    rp.height = height;
    rp.mode = RenderMode::Indirect;
    rp.interpolation = point.interpolation;
    const RgbImage image = renderer->render(camera, rp);
    frameMs = 1000.0 * renderer->timeFrames(camera, rp, frames) / frames;
    return image;
  }
};

}  // namespace sweep_internal

std::vector<SweepResult> runSweep(const SweepParams& params, std::FILE* log) {
  using namespace sweep_internal;
  if (!fs::is_directory(params.outDir))
    throw InputError("--out: folder '" + params.outDir + "' does not exist");
  const std::string cacheDir = params.outDir + "/cache";
  fs::create_directories(cacheDir);
  // Bakes, images and logs stay out of version control; tables and plots are
  // the results.
  if (!fs::exists(params.outDir + "/.gitignore"))
    writeTextAtomically(params.outDir + "/.gitignore", "cache/\n");

  ThreadLimit threadLimit(params.threads);
  const Scene scene = loadScene(params.scene);
  const PinholeCamera camera = scene.cameras.empty()
                                     ? PinholeCamera::framing(scene.bounds(), kPi / 4)
                                     : PinholeCamera::fromScene(scene.cameras.front());
  const References refs = loadOrRenderReferences(params, scene, camera, cacheDir, log);
  CompareParams compareParams;
  compareParams.ignoreBackground = true;

  const std::vector<SweepPoint> points =
      params.points.empty() ? sweepPoints(params.scale) : params.points;
  const nlohmann::json context = {{"scene", fs::path(params.scene).filename().string()},
                                  {"width", params.width},
                                  {"height", params.height},
                                  {"spp", params.referenceSpp},
                                  {"frames", params.frames},
                                  {"threads", params.threads},
                                  {"seed", params.seed},
                                  {"version", LO_VERSION}};
  IndirectRenderer indirectRenderer;
  // The GL context first, when frames are timed: each point's octree is then
  // built once, within its texture limits, for the CPU lookup and the GPU.
  if (params.frames > 0) indirectRenderer.context = createGlContext(GlContextParams{});
  std::vector<SweepResult> results;
  for (size_t pi = 0; pi < points.size(); ++pi) {
    const SweepPoint& point = points[pi];
    const std::string base = cacheDir + "/" + point.key();
    const std::string resultFile = base + ".json";
    if (fs::exists(resultFile)) {
      nlohmann::json cached = nlohmann::json::parse(readText(resultFile));
      if (cached["context"] == context) {
        SweepResult r = resultFromJson(cached["result"], point);
        r.point.group = point.group;
        results.push_back(r);
        if (log)
          std::fprintf(log, "[%zu/%zu] %s: cached\n", pi + 1, points.size(), point.label().c_str());
        continue;
      }
    }
    // Bake (shared by points that differ only in the lookup).
    const std::string bakeBase = cacheDir + "/" + point.bakeKey();
    const std::string vdb = bakeBase + ".vdb", stats = bakeBase + "-bake.json";
    BakeFigures figures;
    if (fs::exists(stats) && fs::exists(vdb) &&
        nlohmann::json::parse(readText(stats)).value("context", nlohmann::json()) == context) {
      figures = bakeFiguresFromJson(nlohmann::json::parse(readText(stats)).at("bake"));
    } else {
      figures = bakeAndWrite(scene, params.scene, bakeParamsOf(point, scene, params.seed), vdb);
      writeTextAtomically(stats,
                          nlohmann::json({{"context", context}, {"bake", toJson(figures)}}).dump(2) +
                              "\n");
    }
    SweepResult r;
    r.point = point;
    r.traceSeconds = figures.traceSeconds;
    r.voxelizeSeconds = figures.voxelizeSeconds;
    r.splatSeconds = figures.splatSeconds;
    r.clusterSeconds = figures.clusterSeconds;
    r.bakeSeconds = figures.bakeSeconds;
    r.peakRssBytes = figures.peakRssBytes;
    r.vdbBytes = figures.vdbBytes;
    r.activeVoxels = figures.activeVoxels;
    r.denseVoxels = figures.denseVoxels;
    // The octree's irradiance at the reference's first hits.
    const LoadedVdl baked = readVdlGrid(vdb);
    GpuOctreeParams octreeParams;
    octreeParams.halfFloat = point.halfFloat;
    octreeParams.cosineCorrection = point.cosineCorrection;
    octreeParams.tolerance = point.tolerance;
    if (const GlContext* gl = indirectRenderer.context.get()) {
      octreeParams.max3DTextureSize = gl->info().max3DTextureSize;
      octreeParams.max2DTextureSize = gl->info().max2DTextureSize;
    }
    const GpuOctree octree = buildGpuOctree(baked.grid, octreeParams);
    r.gpuBytes = double(octree.poolBytes() + octree.vdlBytes());
    r.vdlTexels = double(octree.vdlCount);
    r.gpuLeaves = double(octree.leafCount);
    OctreeShadeParams shade;
    shade.interpolation = point.interpolation;
    shade.normalOffset = RenderParams().normalOffset;
    FirstHitParams hitParams;
    hitParams.width = params.width;
    hitParams.height = params.height;
    // Many rays per pixel: a pixel across an edge mixes its surfaces as
    // the reference's samples do (4 rays made up to a quarter of the jump).
    hitParams.samplesPerPixel = 64;
    hitParams.seed = params.seed;
    const RgbImage irradiance = renderFirstHits(scene, camera, hitParams, [&](const FirstHit& h) {
      return octreeIrradiance(octree, h.position, h.normal, shade);
    });
    writeExr(base + "-irradiance.exr", irradiance);
    const CompareResult irrError = compareImages(irradiance, refs.irradiance, compareParams);
    r.irradianceRelRmse = irrError.luminance.relRmse;
    r.irradianceRelMae = irrError.luminance.relMae;
    // The indirect image through the GL renderer, and its frame time.
    if (params.frames > 0) {
      const RgbImage indirect =
          indirectRenderer.render(scene, octree, point, camera, params.width, params.height,
                                  params.frames, r.frameMs);
      writeExr(base + "-indirect.exr", indirect);
      r.indirectRelRmse = compareImages(indirect, refs.indirect, compareParams).luminance.relRmse;
    }
    writeTextAtomically(
        resultFile,
        nlohmann::json({{"context", context}, {"result", resultJson(r)}}).dump(2) + "\n");
    if (log) {
      std::fprintf(log, "[%zu/%zu] %s: bake %.2f s, GPU %s, irradiance rel. RMSE %.2f%%\n", pi + 1,
                   points.size(), point.label().c_str(), r.bakeSeconds,
                   formatBytes(size_t(r.gpuBytes)).c_str(), 100 * r.irradianceRelRmse);
      std::fflush(log);
    }
    results.push_back(r);
  }
  for (SweepResult& r : results) {
    r.referenceIrradianceNoise = refs.irradianceNoise;
    r.referenceIndirectNoise = refs.indirectNoise;
  }
  markParetoFronts(results);

  // Pictures of the paper's point and of the most accurate point on the time
  // front: reference | light octree | difference, as PNGs for the docs.
  const float ev = exposureFor(refs.irradiance);
  auto picture = [&](const SweepResult& r, const std::string& name) {
    const RgbImage octreeImage = readImage(cacheDir + "/" + r.point.key() + "-irradiance.exr");
    const RgbImage diff = differenceImage(octreeImage, refs.irradiance, compareParams);
    // The difference image is already display-referred: undo the exposure.
    RgbImage diffScaled = diff;
    for (float& v : diffScaled.rgb) v *= std::exp2(-ev);
    writePng(params.outDir + "/" + name,
             sideBySide({&refs.irradiance, &octreeImage, &diffScaled}, 4), ev);
  };
  for (const SweepResult& r : results) {
    if (r.point.sameSettings(paperPoint())) picture(r, "irradiance-paper.png");
  }
  const SweepResult* best = nullptr;
  for (const SweepResult& r : results)
    if (r.paretoTime && (!best || r.irradianceRelRmse < best->irradianceRelRmse)) best = &r;
  if (best) picture(*best, "irradiance-best.png");
  return results;
}

std::string sweepCsv(const std::vector<SweepResult>& results) {
  std::ostringstream os;
  os << "label,group,depth,photons,knn,radius_voxels,vdls,interpolation,half_float,"
        "cosine_correction,trace_s,voxelize_s,splat_s,gather_cluster_s,bake_s,peak_rss_mib,vdb_kib,"
        "gpu_kib,"
        "active_voxels,dense_voxels,vdl_texels,frame_ms,irradiance_rel_rmse,"
        "irradiance_rel_mae,indirect_rel_rmse,pareto_time,pareto_memory,paper\n";
  for (const SweepResult& r : results) {
    const SweepPoint& p = r.point;
    char line[1024];
    std::snprintf(
        line, sizeof line,
        "\"%s\",%s,%d,%zu,%d,%g,%s,%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.1f,%.1f,%.1f,%.0f,%.0f,"
        "%.0f,%.2f,%.5f,%.5f,%.5f,%d,%d,%d\n",
        p.label().c_str(), p.group.c_str(), p.depth, p.photons, p.knn, double(p.radiusVoxels),
        p.vdls.c_str(), int(p.interpolation), int(p.halfFloat), int(p.cosineCorrection),
        r.traceSeconds, r.voxelizeSeconds, r.splatSeconds, r.clusterSeconds, r.bakeSeconds,
        r.peakRssBytes / 1048576.0, r.vdbBytes / 1024.0, r.gpuBytes / 1024.0, r.activeVoxels,
        r.denseVoxels, r.vdlTexels, r.frameMs, r.irradianceRelRmse, r.irradianceRelMae,
        r.indirectRelRmse, int(r.paretoTime), int(r.paretoMemory),
        int(p.sameSettings(paperPoint())));
    os << line;
  }
  return os.str();
}

namespace sweep_internal {

std::string markdownTable(const std::vector<SweepResult>& results) {
  std::ostringstream os;
  os << "| setting | varies | trace s | voxelize s | splat s | gather+cluster s | bake s | "
        "peak RSS MiB | .vdb KiB | GPU KiB | active voxels | GPU leaves | frame ms | "
        "irradiance rel. RMSE | rel. MAE | indirect image rel. RMSE | front |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
  for (const SweepResult& r : results) {
    const bool paper = r.point.sameSettings(paperPoint());
    char line[1024];
    std::string front = std::string(r.paretoTime ? "T" : "") + (r.paretoMemory ? "M" : "");
    std::snprintf(line, sizeof line,
                  "| %s%s%s | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f | %.0f | %.0f | %.0f "
                  "| %s | %s | %.1f%% | %.1f%% | %s | %s |\n",
                  paper ? "**" : "", r.point.label().c_str(), paper ? "** (paper)" : "",
                  r.point.group.c_str(), r.traceSeconds, r.voxelizeSeconds, r.splatSeconds,
                  r.clusterSeconds, r.bakeSeconds, r.peakRssBytes / 1048576.0, r.vdbBytes / 1024.0,
                  r.gpuBytes / 1024.0, r.activeVoxels,
                  r.gpuLeaves >= 0 ? formatNumber(r.gpuLeaves).c_str() : "-",
                  r.frameMs >= 0 ? formatNumber(std::round(r.frameMs * 10) / 10).c_str() : "-",
                  100 * r.irradianceRelRmse, 100 * r.irradianceRelMae,
                  r.indirectRelRmse >= 0
                      ? (formatNumber(std::round(1000 * r.indirectRelRmse) / 10) + "%").c_str()
                      : "-",
                  front.c_str());
    os << line;
  }
  return os.str();
}

/// Data file for gnuplot: x y "label", one point per line, sorted by x.
std::string plotData(std::vector<std::pair<double, std::pair<double, std::string>>> rows) {
  std::sort(rows.begin(), rows.end());
  std::ostringstream os;
  for (const auto& row : rows)
    os << row.first << " " << row.second.first << " \"" << row.second.second << "\"\n";
  return os.str();
}

}  // namespace sweep_internal

void writeSweepReport(const SweepParams& params, const std::vector<SweepResult>& results,
                      std::FILE* log) {
  using namespace sweep_internal;
  const std::string dir = params.outDir;
  writeTextAtomically(dir + "/sweep.csv", sweepCsv(results));

  // Plot data: x = bake seconds or GPU KiB, y = irradiance relative RMSE in %.
  using Rows = std::vector<std::pair<double, std::pair<double, std::string>>>;
  Rows allTime, allMem, frontTime, frontMem, paperTime, paperMem, toleranceMem;
  for (const SweepResult& r : results) {
    const double e = 100 * r.irradianceRelRmse, t = r.bakeSeconds, m = r.gpuBytes / 1024.0;
    const std::string l = r.point.label();
    allTime.push_back({t, {e, l}});
    allMem.push_back({m, {e, l}});
    if (r.paretoTime) frontTime.push_back({t, {e, l}});
    if (r.paretoMemory) frontMem.push_back({m, {e, l}});
    if (r.point.sameSettings(paperPoint())) {
      paperTime.push_back({t, {e, l}});
      paperMem.push_back({m, {e, l}});
      toleranceMem.push_back({m, {e, "uniform"}});
    }
    // The adaptive leaves' trade: the paper's bake at each tolerance.
    SweepPoint uniform = r.point;
    uniform.tolerance = 0;
    uniform.group = "paper";
    if (r.point.tolerance > 0 && uniform.sameSettings(paperPoint())) {
      toleranceMem.push_back({m, {e, "tol " + formatNumber(r.point.tolerance)}});
    }
  }
  const std::string dataDir = dir + "/plot-data";
  fs::create_directories(dataDir);
  writeTextAtomically(dataDir + "/all-time.dat", plotData(allTime));
  writeTextAtomically(dataDir + "/all-memory.dat", plotData(allMem));
  writeTextAtomically(dataDir + "/front-time.dat", plotData(frontTime));
  writeTextAtomically(dataDir + "/front-memory.dat", plotData(frontMem));
  writeTextAtomically(dataDir + "/paper-time.dat", plotData(paperTime));
  writeTextAtomically(dataDir + "/paper-memory.dat", plotData(paperMem));
  writeTextAtomically(dataDir + "/tolerance-memory.dat", plotData(toleranceMem));
  const std::string sceneName = fs::path(params.scene).stem().string();
  std::ostringstream gp;
  gp << "# Redraw with: cd " << dir << " && gnuplot sweep.gp\n"
     << "set terminal pngcairo size 1000,700 font 'sans,10'\n"
     << "set logscale x\nset grid\nset key top right\n"
     << "set ylabel 'indirect irradiance: relative RMSE vs reference (%)'\n";
  auto plot = [&](const char* png, const char* xlabel, const char* which) {
    const bool memory = std::string(which) == "memory";
    gp << "set output '" << png << "'\n"
       << "set title '" << sceneName << ": error against " << xlabel << "'\n"
       << "set xlabel '" << xlabel << " (log scale)'\n"
       << "plot 'plot-data/all-" << which
       << ".dat' using 1:2 with points pt 7 ps 1 lc rgb '#909090' title 'settings', \\\n"
       << "     'plot-data/front-" << which
       << ".dat' using 1:2 with linespoints pt 7 ps 1.2 lw 2 lc rgb '#d62728' title 'Pareto "
          "front', \\\n"
       << "     'plot-data/front-" << which
       << ".dat' using 1:2:3 with labels offset 1,0.6 left font 'sans,8' notitle, \\\n";
    if (memory) {
      gp << "     'plot-data/tolerance-memory.dat' using 1:2 with linespoints pt 9 ps 1.2 lw 2 "
            "lc rgb '#2ca02c' title 'adaptive leaves (tolerance)', \\\n"
         << "     'plot-data/tolerance-memory.dat' using 1:2:3 with labels offset -1,-0.9 right "
            "font 'sans,8' tc rgb '#2ca02c' notitle, \\\n";
    }
    gp << "     'plot-data/paper-" << which
       << ".dat' using 1:2 with points pt 5 ps 2.2 lc rgb '#1f77b4' title 'paper (d6 600k k300 "
          "v4)'\n";
  };
  plot("error-vs-bake-time.png", "bake time, s", "time");
  plot("error-vs-memory.png", "GPU octree + VDL textures, KiB", "memory");
  writeTextAtomically(dir + "/sweep.gp", gp.str());
  const bool plotted = runGnuplot(dir, dir + "/sweep.gp");
  if (!plotted && log) std::fprintf(log, "sweep: gnuplot failed or missing; no plots drawn\n");

  std::ostringstream md;
  md << "# Sweep: " << sceneName << "\n\n"
     << "Measured by `lightoctree sweep " << fs::path(params.scene).filename().string()
     << (params.scale == SweepScale::Quick ? " --quick" : "") << "`; images " << params.width
     << " x " << params.height << " from the scene camera, references path-traced at "
     << params.referenceSpp
     << " spp. Errors are luminance relative RMSE / MAE over the pixels that see the scene "
        "(docs/accuracy.md). "
        "*front*: T = on the Pareto front of irradiance error vs bake "
        "time, M = vs GPU bytes. Frame times: OSMesa (software GL), "
     << params.frames
     << " frames, indirect mode. Times are wall-clock on this machine "
        "and include every bake stage.\n\n"
     << "The references' own noise, the floor under these errors (relative RMS standard "
        "error of luminance): irradiance "
     << formatNumber(results.empty() ? 0.0 : percent2(results.front().referenceIrradianceNoise))
     << "%, indirect image "
     << formatNumber(results.empty() ? 0.0 : percent2(results.front().referenceIndirectNoise))
     << "%.\n\n"
     << markdownTable(results) << "\n";
  if (plotted) {
    md << "![error vs bake time](error-vs-bake-time.png)\n\n"
       << "![error vs memory](error-vs-memory.png)\n\n";
  }
  if (fs::exists(dir + "/irradiance-paper.png"))
    md << "Paper's settings: reference | light octree | difference (red = a quarter of the "
          "mean):\n\n![paper](irradiance-paper.png)\n\n";
  if (fs::exists(dir + "/irradiance-best.png"))
    md << "Most accurate point on the bake-time front:\n\n![best](irradiance-best.png)\n";
  writeTextAtomically(dir + "/sweep.md", md.str());
}

}  // namespace lo
