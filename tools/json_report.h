#pragma once
/// @file tools/json_report.h
/// @brief The `--json FILE` report of `render`, `reference`, `lightmap` and
/// `convert` (bake's is `--stats-json`, compare's `--json`, inspect prints
/// its own with `--json`): what a script needs without parsing prose.
///
/// The document:
///   command          "render", ...
///   version          the program's version
///   read             [{role, path}]: the scene, its buffers and images, the grid
///   written          [{path, bytes}]: every file the command wrote (the report
///                    itself aside), in the order written
///   figures          the command's own numbers (its section of README.md's
///                    "Scripting" says which)
///   stages           per row: name, seconds, rss_bytes, peak_rss_bytes
///   peak_rss_bytes   of the process
/// Bytes that are not UTF-8 (a path) are written as U+FFFD.

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "core/file.h"
#include "core/file_set.h"
#include "core/resources.h"

namespace lo::tool {

struct JsonReport {
  std::string command;
  NamedPaths read;  ///< (role, path)
  nlohmann::json figures = nlohmann::json::object();

  /// The document for the files in `written` and the stage rows `stages`.
  std::string text(const AtomicFileSet& written, const std::vector<StageReport>& stages) const;
  /// Adds the report to `written` as `path` (so it appears with the set).
  void addTo(AtomicFileSet& written, const std::string& path,
             const std::vector<StageReport>& stages) const;
};

}  // namespace lo::tool
