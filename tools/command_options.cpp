#include "command_options.h"

#include <CLI/CLI.hpp>

#include "cli_checks.h"
#include "image/image.h"

namespace lo::tool {

CLI::Option* addLightsArgument(CLI::App* cmd, std::string& lights, const std::string& note) {
  return cmd->add_option("lights", lights, "Baked VDL grid (.vdb from `lightoctree bake`)" + note)
      ->check(existingFile());
}

void addSizeOptions(CLI::App* cmd, int& width, int& height, const std::string& noun,
                    const std::string& unit, int minSide) {
  cmd->add_option("--width", width, noun + " width in " + unit)
      ->check(wholeIn(minSide, kMaxImageSide))
      ->capture_default_str();
  cmd->add_option("--height", height, noun + " height in " + unit)
      ->check(wholeIn(minSide, kMaxImageSide))
      ->capture_default_str();
}

CLI::Option* addThreadsOption(CLI::App* cmd, int& threads) {
  return cmd->add_option("--threads", threads, "Worker threads (0 = all cores)")
      ->check(wholeIn(0, 1024));
}

}  // namespace lo::tool
