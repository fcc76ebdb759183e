#pragma once
/// @file core/fnv.h
/// @brief FNV-1a, 64 bits: the one hash of bytes the project writes into
/// names and files (a scene's content hash, a temporary name's tail, the
/// fingerprint distributed ranks compare). Not for security: a change of
/// input shows as a change of hash.

#include <cstddef>
#include <cstdint>

namespace lo {

class Fnv1a64 {
 public:
  /// Folds `size` bytes at `data` into the hash, in order.
  void bytes(const void* data, size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) hash_ = (hash_ ^ p[i]) * 1099511628211ull;
  }
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 1469598103934665603ull;
};

}  // namespace lo
