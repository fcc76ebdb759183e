#include "picture_options.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"
#include "core/file.h"

namespace lo::tool {

ToneParams PictureOptions::toneParams() const {
  ToneParams p;
  p.curve = parseToneMap(toneMap);
  if (exposure == "auto") {
    p.autoExposure = true;
    return p;
  }
  char* end = nullptr;
  const double ev = std::strtod(exposure.c_str(), &end);
  // strtod reads hexadecimal too ("0x1"), which no flag takes (cli_checks.h).
  if (exposure.empty() || end != exposure.c_str() + exposure.size() || !std::isfinite(ev) ||
      ev < -30.0 || ev > 30.0 || exposure.find_first_of("xX") != std::string::npos) {
    throw InputError("--exposure: '" + exposure + "' is neither auto nor a number of EV in -30..30");
  }
  p.autoExposure = false;
  p.exposureEv = float(ev);
  return p;
}

void addPictureOptions(CLI::App* cmd, PictureOptions& opt) {
  cmd->add_option("--exposure", opt.exposure,
                  "PNG exposure: auto (the image's log-average luminance to middle grey, its "
                  "brightest 1% held near white) or a fixed EV (radiance * 2^EV); the EXR is "
                  "radiance either way")
      ->capture_default_str();
  cmd->add_option("--tone-map", opt.toneMap,
                  "PNG tone curve after the exposure: neutral (Khronos PBR Neutral: base colours "
                  "kept, highlights rolled off below white) or clamp (each channel cut at 1)")
      ->check(CLI::IsMember({"neutral", "clamp"}))
      ->capture_default_str();
}

void printPicture(const std::string& output, const ToneReport& tone, bool quiet) {
  if (!quiet && hasExtension(output, ".png")) std::printf("picture: %s\n", tone.ToString().c_str());
}

}  // namespace lo::tool
