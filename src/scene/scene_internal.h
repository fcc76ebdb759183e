#pragma once
/// @file scene/scene_internal.h
/// @brief Helpers shared by the glTF and OBJ loaders. Not part of the public
/// API: nothing outside src/scene includes this header.

#include <algorithm>
#include <cstdint>
#include <istream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"

namespace lo::scene_internal {

/// Throws InputError "<path>: <problem>".
[[noreturn]] void fail(const std::string& path, const std::string& problem);

/// Resolves `uri` (already percent-decoded) against the folder `baseDir`.
/// Rejects absolute paths and any path that leaves the folder ("..", or a
/// symlink that resolves outside it) with InputError naming `scenePath`,
/// `what` (e.g. "buffer 0") and the uri. Does not check that the file exists.
std::string resolveInsideFolder(const std::string& scenePath, const std::string& baseDir,
                                const std::string& uri, const std::string& what);

/// Skips a UTF-8 byte-order mark at the start of a text file's stream (Windows
/// editors write one): tinyobjloader read "\xEF\xBB\xBFmtllib" as an unknown
/// statement, and an OBJ lost its materials without a word (H17-7-2).
void skipByteOrderMark(std::istream& in);

/// Decodes %XX escapes of a URI reference (glTF uris are URI-encoded).
std::string percentDecode(const std::string& uri);

/// Reads a whole file; throws InputError "<scenePath>: missing <what> '<file>'"
/// when it cannot be opened.
std::vector<unsigned char> readFileBytes(const std::string& scenePath, const std::string& file,
                                         const std::string& what);

/// Decodes a PNG/JPEG/... image (stb_image; 1-4 channels, 8 or 16 bit) into a
/// Texture that keeps its texels as stored (`srgb`: its colour channels are
/// sRGB-encoded) and, for PNG and JPEG, the file's bytes (Texture::encoded).
/// Throws InputError "<scenePath>: unreadable image <what>".
Texture decodeImage(const std::string& scenePath,
                    const std::shared_ptr<const std::vector<uint8_t>>& bytes,
                    const std::string& what, bool srgb = true);

/// A texture of the scene whose image file is read but not yet decoded: the
/// loaders gather them all, then decodeTextures.
struct PendingTexture {
  int index = -1;  ///< into Scene::textures, where the texture is kept (its name, sampler)
  std::shared_ptr<const std::vector<uint8_t>> bytes;
  std::string what;
  bool srgb = true;
};

/// Decodes each of `pending` (decodeImage) into its Scene::textures entry,
/// keeping the entry's name and sampler; first refuses them all when their
/// texels together would take more than half the memory available. Each
/// image alone was checked against that as it was decoded: 160 copies of a
/// 4096^2 PNG reached 7.4 GB before one was refused.
/// @throws InputError "<scenePath>: its N textures would take ... decoded,
/// more than ..., half the ... of memory available".
void decodeTextures(Scene& scene, const std::string& scenePath,
                    const std::vector<PendingTexture>& pending);

/// How far a scene may lie from the origin, in multiples of its size, before
/// its loader rebases it: there float spacing reaches 2^-16 (1.5e-5) of its
/// size.
constexpr double kRebaseDistance = 128.0;

/// World-space bounds of a loader's vertices, in double, and the origin it
/// rebases its scene to (Scene::origin): their centre when it lies farther
/// from (0, 0, 0) than kRebaseDistance times the bounds' diagonal, else
/// (0, 0, 0), so that a scene near the origin keeps its coordinates exactly.
struct RebaseBounds {
  Vec3d lower{kInfinity, kInfinity, kInfinity}, upper{-kInfinity, -kInfinity, -kInfinity};
  void extend(const Vec3d& p) {
    for (int a = 0; a < 3; ++a) {
      lower[a] = std::min(lower[a], p[a]);
      upper[a] = std::max(upper[a], p[a]);
    }
  }
  Vec3d origin() const;

 private:
  static constexpr double kInfinity = std::numeric_limits<double>::infinity();
};

/// Bytes a scene holds per triangle, at most: three vertices of its own
/// (position, normal, two UV sets, tangent: 56 bytes; the double position a
/// loader keeps for the rebase: 24), its indices and material (16).
constexpr double kSceneBytesPerTriangle = 3.0 * (56 + 24) + 16;

/// "" when a scene of `triangles` fits: 32-bit indices, and
/// kSceneBytesPerTriangle each within half the memory available; else "N
/// triangles (X to hold), beyond half the Y of memory available" (or
/// "beyond 32-bit indices"). Counted before the triangles are built: the
/// glTF node tree's (instances included) and the objects `--add` joins.
std::string triangleBudgetProblem(uint64_t triangles);

/// `skyMesh`: loadScene's.
Scene loadGltf(const std::string& path, const std::string& skyMesh);
Scene loadObj(const std::string& path);

/// The light and material numbers within their documented ranges
/// (docs/scene.md, "Limits"): glTF's [0, 1] factors (metallic, roughness,
/// transmission, specular, light colours) clamped with a warning naming
/// them; a negative emission taken as 0 with a warning; an emission above
/// kMaxRadiance, a light intensity outside [0, kMaxLightIntensity] or a
/// light beyond kMaxCoordinate refused.
void checkLightAndMaterialValues(Scene& scene);

/// Final checks shared by both loaders: at least one triangle, finite vertices
/// within kMaxCoordinate, every index in range, one material per triangle in
/// range; base colours clamped to [0, 1] (Scene::warnings says so).
void validateScene(Scene& scene);

/// Takes out every triangle that repeats an earlier one: the same three
/// vertices (so the same positions, normals, UVs and colours) in the same
/// winding (any starting corner) and the same material. Such copies (5,000
/// primitives over one index accessor, whose vertices the loader shares)
/// draw nothing a single one does not, yet every ray would test each of
/// them. Copies through other vertices (another node instance in the same
/// place, another colour) are kept. The first of each set is kept, the order of the rest
/// unchanged; a triangle and its mirror image (the two faces of a sheet) are
/// not copies. Scene::warnings says how many went. Returns that number.
/// O(n log n) time, 16 bytes a triangle besides the scene.
size_t dropRepeatedTriangles(Scene& scene);

}  // namespace lo::scene_internal
