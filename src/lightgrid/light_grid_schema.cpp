// The table-driven operations on every array of a light grid
// (lightgrid/light_grid_schema.h).

#include "lightgrid/light_grid_schema.h"

#include "core/error.h"

namespace lo {

void resizeVoxelArrays(VdlGrid& g) {
  const size_t n = g.coords.size();
  forEachField([&](const auto& row) { (g.*row.voxels).resize(n * valuesPerVoxel(g, row)); });
}

void resizeLayerArrays(VdlGrid& g, size_t layers) {
  g.layers.voxel.resize(layers);
  forEachField([&](const auto& row) {
    if (row.layers) (g.layers.*row.layers).resize(layers * valuesPerLayer(g, row));
    // A voxel's layer 0 needs what its other layers are measured against.
    if (row.arity == FieldArity::OneOrNone && layers > 0) (g.*row.voxels).resize(g.size());
  });
}

void checkLightGridArrays(const VdlGrid& g) {
  LO_CHECK(g.shTerms == 0 || g.shTerms == 4 || g.shTerms == 9);
  const size_t n = g.size(), ne = g.layers.size();
  forEachField([&](const auto& row) {
    const size_t per = valuesPerVoxel(g, row);
    // A OneOrNone array is recorded wherever there are layers.
    if (row.arity == FieldArity::OneOrNone && ne > 0) LO_CHECK_EQ(per, size_t(1));
    LO_CHECK_EQ((g.*row.voxels).size(), n * per);
    if (row.layers) LO_CHECK_EQ((g.layers.*row.layers).size(), ne * valuesPerLayer(g, row));
  });
  const std::vector<uint32_t>& voxel = g.layers.voxel;
  for (size_t e = 0; e < ne; ++e) {
    LO_CHECK_LT(size_t(voxel[e]), n);
    if (e > 0) LO_CHECK_LE(voxel[e - 1], voxel[e]);
    if (e > 1) LO_CHECK(voxel[e - 2] != voxel[e]);  // at most kMaxLayers - 1 extra
  }
}

void copyFieldsOfRole(const VdlGrid& in, VdlGrid& out, FieldRole role) {
  forEachField([&](const auto& row) {
    if (row.role != role) return;
    out.*row.voxels = in.*row.voxels;
    if (row.layers) out.layers.*row.layers = in.layers.*row.layers;
  });
}

}  // namespace lo
