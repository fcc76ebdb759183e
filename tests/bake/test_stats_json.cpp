// The bake's statistics file (bake/stats_json.h): every member of the schema
// with the values given, the flags' text for the settings, the total the sum
// of the rows, later stages' sections in their place, and a section that is
// not JSON or takes one of the document's keys refused.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "bake/stats_json.h"
#include "core/error.h"

namespace lo {
namespace {

BakeStatsRecord record() {
  BakeStatsRecord r;
  r.scene = "scenes/room.gltf";
  r.output = "room.vdb";
  r.params.depth = 5;
  r.params.photons = 12345;
  r.params.vdls.automatic = true;
  r.params.representation = LightRepresentation::Sh2;
  r.params.seed = 18446744073709551615ull;
  r.params.layers = false;
  r.params.includeDirect = true;
  r.radius = 0.125f;
  r.threads = 3;
  r.vdbBytes = 4096;
  r.peakRssBytes = 1u << 20;
  StageReport a;
  a.name = "trace photons";
  a.seconds = 0.25;
  a.rssBytes = 100;
  a.peakBytes = 200;
  StageReport b = a;
  b.name = "write .vdb";
  b.seconds = 0.5;
  r.stages = {a, b};
  return r;
}

TEST(BakeStatsJson, HoldsTheSchemaWithTheValuesGiven) {
  BakeStats stats;
  stats.triangles = 12;
  stats.storedPhotons = 12000;
  stats.emittedPaths = 15000;
  stats.emptyPaths = 1500;
  stats.denseVoxels = 32768;
  stats.level.activeVoxels = 900;
  stats.level.droppedPhotons = 7;
  stats.level.threadSeconds.gatherSeconds = 1.5;
  const std::string text = bakeStatsJson(stats, record());
  ASSERT_EQ(text.back(), '\n');
  EXPECT_EQ(text, bakeStatsJson(stats, record())) << "deterministic";
  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_EQ(j["scene"], "scenes/room.gltf");
  EXPECT_EQ(j["output"], "room.vdb");
  const nlohmann::json& p = j["parameters"];
  EXPECT_EQ(p["depth"], 5);
  EXPECT_EQ(p["photons"], 12345);
  EXPECT_EQ(p["knn"], 300);
  EXPECT_EQ(p["radius"].get<double>(), 0.125);
  EXPECT_EQ(p["vdls"], "auto");
  EXPECT_EQ(p["representation"], "sh2");
  EXPECT_EQ(p["seed"].get<uint64_t>(), 18446744073709551615ull);
  EXPECT_EQ(p["threads"], 3);
  EXPECT_EQ(p["include_direct"], true);
  EXPECT_EQ(p["layers"], "off");
  EXPECT_EQ(p["gather_occlusion"], "on");
  EXPECT_EQ(p["edge_correction"], "on");
  EXPECT_EQ(p["smoothing"], "on");
  EXPECT_TRUE(p["target_error"].is_null());  // a fixed budget
  EXPECT_TRUE(p["max_photons"].is_null());
  EXPECT_EQ(p.size(), 15u);
  const nlohmann::json& c = j["counts"];
  EXPECT_EQ(c["triangles"], 12);
  EXPECT_EQ(c["stored_photons"], 12000);
  EXPECT_EQ(c["emitted_paths"], 15000);
  EXPECT_EQ(c["empty_paths"], 1500);
  EXPECT_EQ(c["active_voxels"], 900);
  EXPECT_EQ(c["dense_voxels"], 32768);
  EXPECT_EQ(c["photons_outside_grid"], 7);
  EXPECT_EQ(c["vdb_bytes"], 4096);
  EXPECT_EQ(j["thread_seconds"]["gather"].get<double>(), 1.5);
  EXPECT_EQ(j["thread_seconds"]["cluster"].get<double>(), 0.0);
  ASSERT_EQ(j["stages"].size(), 2u);
  EXPECT_EQ(j["stages"][1]["name"], "write .vdb");
  EXPECT_EQ(j["stages"][0]["rss_bytes"], 100);
  EXPECT_EQ(j["stages"][0]["peak_rss_bytes"], 200);
  EXPECT_EQ(j["total_seconds"].get<double>(), 0.75);
  EXPECT_EQ(j["peak_rss_bytes"], 1 << 20);
  EXPECT_TRUE(j["noise"].is_null());  // not summarised: no noise recorded
  EXPECT_EQ(j.size(), 9u);
  // nlohmann-json's layout: keys in order, two spaces.
  EXPECT_LT(text.find("\"counts\""), text.find("\"output\""));
  EXPECT_EQ(text.rfind("{\n  \"counts\": {\n    \"active_voxels\": 900,", 0), 0u) << text;
}

TEST(BakeStatsJson, SectionsOfLaterStagesGoInAsGiven) {
  BakeStatsRecord r = record();
  r.sections.emplace_back("distributed", R"({"ranks": 2, "tile_work": [0.1, 2.5e-07]})");
  const nlohmann::json j = nlohmann::json::parse(bakeStatsJson(BakeStats{}, r));
  EXPECT_EQ(j["distributed"]["ranks"], 2);
  EXPECT_EQ(j["distributed"]["tile_work"][1].get<double>(), 2.5e-07);

  BakeStatsRecord bad = record();
  bad.sections.emplace_back("distributed", "{\"ranks\": ");
  EXPECT_THROW(bakeStatsJson(BakeStats{}, bad), InputError);
  BakeStatsRecord own = record();
  own.sections.emplace_back("counts", "{}");
  EXPECT_THROW(bakeStatsJson(BakeStats{}, own), InputError);
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

TEST(BakeStatsJson, TheNoiseFigureIsSpelledOnce) {
  EXPECT_EQ(noiseSummaryJson(NoiseSummary{}), "null");
  NoiseSummary n;
  n.recorded = true;
  n.lit = 900;
  n.unlit = 12;
  n.meanLuminance = 0.5;
  n.median = 0.03;
  n.quantile = 0.0625;
  const nlohmann::json j = nlohmann::json::parse(noiseSummaryJson(n));
  EXPECT_EQ(j.size(), 5u);
  EXPECT_EQ(j["quantile"].get<double>(), 0.0625);
  EXPECT_EQ(j["median"].get<double>(), 0.03);
  EXPECT_EQ(j["lit"], 900);
  EXPECT_EQ(j["unlit"], 12);
  EXPECT_EQ(j["mean_irradiance"].get<double>(), 0.5);
  BakeStats stats;
  stats.noise = n;
  const nlohmann::json doc = nlohmann::json::parse(bakeStatsJson(stats, BakeStatsRecord{}));
  EXPECT_EQ(doc["noise"], j);
}

}  // namespace
}  // namespace lo
