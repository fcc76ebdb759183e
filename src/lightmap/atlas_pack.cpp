#include "lightmap/atlas_pack.h"

#include <stb/stb_rect_pack.h>

#include <algorithm>
#include <cstddef>

namespace {

// stb_rect_pack sorts with qsort, which is not stable: rectangles of equal
// size could come out in a different order on another C library. A stable
// sort keeps them in input order, so the packing is the same everywhere.
void stableSortRects(void* base, size_t count, size_t size,
                     int (*compare)(const void*, const void*)) {
  (void)size;
  auto* rects = static_cast<stbrp_rect*>(base);
  std::stable_sort(rects, rects + count, [compare](const stbrp_rect& a, const stbrp_rect& b) {
    return compare(&a, &b) < 0;
  });
}

}  // namespace

#define STBRP_SORT stableSortRects
#define STB_RECT_PACK_IMPLEMENTATION
#include <stb/stb_rect_pack.h>

namespace lo::lightmap_internal {

int packRects(const std::vector<RectSize>& rects, int pageSize, int maxPages,
              std::vector<RectPlacement>& placement) {
  placement.assign(rects.size(), RectPlacement{});
  std::vector<int> remaining(rects.size());
  for (size_t i = 0; i < rects.size(); ++i) remaining[i] = int(i);
  // Enough skyline nodes (one per texel column) for the unquantised packer.
  std::vector<stbrp_node> nodes(size_t(std::max(pageSize, 1)));
  int pages = 0;
  while (!remaining.empty()) {
    if (pages == maxPages) return -1;
    std::vector<stbrp_rect> batch(remaining.size());
    for (size_t i = 0; i < remaining.size(); ++i) {
      const RectSize& r = rects[size_t(remaining[i])];
      batch[i] = stbrp_rect{remaining[i], r.w, r.h, 0, 0, 0};
    }
    stbrp_context context;
    stbrp_init_target(&context, pageSize, pageSize, nodes.data(), int(nodes.size()));
    stbrp_pack_rects(&context, batch.data(), int(batch.size()));
    std::vector<int> left;
    for (const stbrp_rect& r : batch) {
      if (r.was_packed) {
        placement[size_t(r.id)] = RectPlacement{pages, r.x, r.y};
      } else {
        left.push_back(r.id);
      }
    }
    if (left.size() == remaining.size()) return -1;  // a rectangle larger than a page
    remaining.swap(left);
    ++pages;
  }
  return pages;
}

}  // namespace lo::lightmap_internal
