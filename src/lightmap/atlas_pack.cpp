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
              std::vector<RectPlacement>& placement, size_t* offered) {
  placement.assign(rects.size(), RectPlacement{});
  // The packer's own order (stb_rect_pack sorts each batch so, stably), once.
  std::vector<int> remaining(rects.size());
  for (size_t i = 0; i < rects.size(); ++i) remaining[i] = int(i);
  std::stable_sort(remaining.begin(), remaining.end(), [&](int a, int b) {
    const RectSize& p = rects[size_t(a)];
    const RectSize& q = rects[size_t(b)];
    return p.h != q.h ? p.h > q.h : p.w > q.w;
  });
  // Enough skyline nodes (one per texel column) for the unquantised packer.
  std::vector<stbrp_node> nodes(size_t(std::max(pageSize, 1)));
  const double offer = kPackOfferPages * double(pageSize) * double(pageSize);
  int pages = 0;
  std::vector<stbrp_rect> batch;
  std::vector<int> left;
  while (!remaining.empty()) {
    if (pages == maxPages) return -1;
    size_t take = 0;
    double area = 0;
    while (take < remaining.size()) {
      const RectSize& r = rects[size_t(remaining[take])];
      const double a = double(r.w) * double(r.h);
      if (take > 0 && area + a > offer) break;
      area += a;
      ++take;
    }
    batch.resize(take);
    for (size_t i = 0; i < take; ++i) {
      const RectSize& r = rects[size_t(remaining[i])];
      batch[i] = stbrp_rect{remaining[i], r.w, r.h, 0, 0, 0};
    }
    if (offered) *offered += take;
    stbrp_context context;
    stbrp_init_target(&context, pageSize, pageSize, nodes.data(), int(nodes.size()));
    stbrp_pack_rects(&context, batch.data(), int(batch.size()));
    left.clear();
    for (const stbrp_rect& r : batch) {
      if (r.was_packed) {
        placement[size_t(r.id)] = RectPlacement{pages, r.x, r.y};
      } else {
        left.push_back(r.id);
      }
    }
    if (left.size() == take) return -1;  // a rectangle larger than a page
    left.insert(left.end(), remaining.begin() + ptrdiff_t(take), remaining.end());
    remaining.swap(left);
    ++pages;
  }
  return pages;
}

}  // namespace lo::lightmap_internal
