// libFuzzer target: the .vdb reader as every command uses it (readVdlGrid:
// the trial read in a child process, then the read and the checks of the
// file's meaning) and `inspect`. OpenVDB's own parsing runs in the child,
// whose crashes are refusals, not findings: what is fuzzed is that nothing a
// file holds takes down the command.

#include "core/error.h"
#include "fuzz_input.h"
#include "vdb/vdb_inspect.h"
#include "vdb/vdb_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = lo::fuzz::inputPath(".vdb");
  lo::fuzz::writeInput(path, data, size);
  try {
    lo::readVdlGrid(path);
  } catch (const lo::InputError&) {
  }
  try {
    lo::inspectVdb(path);
  } catch (const lo::InputError&) {
  }
  return 0;
}
