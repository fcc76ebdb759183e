// `lightoctree inspect`: grids, metadata and contract checks of a .vdb file,
// as text or JSON. Exit 0 when every check passes, 2 when one fails, 1 when
// the file cannot be read (the front end's error exit).

#include <CLI/CLI.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "bake/stats_json.h"
#include "cli_checks.h"
#include "commands.h"
#include "core/printable.h"
#include "report.h"
#include "vdb/vdb_inspect.h"

namespace lo::tool {
namespace {

struct InspectOptions {
  std::string input;
  bool json = false;
};

constexpr int kChecksFailed = 3;  // 1: an error, 2: a usage error (lightoctree.cpp)

std::string range(const GridSummary& g) {
  if (g.min.empty()) return g.valueType == "float" || g.valueType == "vec3s" ? "(none)" : "";
  std::string s;
  for (size_t c = 0; c < g.min.size(); ++c) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s%.4g..%.4g", c ? ", " : "", g.min[c], g.max[c]);
    s += buf;
  }
  return s;
}

nlohmann::json toJson(const VdbReport& r) {
  nlohmann::json j;
  j["path"] = r.path;
  j["file_bytes"] = r.fileBytes;
  j["kind"] = r.kind;
  j["ok"] = r.ok();
  j["metadata"] = nlohmann::json::object();
  for (const auto& [k, v] : r.metadata) j["metadata"][k] = v;
  j["grids"] = nlohmann::json::array();
  for (const GridSummary& g : r.grids) {
    nlohmann::json gj = {{"name", g.name},
                         {"type", g.type},
                         {"value_type", g.valueType},
                         {"active_voxels", g.activeVoxels},
                         {"memory_bytes", g.memoryBytes},
                         {"half_float", g.halfFloat},
                         {"non_finite", g.nonFinite},
                         {"voxel_size", g.voxelSize},
                         {"origin", g.origin}};
    if (!g.min.empty()) {
      gj["min"] = g.min;
      gj["max"] = g.max;
    }
    gj["metadata"] = nlohmann::json::object();
    for (const auto& [k, v] : g.metadata) gj["metadata"][k] = v;
    j["grids"].push_back(gj);
  }
  j["noise"] = nlohmann::json::parse(noiseSummaryJson(r.noise));
  j["checks"] = nlohmann::json::array();
  for (const VdbCheck& c : r.checks) {
    j["checks"].push_back({{"name", c.name}, {"passed", c.passed}, {"detail", c.detail}});
  }
  return j;
}

// Every name and value a file supplies goes through printable (control
// characters escaped): the JSON report escapes them itself.
void printText(const VdbReport& r) {
  std::printf("%s: %s, %s file\n", printable(r.path).c_str(),
              formatBytes(size_t(r.fileBytes)).c_str(),
              r.kind == "vdl" ? "lightoctree VDL" : (r.kind == "photons" ? "photon" : "OpenVDB"));
  std::printf("\nmetadata\n");
  for (const auto& [k, v] : r.metadata) {
    std::printf("  %-18s %s\n", printable(k).c_str(), printable(v).c_str());
  }
  std::printf("\n  %-18s %-12s %10s %10s %4s  %s\n", "grid", "value type", "active", "memory",
              "half", "range (per component, active voxels)");
  uint64_t memory = 0;
  for (const GridSummary& g : r.grids) {
    memory += g.memoryBytes;
    std::printf("  %-18s %-12s %10s %10s %4s  %s\n", printable(g.name).c_str(),
                printable(g.valueType).c_str(),
                formatCount(size_t(g.activeVoxels)).c_str(),
                formatBytes(size_t(g.memoryBytes)).c_str(), g.halfFloat ? "yes" : "no",
                range(g).c_str());
  }
  if (!r.grids.empty()) {
    const GridSummary& g = r.grids.front();
    std::printf(
        "  %zu grids, %s in memory; voxel size %.6g, voxel (0,0,0) centre (%.6g, %.6g, "
        "%.6g)\n",
        r.grids.size(), formatBytes(size_t(memory)).c_str(), g.voxelSize[0], g.origin[0],
        g.origin[1], g.origin[2]);
  }
  if (r.noise.recorded) {
    std::printf("\n%s over %s lit voxels and layers (%s unlit)\n", r.noise.ToString().c_str(),
                formatCount(r.noise.lit).c_str(), formatCount(r.noise.unlit).c_str());
  }
  std::printf("\nchecks\n");
  for (const VdbCheck& c : r.checks) {
    std::printf("  %-4s %-24s %s\n", c.passed ? "ok" : "FAIL", c.name.c_str(),
                printable(c.detail).c_str());
  }
  std::printf("\n%s\n", r.ok() ? "all checks passed" : "some checks FAILED");
}

int runInspect(const InspectOptions& opt) {
  VdbReport r = inspectVdb(opt.input);
  if (opt.json) {
    // Metadata of other tools need not be UTF-8: invalid bytes become U+FFFD.
    std::printf("%s\n",
                toJson(r).dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else {
    printText(r);
  }
  return r.ok() ? 0 : kChecksFailed;
}

void addInspectOptions(CLI::App* cmd, InspectOptions& opt) {
  cmd->description(
      "List a .vdb file's grids, metadata, value ranges and memory, and check the VDL contract "
      "(exit 0: checks pass, 3: a check failed, 1: unreadable file, 2: bad command line).");
  cmd->add_option("input", opt.input, ".vdb file")->required()->check(existingFile());
  cmd->add_flag("--json", opt.json, "Print the report as JSON");
}

}  // namespace

std::function<int()> addInspectCommand(CLI::App& app) {
  return addCommand(app, "inspect", addInspectOptions, runInspect);
}

}  // namespace lo::tool
