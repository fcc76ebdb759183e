#pragma once
/// @file core/number_range.h
/// @brief The one check of a number a user gives: a command-line flag
/// (tools/cli_checks.h's numberIn) and an argument of the Python module go
/// through it alike, so that both take the same values and word a refusal
/// the same way. A number is finite first: NaN passes every comparison-only
/// range check (each comparison with it is false), and an infinity passes
/// an open one.

#include <limits>
#include <string>

namespace lo {

/// @brief The values a numeric setting takes: finite, and within [min, max]
/// ((min, max] when `aboveMin`: a length or a scale that must be > 0), a
/// whole number when `whole`.
struct NumberRange {
  double min = -std::numeric_limits<double>::max();
  double max = std::numeric_limits<double>::max();
  bool aboveMin = false;
  bool whole = false;

  /// Whether `value` is one of the range's values (NaN and infinities never are).
  bool contains(double value) const;
  /// The bounds alone: "from 0.001 to 1", "> 0", "" for any finite number.
  std::string boundsText() const;
  /// What the range takes, for a message: "a finite number", "a finite
  /// number > 0", "a finite number from 0.001 to 1", "a whole number from 1 to 12".
  std::string ToString() const;
};

/// Any finite number.
constexpr NumberRange kFiniteNumber{};
/// A finite number > 0 (a length, a scale, a speed).
constexpr NumberRange kPositiveNumber{0.0, std::numeric_limits<double>::max(), true};

/// @brief "" when `range` contains `value`, else the refusal without a name:
/// "must be a finite number from 0.001 to 1, got nan".
std::string numberRangeError(double value, const NumberRange& range);

/// @brief `value` when `range` contains it.
/// @throws InputError "<name>: must be <range>, got <value>" otherwise.
double checkNumber(double value, const NumberRange& range, const std::string& name);

}  // namespace lo
