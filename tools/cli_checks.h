#pragma once
/// @file tools/cli_checks.h
/// @brief CLI11 validators the commands share, each a thin wrapper of the
/// library's own check, so a flag and the library accept the same values.

#include <CLI/CLI.hpp>
#include <string>

namespace lo::tool {

/// `--vdls`: 1..kMaxVdls or "auto" (lo::vdlCountError).
CLI::Validator vdlCountValidator();

/// `--depth`: 1..kMaxGridDepth.
CLI::Validator depthValidator();

}  // namespace lo::tool
