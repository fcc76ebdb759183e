#pragma once
/// @file tools/picture_options.h
/// @brief How `render` and `reference` turn radiance into a PNG a person can
/// look at: --exposure auto|EV and --tone-map neutral|clamp (image/tonemap.h).
/// The EXR output stays linear radiance whatever they say.

#include <string>

#include "image/tonemap.h"

namespace CLI {
class App;
}

namespace lo::tool {

struct PictureOptions {
  std::string exposure = "auto";  ///< "auto" or a number of EV
  std::string toneMap = toString(ToneParams{}.curve);

  /// @throws InputError naming --exposure (not "auto" nor a finite number in
  /// -30..30) or --tone-map.
  ToneParams toneParams() const;
};

/// Registers --exposure and --tone-map on `cmd`.
void addPictureOptions(CLI::App* cmd, PictureOptions& opt);

/// "picture: ..." (how the PNG was exposed, what share clips) on stdout when
/// `output` is a PNG, unless `quiet`.
void printPicture(const std::string& output, const ToneReport& tone, bool quiet);

}  // namespace lo::tool
