#pragma once
/// @file lightmap/atlas_pack.h
/// @brief Internal to src/lightmap: rectangles packed into square pages with
/// stb_rect_pack (skyline, bottom-left). Deterministic: rectangles of equal
/// size keep their input order, whatever the C library's qsort does.

#include <cstddef>
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
///
/// A page is offered the rectangles in the packer's order (tallest first,
/// then widest, then by index) up to kPackOfferPages pages' worth of area,
/// those it leaves go on to the next page: each rectangle is offered about
/// once, whatever the page count (offering every page all that remained was
/// pages x rectangles: a million charts on many pages did not finish). While
/// the rectangles' area is within kPackOfferPages pages, every page is
/// offered all that remain, as it always was. `offered`, when given, has the
/// rectangles handed to the packer over all pages added to it.
int packRects(const std::vector<RectSize>& rects, int pageSize, int maxPages,
              std::vector<RectPlacement>& placement, size_t* offered = nullptr);

/// Pages' worth of area a page is offered (packRects).
constexpr double kPackOfferPages = 2.0;

}  // namespace lo::lightmap_internal
