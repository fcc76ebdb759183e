#pragma once
/// @file octree/octree_level_source.h
/// @brief Where finer octree levels come from while a window is open: the
/// seam between a producer of octrees (the progressive bake, bake/) and the
/// viewer that draws them (render/viewer.h), so that neither stage links the
/// other.

#include <string>

#include "octree/gpu_octree.h"

namespace lo {

class OctreeLevelSource {
 public:
  virtual ~OctreeLevelSource() = default;
  /// The newest finished level since the last call, if any: its octree
  /// (moved out) and its depth. @throws the source's failure, once.
  virtual bool takeNewest(GpuOctree& octree, int& depth) = 0;
  /// A line for the terminal once the level taken last is on screen.
  virtual std::string shownReport() const = 0;
  /// True when no further level will come.
  virtual bool finished() const = 0;
  /// What the source is doing, for the window title.
  virtual std::string status() const = 0;
};

}  // namespace lo
