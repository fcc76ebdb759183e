#include "distributed/distributed_stats.h"

#include <cstdarg>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/resources.h"

namespace lo {

namespace {
/// printf into a std::string.
void appendf(std::string& out, const char* format, ...) {
  char line[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(line, sizeof line, format, args);
  va_end(args);
  out += line;
}
}  // namespace

std::string ranksTable(const DistributedStats& d, size_t storedPhotons) {
  std::string out;
  appendf(out, "\n%d^3 tiles, photon halo %d voxels%s\n", d.tilesPerAxis, d.photonHalo,
          d.attempts > 1 ? " (second attempt: the bins' margin exceeded the first halo's)" : "");
  appendf(out, "%4s %12s %12s %10s %10s %7s %12s %10s %8s\n", "rank", "photons", "held", "voxels",
          "computed", "work", "sent", "peak RSS", "seconds");
  for (const RankStats& r : d.ranks) {
    appendf(out, "%4d %12s %12s %10s %10s %6.1f%% %12s %10s %8.2f\n", r.rank,
            formatCount(size_t(r.photonsTraced)).c_str(),
            formatCount(size_t(r.photonsHeld)).c_str(), formatCount(size_t(r.voxelsOwned)).c_str(),
            formatCount(size_t(r.voxelsComputed)).c_str(), 100.0 * r.workShare,
            formatBytes(size_t(r.bytesSent)).c_str(), formatBytes(size_t(r.peakRssBytes)).c_str(),
            r.totalSeconds);
  }
  uint64_t sent = 0;
  for (const RankStats& r : d.ranks) sent += r.bytesSent;
  if (storedPhotons > 0) {
    appendf(out, "photons exchanged: %.1f bytes per stored photon\n",
            double(sent) / double(storedPhotons));
  }
  return out;
}

std::string distributedStatsJson(const DistributedStats& d, int ranks, size_t storedPhotons) {
  nlohmann::json perRank = nlohmann::json::array();
  uint64_t sent = 0;
  for (const RankStats& r : d.ranks) {
    sent += r.bytesSent;
    perRank.push_back({{"rank", r.rank},
                       {"photons_traced", r.photonsTraced},
                       {"photons_held", r.photonsHeld},
                       {"tiles_owned", r.tilesOwned},
                       {"work_share", r.workShare},
                       {"voxels_owned", r.voxelsOwned},
                       {"voxels_computed", r.voxelsComputed},
                       {"voxels_held", r.voxelsHeld},
                       {"bytes_sent", r.bytesSent},
                       {"bytes_received", r.bytesReceived},
                       {"peak_rss_bytes", r.peakRssBytes},
                       {"seconds", {{"trace", r.traceSeconds},
                                    {"exchange", r.exchangeSeconds},
                                    {"voxelize", r.voxelizeSeconds},
                                    {"splat", r.splatSeconds},
                                    {"gather_cluster", r.gatherClusterSeconds},
                                    {"merge", r.mergeSeconds},
                                    {"total", r.totalSeconds}}}});
  }
  const nlohmann::json j = {
      {"ranks", ranks},
      {"tiles_per_axis", d.tilesPerAxis},
      {"photon_halo_voxels", d.photonHalo},
      {"attempts", d.attempts},
      {"bin_margin_voxels", d.binMarginVoxels},
      {"bytes_exchanged_per_photon", storedPhotons ? double(sent) / double(storedPhotons) : 0.0},
      {"per_rank", perRank},
      // Tile (x * T + y) * T + z: its rank and estimated work (docs/scale.md).
      {"tile_owner", d.tileOwner},
      {"tile_work", d.tileWork}};
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace lo
