#pragma once
/// @file core/error.h
/// @brief Typed exceptions and invariant checks.
///
/// Bad input (a file, a value, a CLI flag) raises InputError whose message names
/// the file or flag and what was wrong. Failed reads/writes raise IoError. A
/// broken internal invariant is an InternalError from LO_CHECK*, which prints
/// both sides. The CLI catches all three, prints the message, exits non-zero.

#include <sstream>
#include <stdexcept>
#include <string>

namespace lo {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

namespace detail {
template <typename A, typename B>
[[noreturn]] void failCheck(const char* expr, const A& a, const B& b, const char* file, int line) {
  std::ostringstream os;
  os << file << ":" << line << ": check failed: " << expr << " (" << a << " vs " << b << ")";
  throw InternalError(os.str());
}
[[noreturn]] inline void failCheck(const char* expr, const char* file, int line) {
  std::ostringstream os;
  os << file << ":" << line << ": check failed: " << expr;
  throw InternalError(os.str());
}
}  // namespace detail

}  // namespace lo

#define LO_CHECK(cond) \
  do { if (!(cond)) ::lo::detail::failCheck(#cond, __FILE__, __LINE__); } while (0)
#define LO_CHECK_OP(a, op, b)                                                        \
  do {                                                                               \
    const auto& lo_a_ = (a);                                                         \
    const auto& lo_b_ = (b);                                                         \
    if (!(lo_a_ op lo_b_)) ::lo::detail::failCheck(#a " " #op " " #b, lo_a_, lo_b_, __FILE__, __LINE__); \
  } while (0)
#define LO_CHECK_EQ(a, b) LO_CHECK_OP(a, ==, b)
#define LO_CHECK_LE(a, b) LO_CHECK_OP(a, <=, b)
#define LO_CHECK_LT(a, b) LO_CHECK_OP(a, <, b)
