#include "bake/stats_json.h"

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace lo {

std::string noiseSummaryJson(const NoiseSummary& n) {
  if (!n.recorded) return "null";
  const nlohmann::json j = {{"quantile", n.quantile},
                            {"median", n.median},
                            {"lit", n.lit},
                            {"unlit", n.unlit},
                            {"mean_irradiance", n.meanLuminance}};
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string bakeStatsJson(const BakeStats& stats, const BakeStatsRecord& record) {
  using nlohmann::json;
  const BakeParams& p = record.params;
  auto onOff = [](bool on) { return on ? "on" : "off"; };
  json j;
  j["scene"] = record.scene;
  j["output"] = record.output;
  j["parameters"] = {{"depth", p.depth},
                     {"photons", p.targetError > 0 ? json(nullptr) : json(p.photons)},
                     {"target_error", p.targetError > 0 ? json(p.targetError) : json(nullptr)},
                     {"max_photons", p.targetError > 0 ? json(p.maxPhotons) : json(nullptr)},
                     {"knn", p.effectiveKnn()},
                     {"radius", record.radius},
                     {"vdls", p.vdls.ToString()},
                     {"representation", representationName(p.representation)},
                     {"seed", p.seed},
                     {"threads", record.threads},
                     {"include_direct", p.includeDirect},
                     {"layers", onOff(p.layers)},
                     {"gather_occlusion", onOff(p.occlusion)},
                     {"edge_correction", onOff(p.edgeCorrection)},
                     {"smoothing", onOff(p.smoothing)}};
  j["counts"] = {{"triangles", stats.triangles},
                 {"stored_photons", stats.storedPhotons},
                 {"emitted_paths", stats.emittedPaths},
                 {"empty_paths", stats.emptyPaths},
                 {"active_voxels", stats.level.activeVoxels},
                 {"dense_voxels", stats.denseVoxels},
                 {"photons_outside_grid", stats.level.droppedPhotons},
                 {"vdb_bytes", record.vdbBytes}};
  auto noiseJson = [](const NoiseSummary& n) { return json::parse(noiseSummaryJson(n)); };
  j["noise"] = noiseJson(stats.noise);
  if (!stats.passes.empty()) {
    json passes = json::array();
    for (const TargetPass& pass : stats.passes) {
      passes.push_back({{"photons", pass.photons},
                        {"paths", pass.paths},
                        {"noise", noiseJson(pass.noise)},
                        {"seconds", pass.seconds}});
    }
    j["target"] = {{"passes", passes}, {"stop", stats.targetStop}};
  }
  j["thread_seconds"] = {{"gather", stats.level.threadSeconds.gatherSeconds},
                         {"cluster", stats.level.threadSeconds.clusterSeconds}};
  json stages = json::array();
  double total = 0;
  for (const StageReport& r : record.stages) {
    stages.push_back({{"name", r.name},
                      {"seconds", r.seconds},
                      {"rss_bytes", r.rssBytes},
                      {"peak_rss_bytes", r.peakBytes}});
    total += r.seconds;
  }
  j["stages"] = stages;
  j["total_seconds"] = total;
  j["peak_rss_bytes"] = record.peakRssBytes;
  for (const auto& [key, text] : record.sections) {
    if (j.contains(key)) {
      throw InputError("bake statistics: the section '" + key + "' is one of the document's own");
    }
    // Parsed, so that the document stays one JSON value with its keys in
    // order; numbers read back exactly and are written as they were.
    json section = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (section.is_discarded()) {
      throw InputError("bake statistics: the section '" + key + "' is not JSON");
    }
    j[key] = std::move(section);
  }
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace lo
