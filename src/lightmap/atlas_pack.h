#pragma once
/// @file lightmap/atlas_pack.h
/// @brief Internal to src/lightmap: rectangles packed into square pages with
/// stb_rect_pack (skyline, bottom-left). Deterministic: rectangles of equal
/// size keep their input order, whatever the C library's qsort does.

#include <vector>

namespace lo::lightmap_internal {

struct RectSize {
  int w = 0, h = 0;  ///< texels, > 0
};

struct RectPlacement {
  int page = -1;     ///< -1 = not placed
  int x = 0, y = 0;  ///< lower-left corner in the page, texels
};

/// @brief Packs the rectangles into pages of pageSize^2, filling page 0 first,
/// then page 1 with what did not fit, and so on. Returns the number of pages
/// used, or -1 when rectangles remain after maxPages pages or a rectangle is
/// larger than a page (placement then holds what was placed).
int packRects(const std::vector<RectSize>& rects, int pageSize, int maxPages,
              std::vector<RectPlacement>& placement);

}  // namespace lo::lightmap_internal
