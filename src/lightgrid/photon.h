#pragma once
/// @file lightgrid/photon.h
/// @brief The stored photon record: photon tracing (src/photon) makes it, the
/// gather reads it and the photon `.vdb` file (src/vdb) stores it. Plain data
/// here, so that reading a photon file does not link the tracer (Embree).

#include <cstdint>

#include "core/math.h"

namespace lo {

/// One stored photon hit on a non-specular surface.
struct Photon {
  Vec3 position;   ///< world space hit point
  Vec3 direction;  ///< unit, world space, from the hit point TOWARDS where the photon came from (wi)
  Vec3 power;      ///< RGB flux carried, W
  Vec3 normal;     ///< unit geometric normal at the hit, facing the side the photon arrived from
  uint16_t bounce = 0;  ///< 0 = direct from a light, 1 = after one diffuse/glossy bounce, ...
  /// 1: a caustic photon, which reached this hit from the light through
  /// mirrors, glass or smooth metal alone (L S+ D): the gather reads it with
  /// its own, smaller reach (GatherParams::separateCaustics).
  uint16_t caustic = 0;
  /// The hemispherical reflectance of the surface at the hit (RGB, 0..1 in
  /// steps of 1/255; hemisphericalReflectance in material/bsdf.h): the share
  /// of the photon's power that surface sends back into the room. The gather
  /// averages it per voxel (VdlGrid::reflectance), so that the renderer can
  /// light a surface that sees this one from below its horizon.
  uint8_t reflectance[3] = {0, 0, 0};
  /// Zero: the record has no byte left unset (photon maps are compared
  /// and sent between ranks as bytes).
  uint8_t spare = 0;
};
static_assert(sizeof(Photon) == 56, "Photon: 13 floats, 2 shorts and 4 bytes, no padding");

/// Photon::reflectance as RGB in 0..1.
inline Vec3 reflectanceOf(const Photon& p) {
  return Vec3{float(p.reflectance[0]), float(p.reflectance[1]), float(p.reflectance[2])} *
         (1.0f / 255.0f);
}

/// Stores RGB `r` (clamped to 0..1, rounded to the nearest 1/255) in p.reflectance.
inline void setReflectance(Photon& p, const Vec3& r) {
  for (int c = 0; c < 3; ++c) {
    const float v = r[c] > 0 ? (r[c] < 1 ? r[c] : 1.0f) : 0.0f;
    p.reflectance[c] = uint8_t(v * 255.0f + 0.5f);
  }
}

/// One ray of a photon path whose light the octree holds: it starts where
/// the light left its last surface (or, for the sky's and with
/// --include-direct, its emitter) and ends at the next hit, or beyond the
/// scene when it hit nothing. The free-space light is the track length of
/// these rays through each volume voxel (cluster/volume_light.h).
struct PhotonSegment {
  Vec3 from;   ///< world space
  Vec3 to;     ///< world space
  Vec3 power;  ///< RGB flux carried along it, W
};

}  // namespace lo
