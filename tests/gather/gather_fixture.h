#pragma once
/// @file tests/gather/gather_fixture.h
/// @brief What the gather's tests set up again and again: small scenes,
/// photons spread over them, and the surface grid they are splatted into.

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "gather/gather.h"
#include "scene/scene.h"

namespace lo::test {

/// The unit floor: the quad [0, 1] x {0} x [0, 1] facing up (oneMaterialScene).
Scene unitFloor();

/// A Cornell-like room: the closed unit box (inward faces) with two blocks
/// standing on the floor (outward faces, no bottom face), placed off the voxel
/// grid's planes.
Scene cornellLikeBox();

/// `count` photons spread uniformly (by area) over the scene's triangles, each
/// arriving on the side its triangle faces; power 1/count per channel.
std::vector<Photon> uniformPhotons(const Scene& scene, size_t count, uint64_t seed);

/// The surface grid of `scene` at `depth` with `photons` splatted into it
/// (expects none to miss the grid).
SurfaceGrid gridFor(const Scene& scene, int depth, const std::vector<Photon>& photons);

/// `v` in increasing order: gathered photon sets compared as sets.
std::vector<uint32_t> sorted(std::vector<uint32_t> v);

/// The fixture of the gather's tests: the scene a test sets, the photons on
/// it and the surface grid they are splatted into.
class GatherTest : public ::testing::Test {
 protected:
  /// `count` photons spread over `scene` (uniformPhotons with `seed`) and
  /// its grid at `depth` with them.
  void spreadPhotons(size_t count, uint64_t seed, int depth);
  Scene scene;
  std::vector<Photon> photons;
  SurfaceGrid grid;
};

/// The suites of the gather's tests.
using Gather = GatherTest;
using GatherLayers = GatherTest;

}  // namespace lo::test
