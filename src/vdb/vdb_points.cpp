// The photon map as an OpenVDB PointDataGrid ("photons": P, Cd, direction,
// N, bounce, reflectance). The only translation unit that includes OpenVDB's points
// headers, which compile slowly.

#include <openvdb/openvdb.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "vdb/vdb_contract.h"
#include "vdb/vdb_file.h"
#include "vdb/vdb_internal.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace vdb_internal {
namespace {

using openvdb::math::Transform;

void writePoints(const std::string& path, const std::vector<Photon>& photons, float voxelSize,
                 const Vec3d& offset, AtomicFileSet* into, const PhotonMapInfo& info) {
  if (!(voxelSize > 0) || !std::isfinite(voxelSize)) {
    throw InputError(path + ": photon point voxel size must be positive, got " +
                     std::to_string(voxelSize));
  }
  initOpenVdb();
  namespace pts = openvdb::points;
  const size_t n = photons.size();
  std::vector<openvdb::Vec3R> positions(n);
  std::vector<openvdb::Vec3s> power(n), direction(n), normal(n), reflectance(n);
  std::vector<int32_t> bounce(n);
  for (size_t i = 0; i < n; ++i) {
    const Photon& p = photons[i];
    positions[i] = openvdb::Vec3R(offset.x + double(p.position.x), offset.y + double(p.position.y),
                                  offset.z + double(p.position.z));
    power[i] = toVdb(p.power);
    direction[i] = toVdb(p.direction);
    normal[i] = toVdb(p.normal);
    reflectance[i] = toVdb(reflectanceOf(p));
    bounce[i] = int32_t(p.bounce);
  }
  // Points are world space; the grid only buckets them, from the scene's
  // origin (voxel indices stay small far from the world's).
  Transform::Ptr xform = Transform::createLinearTransform(double(voxelSize));
  xform->postTranslate(openvdb::Vec3d(offset.x, offset.y, offset.z));
  pts::PointAttributeVector<openvdb::Vec3R> positionWrapper(positions);
  auto indexGrid =
      openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positionWrapper, *xform);
  // NullCodec: full float positions (relative to the voxel centre), no quantisation.
  pts::PointDataGrid::Ptr grid = pts::createPointDataGrid<pts::NullCodec, pts::PointDataGrid>(
      *indexGrid, positionWrapper, *xform);
  auto addVec3 = [&](const char* name, const std::vector<openvdb::Vec3s>& values) {
    pts::appendAttribute<openvdb::Vec3s>(grid->tree(), name);
    pts::PointAttributeVector<openvdb::Vec3s> wrapper(values);
    pts::populateAttribute(grid->tree(), indexGrid->tree(), name, wrapper);
  };
  addVec3("Cd", power);
  addVec3("direction", direction);
  addVec3("N", normal);
  pts::appendAttribute<int32_t>(grid->tree(), "bounce");
  pts::PointAttributeVector<int32_t> bounceWrapper(bounce);
  pts::populateAttribute(grid->tree(), indexGrid->tree(), "bounce", bounceWrapper);
  addVec3("reflectance", reflectance);

  grid->setName("photons");
  grid->insertMeta("units",
                   openvdb::StringMetadata("P: world units; Cd: photon power, W (RGB); "
                                           "direction: unit, towards where the photon came from; "
                                           "N: unit surface normal; "
                                           "reflectance: the surface's hemispherical "
                                           "reflectance, RGB 0..1"));
  openvdb::MetaMap meta;
  meta.insertMeta("generator", openvdb::StringMetadata("lightoctree"));
  meta.insertMeta("version", openvdb::StringMetadata(LO_VERSION));
  meta.insertMeta("photons", openvdb::Int64Metadata(int64_t(n)));
  // The scene the photons were traced in, as the .vdb records it: a reader
  // given another scene can say so (convert --photon-map --scene).
  if (!info.sourceSceneHash.empty()) {
    meta.insertMeta("source_scene_hash", openvdb::StringMetadata(info.sourceSceneHash));
  }
  // The sky they were traced under: a grid re-gathered from them holds its light.
  if (!info.skyHash.empty()) meta.insertMeta("sky_hash", openvdb::StringMetadata(info.skyHash));
  // Whether they hold the direct light: a grid re-gathered from them does.
  if (info.includeDirect >= 0) {
    meta.insertMeta("include_direct", openvdb::Int32Metadata(info.includeDirect));
  }
  // The region the photons were stored in (bake --bounds), in world
  // coordinates as the positions: a reader can tell a grid it does not cover.
  if (!info.region.empty()) {
    for (const auto& [key, corner] : {std::pair{"region_min", info.region.lower},
                                      std::pair{"region_max", info.region.upper}}) {
      const Vec3d w = offset + Vec3d(corner);
      meta.insertMeta(key, openvdb::Vec3DMetadata(openvdb::Vec3d(w.x, w.y, w.z)));
    }
  }
  writeVdbFile(path, {{"photons", [&grid] { return openvdb::GridBase::Ptr(grid); }}}, meta, into);
}

std::vector<Photon> readPoints(const std::string& path, const Vec3d& origin,
                               PhotonMapInfo* info) {
  namespace pts = openvdb::points;
  OpenedFile f = openFile(path);
  if (info) {
    auto hash = openvdb::DynamicPtrCast<const openvdb::StringMetadata>((*f.meta)["source_scene_hash"]);
    info->sourceSceneHash = hash ? hash->value() : "";
    auto sky = openvdb::DynamicPtrCast<const openvdb::StringMetadata>((*f.meta)["sky_hash"]);
    info->skyHash = sky ? sky->value() : "";
    // As the grid's (either integer width; 0 or 1).
    info->includeDirect = metaOnOff(path, *f.meta, "include_direct");
    auto lower = openvdb::DynamicPtrCast<const openvdb::Vec3DMetadata>((*f.meta)["region_min"]);
    auto upper = openvdb::DynamicPtrCast<const openvdb::Vec3DMetadata>((*f.meta)["region_max"]);
    info->region = Bounds3();
    if (lower && upper && lower->value().isFinite() && upper->value().isFinite()) {
      for (const openvdb::Vec3d& w : {lower->value(), upper->value()}) {
        info->region.extend((Vec3d(w.x(), w.y(), w.z()) - origin).toVec3());
      }
    }
  }
  if (!findGrid(f, "photons") && findGrid(f, gridNameOf(&VdlGrid::irradiance))) {
    throw InputError(path + ": is a VDL file (written by `lightoctree bake -o`), not a photon "
                     "file (`bake --photon-map`)");
  }
  auto grid = requireGrid<pts::PointDataGrid>(path, f, "photons");
  std::vector<Photon> out;
  out.reserve(size_t(pts::pointCount(grid->tree())));
  auto leaf = grid->tree().cbeginLeaf();
  if (!leaf) return out;
  const auto& descriptor = leaf->attributeSet().descriptor();
  auto attribute = [&](const char* name) {
    const size_t index = descriptor.find(name);
    if (index == pts::AttributeSet::INVALID_POS) {
      throw InputError(path + ": photon grid has no attribute '" + name + "'");
    }
    return index;
  };
  const size_t pIndex = attribute("P"), cdIndex = attribute("Cd");
  const size_t dIndex = attribute("direction"), nIndex = attribute("N");
  const size_t bIndex = attribute("bounce");
  // Photon files written before the surfaces' reflectance was recorded lack
  // it: their photons reflect nothing (VdlGrid::reflectance 0).
  const size_t rIndex = descriptor.find("reflectance");
  const Transform& xform = grid->transform();
  try {
    for (; leaf; ++leaf) {
      pts::AttributeHandle<openvdb::Vec3f> pHandle(leaf->constAttributeArray(pIndex));
      pts::AttributeHandle<openvdb::Vec3s> cdHandle(leaf->constAttributeArray(cdIndex));
      pts::AttributeHandle<openvdb::Vec3s> dHandle(leaf->constAttributeArray(dIndex));
      pts::AttributeHandle<openvdb::Vec3s> nHandle(leaf->constAttributeArray(nIndex));
      pts::AttributeHandle<int32_t> bHandle(leaf->constAttributeArray(bIndex));
      std::unique_ptr<pts::AttributeHandle<openvdb::Vec3s>> rHandle;
      if (rIndex != pts::AttributeSet::INVALID_POS) {
        rHandle = std::make_unique<pts::AttributeHandle<openvdb::Vec3s>>(
            leaf->constAttributeArray(rIndex));
      }
      for (auto idx = leaf->beginIndexOn(); idx; ++idx) {
        const openvdb::Vec3d world =
            xform.indexToWorld(pHandle.get(*idx) + idx.getCoord().asVec3d());
        Photon p;
        p.position = Vec3(float(world.x() - origin.x), float(world.y() - origin.y),
                          float(world.z() - origin.z));
        p.power = fromVdb(cdHandle.get(*idx));
        p.direction = fromVdb(dHandle.get(*idx));
        p.normal = fromVdb(nHandle.get(*idx));
        p.bounce = uint16_t(std::clamp(bHandle.get(*idx), 0, 0xffff));
        if (rHandle) setReflectance(p, fromVdb(rHandle->get(*idx)));
        out.push_back(p);
      }
    }
  } catch (const openvdb::Exception& e) {
    throw InputError(path + ": cannot read the photon attributes: " + e.what());
  }
  return out;
}

}  // namespace

PointFileInfo inspectPointFile(const std::string& path) {
  namespace pts = openvdb::points;
  OpenedFile f = openFile(path);
  PointFileInfo info;
  for (const auto& g : *f.grids) info.gridNames.push_back(g->getName());
  auto grid = requireGrid<pts::PointDataGrid>(path, f, "photons");
  info.pointCount = pts::pointCount(grid->tree());
  auto leaf = grid->tree().cbeginLeaf();
  if (!leaf) return info;
  const auto& descriptor = leaf->attributeSet().descriptor();
  info.attributes.resize(descriptor.size());
  for (const auto& [name, index] : descriptor.map()) info.attributes[index] = name;
  const size_t cdIndex = descriptor.find("Cd"), bIndex = descriptor.find("bounce");
  const size_t pIndex = descriptor.find("P");
  double cd[3] = {0, 0, 0};
  for (; leaf; ++leaf) {
    pts::AttributeHandle<openvdb::Vec3s> cdHandle(leaf->constAttributeArray(cdIndex));
    pts::AttributeHandle<int32_t> bHandle(leaf->constAttributeArray(bIndex));
    pts::AttributeHandle<openvdb::Vec3f> pHandle(leaf->constAttributeArray(pIndex));
    for (auto idx = leaf->beginIndexOn(); idx; ++idx) {
      const openvdb::Vec3s c = cdHandle.get(*idx);
      for (int k = 0; k < 3; ++k) cd[k] += c[k];
      info.totalBounce += bHandle.get(*idx);
      const openvdb::Vec3d world =
          grid->transform().indexToWorld(pHandle.get(*idx) + idx.getCoord().asVec3d());
      info.positionBounds.extend(Vec3(float(world.x()), float(world.y()), float(world.z())));
    }
  }
  info.totalCd = Vec3(float(cd[0]), float(cd[1]), float(cd[2]));
  return info;
}

}  // namespace vdb_internal

std::vector<Photon> readPhotonPoints(const std::string& path, const Vec3d& origin,
                                     PhotonMapInfo* info) {
  return vdb_internal::readPoints(path, origin, info);
}

void writePhotonPoints(const std::string& path, const std::vector<Photon>& photons, float voxelSize,
                       const Vec3d& offset, AtomicFileSet* into, const PhotonMapInfo& info) {
  vdb_internal::writePoints(path, photons, voxelSize, offset, into, info);
}

}  // namespace lo
