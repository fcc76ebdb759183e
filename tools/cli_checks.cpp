#include "cli_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "bake/bake.h"
#include "core/file.h"
#include "distributed/tiled_bake.h"

namespace lo::tool {

CLI::Validator existingFile() {
  return CLI::Validator([](std::string& path) { return inputFileProblem(path); }, "FILE");
}

CLI::Validator vdlCountValidator() {
  return CLI::Validator([](std::string& s) { return vdlCountError(s); },
                        "1.." + std::to_string(kMaxVdls) + "|auto", "VdlCount");
}

CLI::Validator depthValidator() { return numberIn(kDepthRange); }

CLI::Validator autoDepthValidator() {
  return CLI::Validator([](std::string& s) { return depthError(s); },
                        "1.." + std::to_string(kMaxGridDepth) + "|auto", "Depth");
}

CLI::Validator numberIn(const NumberRange& range) {
  // The help's type after the option's own: "FLOAT:from 0.001 to 1", "INT:from 1 to 12".
  const std::string description = range.boundsText();
  return CLI::Validator(
      [range](std::string& s) -> std::string {
        // strtod reads hexadecimal ("0x10", "0x1p3"), which no flag's help
        // or document offers: numbers are written in decimal, on every flag.
        if (s.find_first_of("xX") != std::string::npos) {
          return "must be " + range.ToString() + ", in decimal digits, got '" + s + "'";
        }
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (s.empty() || end != s.c_str() + s.size() || !range.contains(v)) {
          return "must be " + range.ToString() + ", got '" + s + "'";
        }
        // The tools compute in single precision: 1e-308 became 0 and 1e308
        // infinity after the parse, refused later quoting a value never typed.
        const double size = std::fabs(v);
        if (v != 0 && !(size >= double(std::numeric_limits<float>::min()) &&
                        size <= double(std::numeric_limits<float>::max()))) {
          return "must be " + range.ToString() + " and 0 or of a size single precision holds " +
                 "(1.2e-38 to 3.4e38), got '" + s + "'";
        }
        return {};
      },
      description, "Number");
}

CLI::Validator wholeIn(double min, double max) {
  return numberIn(NumberRange{min, max, false, true});
}

std::string decimalWholeError(std::string& s) {
  const size_t sign = !s.empty() && (s[0] == '-' || s[0] == '+') ? 1 : 0;
  if (s.size() == sign || s.find_first_not_of("0123456789", sign) != std::string::npos) {
    return "must be a whole number in decimal digits (100000, not 1e5, 1.0 or 0x10), got '" + s +
           "'";
  }
  // The parser converts with strtoll(s, 0): "010" was octal 8 and "08" no
  // number at all. Without its leading zeros, "010" is read as ten.
  const size_t first = std::min(s.find_first_not_of('0', sign), s.size() - 1);
  s = s.substr(0, sign) + s.substr(first);
  return {};
}

void requireNumberRules(CLI::App& app) {
  CLI::Validator finite = numberIn(kFiniteNumber);
  finite.description("");  // the option's help says FLOAT already
  CLI::Validator decimal(decimalWholeError, "", "DecimalWhole");
  for (CLI::Option* option : app.get_options()) {
    // CLI11 names a float, a double and a vector of them FLOAT; a signed
    // integer INT, an unsigned one UINT. The decimal rule goes first, as a
    // transform (a check may not change the value): the option's own checks
    // (a range, a set) and the conversion then see "010" as "10".
    const std::string type = option->get_type_name();
    if (type.rfind("FLOAT", 0) == 0) option->check(finite);
    if (type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0) option->transform(decimal);
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    requireNumberRules(*sub);
  }
}

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

}  // namespace lo::tool
