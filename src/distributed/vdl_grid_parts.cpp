// selectVoxels, serializeVdlGrid and mergeVdlGrids: every per-voxel and
// per-layer array of a VdlGrid is moved by walking the light grid's field
// table (lightgrid/light_grid_schema.h), so a field added there is split,
// sent and merged without a change here.

#include "distributed/vdl_grid_parts.h"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <string>
#include <type_traits>

#include "core/error.h"
#include "lightgrid/light_grid_schema.h"

namespace lo {

namespace distributed_internal {

/// out = the runs of `per` values at each index of `order`, appended.
template <typename T>
void gatherRuns(const std::vector<T>& in, size_t per, const std::vector<size_t>& order,
                std::vector<T>& out) {
  out.clear();
  out.reserve(order.size() * per);
  for (size_t i : order)
    out.insert(out.end(), in.begin() + std::ptrdiff_t(i * per),
               in.begin() + std::ptrdiff_t((i + 1) * per));
}

/// The grid's arrays reordered: voxel i of the result is `voxels[i]`, its
/// layers those of `layers` (indices into g.layers) with voxel indices
/// `layerVoxel`.
VdlGrid reorder(const VdlGrid& g, const std::vector<size_t>& voxels,
                const std::vector<size_t>& layers, std::vector<uint32_t> layerVoxel) {
  VdlGrid out;
  out.frame = g.frame;
  out.maxVdls = g.maxVdls;
  out.shTerms = g.shTerms;
  gatherRuns(g.coords, 1, voxels, out.coords);
  forEachField([&](const auto& row) {
    gatherRuns(g.*row.voxels, valuesPerVoxel(g, row), voxels, out.*row.voxels);
    if (row.layers) {
      gatherRuns(g.layers.*row.layers, valuesPerLayer(g, row), layers, out.layers.*row.layers);
    }
  });
  out.layers.voxel = std::move(layerVoxel);
  return out;
}

/// Appends / reads plain arrays with their lengths.
struct Writer {
  std::vector<char> bytes;
  template <typename T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    const char* p = reinterpret_cast<const char*>(&value);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  template <typename T>
  void putArray(const std::vector<T>& values, size_t) {
    put(uint64_t(values.size()));
    const char* p = reinterpret_cast<const char*>(values.data());
    bytes.insert(bytes.end(), p, p + values.size() * sizeof(T));
  }
};

struct Reader {
  const std::vector<char>& bytes;
  size_t at = 0;
  void need(size_t n) const {
    if (n > bytes.size() - at) {
      throw IoError("a light grid part of " + std::to_string(bytes.size()) +
                    " bytes ends early (at byte " + std::to_string(at) + ")");
    }
  }
  template <typename T>
  T get() {
    need(sizeof(T));
    T value;
    std::memcpy(&value, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return value;
  }
  template <typename T>
  void getArray(std::vector<T>& values, size_t) {
    const uint64_t n = get<uint64_t>();
    if (n > (bytes.size() - at) / sizeof(T)) {
      throw IoError("a light grid part's array of " + std::to_string(n) +
                    " values runs past its end");
    }
    values.resize(size_t(n));
    if (n > 0) std::memcpy(values.data(), bytes.data() + at, size_t(n) * sizeof(T));
    at += size_t(n) * sizeof(T);
  }
};

constexpr uint64_t kPartMagic = 0x4c4f50415254ull;  // "LOPART"

}  // namespace distributed_internal

VdlGrid selectVoxels(const VdlGrid& grid, const std::vector<uint32_t>& voxels) {
  using namespace distributed_internal;
  std::vector<size_t> order(voxels.begin(), voxels.end());
  std::vector<uint32_t> newIndex(grid.size(), UINT32_MAX);
  for (size_t i = 0; i < order.size(); ++i) {
    LO_CHECK_LT(order[i], grid.size());
    if (i > 0) LO_CHECK_LT(order[i - 1], order[i]);
    newIndex[order[i]] = uint32_t(i);
  }
  std::vector<size_t> layers;
  std::vector<uint32_t> layerVoxel;
  for (size_t e = 0; e < grid.layers.size(); ++e) {
    const uint32_t v = newIndex[grid.layers.voxel[e]];
    if (v == UINT32_MAX) continue;
    layers.push_back(e);
    layerVoxel.push_back(v);
  }
  return reorder(grid, order, layers, std::move(layerVoxel));
}

std::vector<char> serializeVdlGrid(const VdlGrid& grid) {
  using namespace distributed_internal;
  Writer w;
  w.put(kPartMagic);
  w.put(grid.frame);
  w.put(int32_t(grid.maxVdls));
  w.put(int32_t(grid.shTerms));
  auto put = [&](const auto& array, size_t per) { w.putArray(array, per); };
  forEachVoxelArray(grid, put);
  w.putArray(grid.layers.voxel, 1);
  forEachLayerArray(grid, put);
  return std::move(w.bytes);
}

VdlGrid deserializeVdlGrid(const std::vector<char>& bytes) {
  using namespace distributed_internal;
  Reader r{bytes};
  if (r.get<uint64_t>() != kPartMagic) throw IoError("not a light grid part");
  VdlGrid g;
  g.frame = r.get<GridFrame>();
  g.maxVdls = r.get<int32_t>();
  g.shTerms = r.get<int32_t>();
  auto get = [&](auto& array, size_t per) { r.getArray(array, per); };
  forEachVoxelArray(g, get);
  r.getArray(g.layers.voxel, 1);
  forEachLayerArray(g, get);
  if (r.at != bytes.size()) throw IoError("a light grid part has bytes after its end");
  // Every array's length agrees with the voxel and layer counts.
  const size_t n = g.size(), m = g.layers.size();
  bool ok = g.maxVdls >= 1 && g.maxVdls <= kMaxVdls && g.shTerms >= 0 && g.shTerms <= 9;
  if (ok) {
    forEachVoxelArray(
        g, [&](const auto& a, size_t per) { ok = ok && (per == 0 || a.size() == n * per); });
    forEachLayerArray(g, [&](const auto& a, size_t per) { ok = ok && a.size() == m * per; });
    for (uint32_t v : g.layers.voxel) ok = ok && v < n;
  }
  if (!ok) throw IoError("a light grid part's arrays disagree in length");
  return g;
}

VdlGrid mergeVdlGrids(std::vector<VdlGrid> parts) {
  using namespace distributed_internal;
  if (parts.empty()) return VdlGrid{};
  // Concatenated, then sorted by canonical key.
  VdlGrid all;
  all.frame = parts[0].frame;
  all.maxVdls = parts[0].maxVdls;
  all.shTerms = parts[0].shTerms;
  bool points = false;
  for (const VdlGrid& p : parts) points = points || !p.points.empty();
  for (VdlGrid& p : parts) {
    if (p.maxVdls != all.maxVdls || p.shTerms != all.shTerms ||
        !(p.frame.origin == all.frame.origin) || p.frame.voxelSize != all.frame.voxelSize ||
        p.frame.depth != all.frame.depth) {
      throw IoError("light grid parts of different frames or payloads cannot be merged");
    }
    if (points && p.points.empty() && p.size() > 0) {
      throw IoError("light grid parts disagree on surface points");
    }
    const uint32_t offset = uint32_t(all.size());
    auto append = [](auto& dst, auto& src) { dst.insert(dst.end(), src.begin(), src.end()); };
    append(all.coords, p.coords);
    forEachField([&](const auto& row) {
      append(all.*row.voxels, p.*row.voxels);
      if (row.layers) append(all.layers.*row.layers, p.layers.*row.layers);
    });
    for (uint32_t v : p.layers.voxel) all.layers.voxel.push_back(v + offset);
    p = VdlGrid{};  // frees the part
  }
  std::vector<uint64_t> keys(all.size());
  for (size_t v = 0; v < all.size(); ++v) keys[v] = canonicalVoxelKey(all.coords[v]);
  std::vector<size_t> order(all.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return keys[a] < keys[b]; });
  std::vector<uint32_t> newIndex(all.size());
  for (size_t i = 0; i < order.size(); ++i) {
    if (i > 0 && keys[order[i]] == keys[order[i - 1]]) {
      throw IoError("light grid parts share voxel " + all.coords[order[i]].ToString());
    }
    newIndex[order[i]] = uint32_t(i);
  }
  std::vector<size_t> layers(all.layers.size());
  std::iota(layers.begin(), layers.end(), size_t(0));
  std::stable_sort(layers.begin(), layers.end(), [&](size_t a, size_t b) {
    return newIndex[all.layers.voxel[a]] < newIndex[all.layers.voxel[b]];
  });
  std::vector<uint32_t> layerVoxel;
  layerVoxel.reserve(layers.size());
  for (size_t e : layers) layerVoxel.push_back(newIndex[all.layers.voxel[e]]);
  return reorder(all, order, layers, std::move(layerVoxel));
}

}  // namespace lo
