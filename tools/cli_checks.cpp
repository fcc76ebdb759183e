#include "cli_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "bake/bake.h"
#include "distributed/tiled_bake.h"

namespace lo::tool {

CLI::Validator vdlCountValidator() {
  return CLI::Validator([](std::string& s) { return vdlCountError(s); },
                        "1.." + std::to_string(kMaxVdls) + "|auto", "VdlCount");
}

CLI::Validator depthValidator() { return CLI::Range(1, kMaxGridDepth); }

CLI::Validator seedValidator() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        const std::string max = "18446744073709551615";
        const bool digits = !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
        std::string trimmed = s.substr(std::min(s.find_first_not_of('0'), s.size()));
        if (trimmed.empty()) trimmed = "0";
        if (!digits || trimmed.size() > max.size() ||
            (trimmed.size() == max.size() && trimmed > max)) {
          return "must be a whole number from 0 to " + max + ", got '" + s + "'";
        }
        return {};
      },
      "0..2^64-1", "Seed");
}

CLI::Validator tilesValidator() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        if (s == "auto") return {};
        const bool digits = !s.empty() && s.size() <= 3 &&
                            s.find_first_not_of("0123456789") == std::string::npos;
        const int n = digits ? std::stoi(s) : 0;
        if (n < 1 || n > kMaxTilesPerAxis || (n & (n - 1)) != 0) {
          return "must be 'auto' or a power of two from 1 to " + std::to_string(kMaxTilesPerAxis) +
                 " (tiles per axis), got '" + s + "'";
        }
        return {};
      },
      "auto|1,2,4,..", "Tiles");
}

CLI::Validator finitePositive() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (end == s.c_str() || *end != '\0' || !std::isfinite(v) || !(v > 0)) {
          return "must be a finite number > 0, got '" + s + "'";
        }
        return {};
      },
      "NUMBER > 0", "FinitePositive");
}

}  // namespace lo::tool
