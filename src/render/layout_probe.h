#pragma once
/// @file render/layout_probe.h
/// @brief Runs the GLSL build of shaders/octree_layout.h on inputs, so a test
/// can check that the shaders and the C++ build of the header agree (the
/// NanoVDB practice). Needs a current GlContext.

#include <array>
#include <vector>

namespace lo {

enum class LayoutProbe {
  /// in: (x, y, z, packed) -> (loPackDirection(x,y,z), loPackedTheta(packed), loPackedPhi(packed),
  /// 0)
  PackDirection = 0,
  /// in: (packed, -, -, -) -> (loUnpackDirectionX/Y/Z(packed), loPackDirection of that)
  UnpackDirection = 1,
  /// in: (r, g, b, index) -> (loUnpackAddress(r,g,b), R + 256 G of its repacking,
  ///                          loVdlTexelX(index), loVdlTexelY(index))
  Address = 2,
};

/// One fragment per input, into an RGBA32F target; returns the outputs in order.
std::vector<std::array<float, 4>> runLayoutProbe(LayoutProbe function,
                                                 const std::vector<std::array<float, 4>>& inputs);

}  // namespace lo
