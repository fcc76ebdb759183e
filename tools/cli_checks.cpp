#include "cli_checks.h"

#include <sstream>

#include "bake/bake.h"

namespace lo::tool {

CLI::Validator vdlCountValidator() {
  return CLI::Validator([](std::string& s) { return vdlCountError(s); },
                        "1.." + std::to_string(kMaxVdls) + "|auto", "VdlCount");
}

CLI::Validator depthValidator() { return CLI::Range(1, kMaxGridDepth); }

std::string numberText(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

}  // namespace lo::tool
