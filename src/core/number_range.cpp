#include "core/number_range.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"

namespace lo {

namespace {

/// The shortest text that reads back as `v` ("0.001", "1e-09"), whole
/// numbers below 1e15 in full ("200000000", not "2e+08").
std::string shortest(double v) {
  char text[32];
  if (v == std::floor(v) && std::fabs(v) < 1e15) {
    std::snprintf(text, sizeof text, "%.0f", v);
    return text;
  }
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    if (std::strtod(text, nullptr) == v) break;
  }
  return text;
}

}  // namespace

bool NumberRange::contains(double value) const {
  if (!std::isfinite(value)) return false;
  if (whole && value != std::floor(value)) return false;
  return (aboveMin ? value > min : value >= min) && value <= max;
}

std::string NumberRange::boundsText() const {
  const bool lowest = min <= -std::numeric_limits<double>::max();
  const bool highest = max >= std::numeric_limits<double>::max();
  if (lowest && highest) return {};
  if (highest) return (aboveMin ? "> " : ">= ") + shortest(min);
  if (lowest) return "<= " + shortest(max);
  if (aboveMin) return "> " + shortest(min) + " and <= " + shortest(max);
  return "from " + shortest(min) + " to " + shortest(max);
}

std::string NumberRange::ToString() const {
  const std::string bounds = boundsText();
  return std::string(whole ? "a whole number" : "a finite number") +
         (bounds.empty() ? "" : " " + bounds);
}

std::string numberRangeError(double value, const NumberRange& range) {
  if (range.contains(value)) return {};
  return "must be " + range.ToString() + ", got " + shortest(value);
}

double checkNumber(double value, const NumberRange& range, const std::string& name) {
  const std::string error = numberRangeError(value, range);
  if (!error.empty()) throw InputError(name + ": " + error);
  return value;
}

}  // namespace lo
