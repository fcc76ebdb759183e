#pragma once
/// @file tools/command_options.h
/// @brief Arguments and flags several commands register alike: the LIGHTS
/// argument, the image size and --threads. One registration each, so that
/// the commands word and check them the same way.

#include <string>

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace lo::tool {

/// Registers the LIGHTS argument (an existing .vdb from `bake`) on `cmd`,
/// `note` appended to its help; the caller says whether it is required.
CLI::Option* addLightsArgument(CLI::App* cmd, std::string& lights, const std::string& note = "");

/// Registers --width and --height ("<noun> width in <unit>"), each from
/// `minSide` to kMaxImageSide (image/image.h), their defaults shown.
void addSizeOptions(CLI::App* cmd, int& width, int& height, const std::string& noun = "Image",
                    const std::string& unit = "pixels", int minSide = 1);

/// Registers --threads (0 = all cores, core/threads.h's ThreadLimit); the
/// caller says whether its default is shown.
CLI::Option* addThreadsOption(CLI::App* cmd, int& threads);

}  // namespace lo::tool
