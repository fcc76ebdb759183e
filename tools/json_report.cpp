#include "json_report.h"

namespace lo::tool {

std::string JsonReport::text(const AtomicFileSet& written,
                             const std::vector<StageReport>& stages) const {
  using nlohmann::json;
  json j;
  j["command"] = command;
  j["version"] = LO_VERSION;
  json read = json::array();
  for (const auto& [role, path] : this->read) {
    if (!path.empty()) read.push_back({{"role", role}, {"path", path}});
  }
  j["read"] = read;
  json files = json::array();
  for (const std::string& path : written.paths()) {
    files.push_back({{"path", path}, {"bytes", written.bytesOf(path)}});
  }
  j["written"] = files;
  j["figures"] = figures;
  json rows = json::array();
  for (const StageReport& r : stages) {
    rows.push_back({{"name", r.name},
                    {"seconds", r.seconds},
                    {"rss_bytes", r.rssBytes},
                    {"peak_rss_bytes", r.peakBytes}});
  }
  j["stages"] = rows;
  j["peak_rss_bytes"] = peakRssBytes();
  return j.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

void JsonReport::addTo(AtomicFileSet& written, const std::string& path,
                       const std::vector<StageReport>& stages) const {
  written.addText(path, text(written, stages));
}

}  // namespace lo::tool
