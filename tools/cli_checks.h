#pragma once
/// @file tools/cli_checks.h
/// @brief CLI11 validators the commands share, each a thin wrapper of the
/// library's own check, so a flag and the library accept the same values.

#include <CLI/CLI.hpp>
#include <string>

#include "core/number_range.h"

namespace lo::tool {

/// An input file that exists and is a file, or why not: CLI::ExistingFile
/// said "File does not exist" of a loop of symbolic links, one to nothing
/// and one that cannot be reached (H14-2-1).
CLI::Validator existingFile();

/// `--vdls`: 1..kMaxVdls or "auto" (lo::vdlCountError).
CLI::Validator vdlCountValidator();

/// `--depth`: 1..kMaxGridDepth (kDepthRange, as the bake and the Python module).
CLI::Validator depthValidator();
/// --depth of bake: a depth or auto (bake.h, parseDepth).
CLI::Validator autoDepthValidator();

/// A number within `range` (core/number_range.h, the check the Python module
/// applies to its arguments): finite first, so NaN and infinities are
/// refused where CLI::Range and CLI::PositiveNumber let NaN through.
/// "--fov: must be a finite number from 1 to 179, got 'nan'".
CLI::Validator numberIn(const NumberRange& range);
/// numberIn of the whole numbers from `min` to `max`.
CLI::Validator wholeIn(double min, double max);

/// The rule of every numeric flag of `app` and its subcommands, whatever its
/// own check: a floating-point one gets the finite check
/// (numberIn(kFiniteNumber)), so a flag registered without a range still
/// refuses NaN and infinities; a whole-number one (INT, UINT) takes decimal
/// digits alone, leading zeros read as decimal ("010" is ten, not octal 8;
/// "0x10" refused; decimalWholeError). Called once, after every command has
/// registered its flags.
void requireNumberRules(CLI::App& app);
/// "" when `s` is an optional sign and decimal digits, which it rewrites
/// without their leading zeros; else why not.
std::string decimalWholeError(std::string& s);

/// `--seed`: decimal digits only, at most 2^64 - 1: "-1", "1e23" or a number
/// beyond 64 bits would otherwise wrap to some other seed without a word.
CLI::Validator seedValidator();
/// `bake --tiles`: "auto" or a power of two up to kMaxTilesPerAxis.
CLI::Validator tilesValidator();

}  // namespace lo::tool
