#pragma once
/// @file cluster/kmeans_internal.h
/// @brief Private to src/cluster and its tests: the Lloyd refinement behind
/// clusterDirections, callable from chosen initial centres so that tests can
/// build situations k-means++ never produces (an empty cluster).

#include <cstddef>

#include "cluster/vdl_cluster.h"

namespace lo::kmeans_internal {

/// Lloyd iterations from `centres[0..k)` (unit vectors), then the same
/// finalisation as clusterDirections (VDL sums, empty clusters dropped, sort,
/// angular error). k in [1, kMaxVdls].
ClusterResult clusterFromCentres(const DirectionSample* samples, size_t n, const Vec3* centres,
                                 int k, int maxIterations);

}  // namespace lo::kmeans_internal
