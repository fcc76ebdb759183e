#include "cli_checks.h"

#include "bake/bake.h"

namespace lo::tool {

CLI::Validator vdlCountValidator() {
  return CLI::Validator([](std::string& s) { return vdlCountError(s); },
                        "1.." + std::to_string(kMaxVdls) + "|auto", "VdlCount");
}

CLI::Validator depthValidator() { return CLI::Range(1, kMaxGridDepth); }

}  // namespace lo::tool
