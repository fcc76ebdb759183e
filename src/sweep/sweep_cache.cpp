// The sweep's cache (sweep_internal.h, SweepCache): JSON files beside the
// bakes and images, so that a sweep run again computes only what changed.

#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/file.h"
#include "image/image.h"
#include "sweep/sweep_internal.h"

namespace fs = std::filesystem;

namespace lo {
namespace sweep_internal {
namespace {

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
          {"stored_photons", r.storedPhotons},
          {"noise_figure", r.noiseFigure},
          {"gpu_leaves", r.gpuLeaves},
          {"frame_ms", r.frameMs},
          {"irradiance_rel_rmse", r.irradianceRelRmse},
          {"irradiance_rel_mae", r.irradianceRelMae},
          {"irradiance_binned_rel_rmse", r.irradianceBinnedRelRmse},
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
  r.storedPhotons = j.at("stored_photons");
  r.noiseFigure = j.at("noise_figure");
  r.gpuLeaves = j.value("gpu_leaves", -1.0);
  r.frameMs = j.at("frame_ms");
  r.irradianceRelRmse = j.at("irradiance_rel_rmse");
  r.irradianceRelMae = j.at("irradiance_rel_mae");
  r.irradianceBinnedRelRmse = j.at("irradiance_binned_rel_rmse");
  r.indirectRelRmse = j.at("indirect_rel_rmse");
  return r;
}

nlohmann::json toJson(const BakeFigures& f) {
  return {{"trace_seconds", f.traceSeconds},   {"voxelize_seconds", f.voxelizeSeconds},
          {"splat_seconds", f.splatSeconds},   {"cluster_seconds", f.clusterSeconds},
          {"bake_seconds", f.bakeSeconds},     {"peak_rss_bytes", f.peakRssBytes},
          {"vdb_bytes", f.vdbBytes},           {"active_voxels", f.activeVoxels},
          {"dense_voxels", f.denseVoxels},     {"stored_photons", f.storedPhotons},
          {"noise_figure", f.noiseFigure}};
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
  f.storedPhotons = j.at("stored_photons");
  f.noiseFigure = j.at("noise_figure");
  return f;
}

nlohmann::json readJson(const std::string& path) { return nlohmann::json::parse(readFile(path)); }

}  // namespace

SweepCache::SweepCache(const SweepParams& params, const std::string& dir)
    : params_(params), dir_(dir) {
  context_ = nlohmann::json({{"scene", fs::path(params.scene).filename().string()},
                             {"width", params.width},
                             {"height", params.height},
                             {"spp", params.referenceSpp},
                             {"frames", params.frames},
                             {"threads", params.threads},
                             {"seed", params.seed},
                             {"version", LO_VERSION}})
                 .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string SweepCache::vdbPath(const SweepPoint& point) const {
  return dir_ + "/" + point.bakeKey() + ".vdb";
}

std::string SweepCache::imagePath(const SweepPoint& point, const std::string& what) const {
  return dir_ + "/" + point.key() + "-" + what + ".exr";
}

namespace {

/// What the references were rendered with: another key renders them again.
nlohmann::json referenceKey(const SweepParams& params, const PinholeCamera& camera) {
  return {{"scene", fs::path(params.scene).filename().string()},
          {"width", params.width},
          {"height", params.height},
          {"spp", params.referenceSpp},
          {"seed", params.seed},
          {"indirect", params.frames > 0},
          {"camera",
           {camera.eye.x, camera.eye.y, camera.eye.z, camera.forward.x, camera.forward.y,
            camera.forward.z, camera.up.x, camera.up.y, camera.up.z, camera.yfov}}};
}

}  // namespace

bool SweepCache::loadReferences(References& refs, const PinholeCamera& camera) const {
  const std::string keyFile = dir_ + "/reference.json";
  const std::string irrFile = dir_ + "/reference-irradiance.exr";
  const std::string indFile = dir_ + "/reference-indirect.exr";
  const std::string maskFile = dir_ + "/reference-emitters.exr";
  if (!fs::exists(keyFile) || !fs::exists(irrFile) || !fs::exists(maskFile) ||
      (params_.frames > 0 && !fs::exists(indFile)))
    return false;
  const nlohmann::json cached = readJson(keyFile);
  if (cached["key"] != referenceKey(params_, camera)) return false;
  if (!cached.contains("irradiance_binned_noise")) return false;  // before the emitter mask
  refs.irradiance = readImage(irrFile);
  refs.emitterMask = readImage(maskFile);
  refs.irradianceBinnedNoise = cached.value("irradiance_binned_noise", 0.0);
  if (params_.frames > 0) refs.indirect = readImage(indFile);
  refs.irradianceNoise = cached.value("irradiance_noise", 0.0);
  refs.indirectNoise = cached.value("indirect_noise", 0.0);
  refs.seconds = cached.value("seconds", 0.0);
  return true;
}

void SweepCache::storeReferences(const References& refs, const PinholeCamera& camera) const {
  writeExr(dir_ + "/reference-irradiance.exr", refs.irradiance);
  writeExr(dir_ + "/reference-emitters.exr", refs.emitterMask);
  if (params_.frames > 0) writeExr(dir_ + "/reference-indirect.exr", refs.indirect);
  const nlohmann::json j = {{"key", referenceKey(params_, camera)},
                            {"irradiance_noise", refs.irradianceNoise},
                            {"indirect_noise", refs.indirectNoise},
                            {"irradiance_binned_noise", refs.irradianceBinnedNoise},
                            {"seconds", refs.seconds}};
  writeTextAtomically(dir_ + "/reference.json", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

bool SweepCache::loadBake(const SweepPoint& point, BakeFigures& figures) const {
  const std::string stats = dir_ + "/" + point.bakeKey() + "-bake.json";
  if (!fs::exists(stats) || !fs::exists(vdbPath(point))) return false;
  const nlohmann::json cached = readJson(stats);
  if (cached.value("context", nlohmann::json()) != nlohmann::json::parse(context_)) return false;
  if (!cached.at("bake").contains("noise_figure")) return false;  // before the noise figure
  figures = bakeFiguresFromJson(cached.at("bake"));
  return true;
}

void SweepCache::storeBake(const SweepPoint& point, const BakeFigures& figures) const {
  writeTextAtomically(
      dir_ + "/" + point.bakeKey() + "-bake.json",
      nlohmann::json({{"context", nlohmann::json::parse(context_)}, {"bake", toJson(figures)}})
              .dump(2, ' ', false, nlohmann::json::error_handler_t::replace) +
          "\n");
}

bool SweepCache::loadResult(const SweepPoint& point, SweepResult& result) const {
  const std::string file = dir_ + "/" + point.key() + ".json";
  if (!fs::exists(file)) return false;
  const nlohmann::json cached = readJson(file);
  if (cached["context"] != nlohmann::json::parse(context_)) return false;
  // Results from before the binned error and the noise figure: stale.
  if (!cached["result"].contains("irradiance_binned_rel_rmse")) return false;
  result = resultFromJson(cached["result"], point);
  return true;
}

void SweepCache::storeResult(const SweepResult& result) const {
  writeTextAtomically(dir_ + "/" + result.point.key() + ".json",
                      nlohmann::json({{"context", nlohmann::json::parse(context_)},
                                      {"result", resultJson(result)}})
                              .dump(2, ' ', false, nlohmann::json::error_handler_t::replace) +
                          "\n");
}

}  // namespace sweep_internal
}  // namespace lo
