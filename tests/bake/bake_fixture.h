#pragma once
/// @file tests/bake/bake_fixture.h
/// @brief The parameters of the small bakes that the tests of the bake, and of
/// the stages that read its output, run.

#include <cstddef>

#include "bake/bake.h"

namespace lo::test {

/// A bake at `depth` storing `photons`, gathering `knn` photons per voxel;
/// every other parameter at its default.
inline BakeParams smallBake(int depth, size_t photons, int knn = BakeParams{}.knn) {
  BakeParams p;
  p.depth = depth;
  p.photons = photons;
  p.knn = knn;
  return p;
}

}  // namespace lo::test
