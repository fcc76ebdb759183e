// lightoctree: the command-line front end. Parses, calls the stages, reports.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "cli_checks.h"
#include "commands.h"

namespace {

/// Exit status of a command line the parser refuses (docs: README, "Exit status").
constexpr int kUsageError = 2;

int run(int argc, char** argv) {
  CLI::App app{
      "Light Octree " LO_VERSION
      ": bakes photon-mapped global illumination into sparse OpenVDB grids of virtual "
      "directional lights.",
      "lightoctree"};
  app.require_subcommand(1);
  app.set_version_flag("--version", LO_VERSION);
  std::vector<std::function<int()>> commands;
  commands.push_back(lo::tool::addBakeCommand(app));
  commands.push_back(lo::tool::addRenderCommand(app));
  commands.push_back(lo::tool::addLightmapCommand(app));
  commands.push_back(lo::tool::addConvertCommand(app));
  commands.push_back(lo::tool::addInspectCommand(app));
  commands.push_back(lo::tool::addReferenceCommand(app));
  commands.push_back(lo::tool::addCompareCommand(app));
  commands.push_back(lo::tool::addSweepCommand(app));
  commands.push_back(lo::tool::addViewCommand(app));
  lo::tool::requireFiniteNumbers(app);  // every float flag, those with a range or not
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; a usage error exits 2, as command-line
    // tools do (the parser's own codes, 105-109, say nothing to a script).
    return app.exit(e) == 0 ? 0 : kUsageError;
  }
  for (auto& command : commands) {
    int rc = command();
    if (rc >= 0) return rc;
  }
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lightoctree: error: %s\n", e.what());
    return 1;
  }
}
