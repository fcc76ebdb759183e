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

/// `--seed`: decimal digits only, at most 2^64 - 1: "-1", "1e23" or a number
/// beyond 64 bits would otherwise wrap to some other seed without a word.
CLI::Validator seedValidator();
/// `bake --tiles`: "auto" or a power of two up to kMaxTilesPerAxis.
CLI::Validator tilesValidator();

/// A finite number > 0 ("nan" and "inf" refused, unlike CLI::PositiveNumber).
CLI::Validator finitePositive();

}  // namespace lo::tool
