#pragma once
/// @file tests/test_util.h
/// @brief Small scenes and lights built in code, paths to test data, and the
/// checks and quadratures that the tests of several stages share.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "octree/gpu_octree.h"
#include "core/rng.h"
#include "scene/scene.h"

namespace lo {
class GlContext;
}

namespace lo::test {

/// One OSMesa context for the whole test binary, made current; null when the
/// machine has none (tests then skip).
GlContext* osmesaContext();

/// Folder with the shared test scenes (../shared/scenes beside the repository).
std::string sharedScenesDir();
/// The repository's data/ folder.
std::string dataDir();
/// A fresh, empty folder for files a test writes (under the build tree).
std::string outputDir(const std::string& testName);

/// A scene of one default material and no triangles yet.
Scene oneMaterialScene();

/// Adds an axis-aligned quad (two triangles) with the given material; the
/// winding makes its geometric normal equal `normal`.
void addQuad(Scene& scene, const Vec3& corner, const Vec3& edgeU, const Vec3& edgeV,
             const Vec3& normal, int material);

/// Closed cube [lo, hi]^3 of six inward-facing quads with material `material`.
void addClosedBox(Scene& scene, const Vec3& lo, const Vec3& hi, int material);

/// A block standing on y = lo.y: five outward-facing quads (no bottom face).
void addBlock(Scene& scene, const Vec3& lo, const Vec3& hi, int material);

/// A point light of `intensity` W/sr (cd) at `position`, of `color`.
Light pointLight(const Vec3& position, float intensity, const Vec3& color = Vec3(1.0f));

/// A sun (directional light) travelling along `direction`, normalised here;
/// `irradiance` W/m^2 (lx).
Light sun(const Vec3& direction, float irradiance);

/// The closed unit box (inward faces, default material) with two blocks
/// standing on its floor (outward faces, no bottom face): a Cornell-like room.
Scene boxWithTwoBlocks(const Bounds3& block1, const Bounds3& block2);

/// A direction uniform on the unit sphere (z uniform in [-1, 1], then the
/// azimuth): two numbers from `rng`.
Vec3 randomUnit(Rng& rng);

/// Expects `run` to throw InputError whose message holds each of `parts`;
/// a failure quotes the message, or says that nothing was thrown.
void expectRefusal(const std::function<void()>& run, const std::vector<std::string>& parts);

/// The midpoint rule on the hemisphere around +z, cosine-weighted: calls
/// `at(l, z)` for the centre of each of steps x steps cells uniform in
/// (sin^2 theta, phi), l = (r cos phi, r sin phi, z), z = cos theta. A cell
/// spans the solid angle pi / (steps^2 z): the hemisphere integral of g is
/// pi / steps^2 times the sum of g(l) / z.
void forCosineGrid(int steps, const std::function<void(const Vec3& l, float z)>& at);

/// Runs `command` through the shell; its standard output ("" if it cannot start).
std::string runCommand(const std::string& command);

/// Runs `run` with the process's address space limited (ulimit -v) to what it
/// maps now plus `headroom` bytes, the limit put back after: the message of
/// what it threw ("no error" when nothing; an exception other than
/// InputError's prefixed "not an InputError: "), or nullopt when the limit
/// already in force is lower (`run` is not run).
std::optional<std::string> messageUnderAddressSpaceLimit(size_t headroom,
                                                         const std::function<void()>& run);

/// Runs `child` in a forked child process, so that limits it sets (ulimit -v,
/// -n) stay there: the text it returns, read back through a pipe, or
/// "child failed: ..." when it exits otherwise (a return code of its own:
/// `std::_Exit(2)` for a set-up it could not make).
std::string textFromChild(const std::function<std::string()>& child);

/// The unit room (albedo 0.6) with a block on the floor, lit by a point light
/// of intensity 1 at (0.5, 0.8, 0.5): a small scene for whole-bake tests.
Scene pointLitRoom();

/// Two rooms side by side, [0, 1] and [1, 2] along x (y, z in [0, 1]),
/// sealed from each other by a thin divider at x = 1 (one quad per side;
/// albedo 0.7); a point light of intensity 1 at (0.5, 0.7, 0.5), in the first.
Scene sealedRooms();

/// An 8 x 8 sky image (Sky::image): radiance 4 within 45 degrees of the
/// zenith (rows 0 and 1), 1 down to the horizon (rows 2 and 3), 7 below
/// (unused). An open surface facing up receives E = 4 pi sin^2(45) +
/// pi cos^2(45) = 2.5 pi from it.
std::shared_ptr<const Texture> twoBandSkyImage();

/// GPU octree parameters with the texels of the paper's form (no cosine
/// correction): tests of the layout and the lookup compare texels with the
/// grid's VDLs, and the golden images were made with it.
inline GpuOctreeParams paperCosine() {
  GpuOctreeParams p;
  p.cosineCorrection = false;
  return p;
}

}  // namespace lo::test
