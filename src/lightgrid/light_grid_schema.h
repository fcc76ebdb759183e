#pragma once
/// @file lightgrid/light_grid_schema.h
/// @brief The light grid's fields, declared once: for each per-voxel array of
/// VdlGrid its layer mirror, how many values a voxel holds, the .vdb grid it
/// is stored as (name, units, vector type), whether it may be stored as half
/// floats or left out of a file, and what resampling does with it. Writing
/// and reading .vdb files, the array checks, resizing, the resampling copies
/// and the distributed split and merge all walk this table, so a field is
/// added by adding a row (docs/architecture.md, "Adding a field to the light
/// grid"). Depends on core only: the OpenVDB side lives in src/vdb.

#include <cstddef>
#include <cstdint>
#include <tuple>
#include <type_traits>
#include <vector>

#include "lightgrid/vdl_grid.h"

namespace lo {

/// How many values of a field a voxel (or surface layer) holds.
enum class FieldArity {
  One,        ///< one per voxel
  OneOrNone,  ///< one per voxel, or none at all (an empty array: not
              ///< recorded); stored only on the voxels with surface layers;
              ///< always one per layer
  VdlSlots,   ///< VdlGrid::maxVdls per voxel, strongest first
  ShTerms,    ///< VdlGrid::shTerms per voxel
};

/// The vector type a Vec3 grid declares (OpenVDB's VecType, which readers
/// such as Houdini use to transform the values); None for scalar grids.
enum class FieldVecType { None, Invariant, CovariantNormalize, ContravariantAbsolute };

/// What changing the light of a grid does with a field.
enum class FieldRole {
  Surface,  ///< the voxel's geometry: kept by every light conversion
  Gather,   ///< the gathered totals: kept when the light is only re-clustered
  Light,    ///< the light's form (VDLs, SH): made again by a conversion
};

/// One row of the light grid's table. `T` is the array's value type: Vec3
/// and float are stored as Vec3s and float grids, uint8_t counts as float
/// grids of integers, Vdl as one grid per slot and Vdl member
/// (kVdlComponents).
template <typename T>
struct LightGridField {
  using Value = T;
  const char* member;                 ///< the VdlGrid member, for messages
  std::vector<T> VdlGrid::*voxels;    ///< the per-voxel array
  std::vector<T> VdlLayers::*layers;  ///< its mirror per surface layer; nullptr: none
  FieldArity arity;
  /// The .vdb grid of the voxels; for VdlSlots and ShTerms the prefix of
  /// one grid per slot or term ("vdl" -> vdl0_irradiance, "sh" -> sh0).
  const char* gridName;
  /// Layer l's grid is "layer<l>_" + this; nullptr exactly when `layers` is.
  const char* layerGridName;
  const char* units;  ///< the grid's "units" metadata (Vdl: per component)
  FieldVecType vecType;
  bool halfFloat;  ///< stored as 16-bit halves when a file asks for them
  bool optional;   ///< a file may leave it out (convert --drop); read as 0
  FieldRole role;
};

/// The grids one VDL slot is stored as: one per member of Vdl, named
/// gridName + slot + suffix (vdl0_irradiance, vdl0_direction), active only
/// where the voxel has more VDLs than the slot's index.
struct VdlComponent {
  Vec3 Vdl::*member;
  const char* suffix;
  const char* units;
  FieldVecType vecType;
};
inline constexpr VdlComponent kVdlComponents[] = {
    {&Vdl::irradiance, "_irradiance", "W/m^2", FieldVecType::Invariant},
    {&Vdl::direction, "_direction", "unit vector towards the light, world space",
     FieldVecType::Invariant},
};

namespace lightgrid_internal {
constexpr bool kHalf = true, kFull = false;
constexpr bool kOptional = true, kRequired = false;
}  // namespace lightgrid_internal

/// Every per-voxel array of VdlGrid but the coordinates (the key), in .vdb
/// file order: a layer's grids follow the table, the voxels' grids too, but
/// with the OneOrNone rows last (they cover only the voxels with layers).
/// The order, names, units and types are the file contract
/// (docs/vdb-contract.md): changing them changes the files' bytes.
inline constexpr auto kLightGridFields = [] {
  using namespace lightgrid_internal;
  using A = FieldArity;
  using V = FieldVecType;
  using R = FieldRole;
  return std::make_tuple(
      //                  member, voxel array, layer array, arity,
      //                  grid, layer grid, units, vector type, half, optional, role
      LightGridField<Vec3>{"irradiance", &VdlGrid::irradiance, &VdlLayers::irradiance, A::One,
                           "irradiance", "irradiance", "W/m^2", V::Invariant, kHalf, kRequired,
                           R::Gather},
      LightGridField<Vec3>{"reflectance", &VdlGrid::reflectance, &VdlLayers::reflectance,
                           A::One, "reflectance", "reflectance",
                           "share of the irradiance reflected (RGB, 0..1)", V::Invariant, kHalf,
                           kOptional, R::Gather},
      LightGridField<Vec3>{"normals", &VdlGrid::normals, &VdlLayers::normals, A::One, "normal",
                           "normal", "unit vector, world space", V::CovariantNormalize, kHalf,
                           kRequired, R::Surface},
      LightGridField<Vec3>{"points", &VdlGrid::points, &VdlLayers::points, A::OneOrNone,
                           "layer_point", "point", "world space", V::ContravariantAbsolute, kFull,
                           kRequired, R::Surface},
      LightGridField<float>{"photonCount", &VdlGrid::photonCount, &VdlLayers::photonCount, A::One,
                            "photon_count", "photon_count", "photons", V::None, kFull, kOptional,
                            R::Gather},
      LightGridField<float>{"noise", &VdlGrid::noise, &VdlLayers::noise, A::One, "noise",
                            "noise", "relative standard error of the irradiance (std. dev. / value)",
                            V::None, kHalf, kOptional, R::Gather},
      LightGridField<float>{"angularError", &VdlGrid::angularError, &VdlLayers::angularError,
                            A::One, "angular_error", "angular_error",
                            "chord length (0..2), weighted std. deviation", V::None, kHalf,
                            kOptional, R::Light},
      LightGridField<uint8_t>{"vdlCount", &VdlGrid::vdlCount, &VdlLayers::vdlCount, A::One,
                              "vdl_count", "vdl_count", "count", V::None, kFull, kRequired,
                              R::Light},
      LightGridField<float>{"radius", &VdlGrid::radius, &VdlLayers::radius, A::One, "radius",
                            "radius", "world units", V::None, kHalf, kOptional, R::Gather},
      LightGridField<float>{"areas", &VdlGrid::areas, nullptr, A::One, "area", nullptr,
                            "world units^2", V::None, kFull, kOptional, R::Surface},
      LightGridField<Vdl>{"vdls", &VdlGrid::vdls, &VdlLayers::vdls, A::VdlSlots, "vdl", "vdl",
                          "", V::None, kHalf, kRequired, R::Light},
      LightGridField<Vec3>{"sh", &VdlGrid::sh, &VdlLayers::sh, A::ShTerms, "sh", "sh",
                           "W/m^2 (SH term; E(n) = sum_i sh<i> Y_i(n))", V::Invariant, kHalf,
                           kRequired, R::Light});
}();

/// Calls fn(row) for every row of kLightGridFields, in order.
template <typename Fn>
void forEachField(Fn&& fn) {
  std::apply([&](const auto&... row) { (fn(row), ...); }, kLightGridFields);
}

/// Values per voxel of `row` in `g` (OneOrNone: 0 when not recorded).
template <typename T>
size_t valuesPerVoxel(const VdlGrid& g, const LightGridField<T>& row) {
  switch (row.arity) {
    case FieldArity::One: return 1;
    case FieldArity::OneOrNone: return (g.*row.voxels).empty() ? 0 : 1;
    case FieldArity::VdlSlots: return size_t(g.maxVdls);
    case FieldArity::ShTerms: return size_t(g.shTerms);
  }
  return 0;
}

/// Values per surface layer of `row` in `g`.
template <typename T>
size_t valuesPerLayer(const VdlGrid& g, const LightGridField<T>& row) {
  return row.arity == FieldArity::OneOrNone ? 1 : valuesPerVoxel(g, row);
}

/// Calls fn(array, valuesPerVoxel) for every per-voxel array of `g`, the
/// coordinates first. `Grid` is VdlGrid or const VdlGrid.
template <typename Grid, typename Fn>
void forEachVoxelArray(Grid& g, Fn&& fn) {
  fn(g.coords, size_t(1));
  forEachField([&](const auto& row) { fn(g.*row.voxels, valuesPerVoxel(g, row)); });
}

/// Calls fn(array, valuesPerLayer) for every per-layer array of `g` but
/// the voxel index (VdlLayers::voxel).
template <typename Grid, typename Fn>
void forEachLayerArray(Grid& g, Fn&& fn) {
  forEachField([&](const auto& row) {
    if (row.layers) fn(g.layers.*row.layers, valuesPerLayer(g, row));
  });
}

/// Sizes every per-voxel array to g.coords.size() voxels (OneOrNone arrays
/// only when they are recorded), new values zero.
void resizeVoxelArrays(VdlGrid& g);

/// Sizes the layer index and every per-layer array to `layers` entries,
/// new values zero; with layers, the voxels' OneOrNone arrays are recorded
/// (sized to the voxels) too.
void resizeLayerArrays(VdlGrid& g, size_t layers);

/// Checks (LO_CHECK: a broken invariant, not bad input) that every array of
/// `g` has its row's length, shTerms is 0, 4 or 9, and the layer index is
/// ascending within the voxels, at most kMaxLayers - 1 entries per voxel.
void checkLightGridArrays(const VdlGrid& g);

/// Copies from `in` to `out` the voxel and layer arrays of the rows with
/// `role` (the grids have the same voxels and layers).
void copyFieldsOfRole(const VdlGrid& in, VdlGrid& out, FieldRole role);

}  // namespace lo
