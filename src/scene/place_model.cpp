/// @file scene/place_model.cpp
/// @brief placeModel: a model's arrays appended to a scene's, moved into place.

#include "scene/place_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "core/error.h"
#include "core/resources.h"
#include "scene/scene_internal.h"

namespace lo {

Placement parsePlacement(const std::string& text) {
  std::vector<double> values;
  std::vector<std::string> parts;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    // Decimal only, as every numeric flag: strtod reads "0x10" as 16.
    const bool hex = part.find_first_of("xX") != std::string::npos;
    if (part.empty() || hex || end == part.c_str() || *end != '\0' || !std::isfinite(v)) {
      throw InputError("--at '" + text + "': '" + part + "' is not a finite decimal number");
    }
    values.push_back(v);
    parts.push_back(part);
  }
  if (values.size() < 3 || values.size() > 5) {
    throw InputError("--at '" + text + "': expected x,y,z[,yaw[,scale]], got " +
                     std::to_string(values.size()) + " numbers");
  }
  // Each part checked by itself and named: a yaw of 1e300 degrees became
  // infinity in single precision and was reported as a vertex at NaN; a
  // scale of 1e-300 became 0, a model of no size.
  const char* names[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    if (std::fabs(values[size_t(k)]) > double(kMaxCoordinate)) {
      throw InputError("--at '" + text + "': " + names[k] + " " + parts[size_t(k)] +
                       " lies beyond " + formatNumber(double(kMaxCoordinate)) + " scene units");
    }
  }
  Placement p;
  p.at = Vec3d{values[0], values[1], values[2]};
  if (values.size() > 3) {
    if (std::fabs(values[3]) > kMaxYawDegrees) {
      throw InputError("--at '" + text + "': the yaw " + parts[3] + " must lie from -" +
                       formatNumber(kMaxYawDegrees) + " to " + formatNumber(kMaxYawDegrees) +
                       " degrees");
    }
    p.yawDegrees = float(values[3]);
  }
  if (values.size() > 4) {
    if (!(values[4] >= double(std::numeric_limits<float>::min())) || values[4] > 1e6) {
      throw InputError("--at '" + text + "': the scale " + parts[4] +
                       " must lie in (0, 1e6], at least 1.2e-38 (what single precision holds)");
    }
    p.scale = float(values[4]);
  }
  return p;
}

namespace {

/// Per-vertex values of `n` vertices from an array that may be empty: the
/// array, or `fill` repeated.
template <typename T>
void appendOrFill(std::vector<T>& to, size_t toVertices, const std::vector<T>& from,
                  size_t fromVertices, size_t per, const std::vector<T>& fill) {
  if (to.empty() && from.empty()) return;
  if (to.empty()) {
    for (size_t v = 0; v < toVertices; ++v) to.insert(to.end(), fill.begin(), fill.end());
  }
  if (from.empty()) {
    for (size_t v = 0; v < fromVertices; ++v) to.insert(to.end(), fill.begin(), fill.end());
  } else {
    to.insert(to.end(), from.begin(), from.begin() + std::ptrdiff_t(fromVertices * per));
  }
}

}  // namespace

namespace {

/// placeModel; the model's materials take the scene's textures from
/// `sharedTextures` on (those of an earlier copy of the same model) instead
/// of appending its own when `sharedTextures` >= 0.
void joinModel(Scene& scene, Scene model, const Placement& placement, int sharedTextures) {
  const float yaw = placement.yawDegrees * float(kPi / 180.0);
  const float c = std::cos(yaw), s = std::sin(yaw);
  auto turn = [c, s](const Vec3& v) { return Vec3{c * v.x + s * v.z, v.y, -s * v.x + c * v.z}; };
  const Vec3 at = scene.toLocal(placement.at);
  const Vec3d modelOrigin = model.origin;
  for (Vec3& p : model.positions) {
    const Vec3d world = Vec3d(p) + modelOrigin;  // the model's own coordinates
    const Vec3 placed = turn(world.toVec3() * placement.scale) + at;
    if (!isFinite(placed) || maxComponent(max(placed, -placed)) > kMaxCoordinate) {
      throw InputError(model.sourcePath + " placed at --at puts a vertex at " + placed.ToString() +
                       ", beyond " + std::to_string(kMaxCoordinate) + " scene units");
    }
    p = placed;
  }
  for (Vec3& n : model.normals) n = turn(n);
  for (size_t v = 0; 4 * v + 3 < model.tangents.size(); ++v) {
    const Vec3 t = turn(Vec3{model.tangents[4 * v], model.tangents[4 * v + 1], model.tangents[4 * v + 2]});
    model.tangents[4 * v] = t.x;
    model.tangents[4 * v + 1] = t.y;
    model.tangents[4 * v + 2] = t.z;
  }

  const size_t baseVertices = scene.positions.size(), addVertices = model.positions.size();
  const uint32_t vertexOffset = uint32_t(baseVertices);
  const int32_t materialOffset = int32_t(scene.materials.size());
  const int textureOffset = sharedTextures >= 0 ? sharedTextures : int(scene.textures.size());
  // Normals: where one side has none, zero vectors, which every reader
  // takes for the face's own normal (Scene::normals): flat faces stay flat,
  // where normals averaged over shared corners would bend them.
  appendOrFill(scene.normals, baseVertices, model.normals, addVertices, 1, {Vec3{0, 0, 0}});
  appendOrFill(scene.texcoords0, baseVertices, model.texcoords0, addVertices, 2, {0.0f, 0.0f});
  appendOrFill(scene.texcoords1, baseVertices, model.texcoords1, addVertices, 2, {0.0f, 0.0f});
  appendOrFill(scene.tangents, baseVertices, model.tangents, addVertices, 4,
               {0.0f, 0.0f, 0.0f, 0.0f});
  appendOrFill(scene.colors, baseVertices, model.colors, addVertices, 4, {1.0f, 1.0f, 1.0f, 1.0f});
  scene.positions.insert(scene.positions.end(), model.positions.begin(), model.positions.end());
  for (uint32_t i : model.indices) scene.indices.push_back(i + vertexOffset);
  for (int32_t m : model.triangleMaterial) scene.triangleMaterial.push_back(m + materialOffset);
  for (Material& m : model.materials) {
    for (int* t : {&m.baseColorTexture, &m.normalTexture, &m.metallicRoughnessTexture,
                   &m.occlusionTexture, &m.emissiveTexture}) {
      if (*t >= 0) *t += textureOffset;
    }
    scene.materials.push_back(std::move(m));
  }
  if (sharedTextures < 0) {
    for (Texture& t : model.textures) scene.textures.push_back(std::move(t));
  }
  if (scene.movingMaterialsFrom > size_t(materialOffset)) {
    scene.movingMaterialsFrom = size_t(materialOffset);
  }
  if (!model.lights.empty()) {
    scene.warnings.push_back(model.sourcePath + ": its " + std::to_string(model.lights.size()) +
                             " lights are left out: an added object does not change the baked light");
  }
  for (std::string& w : model.warnings) scene.warnings.push_back(std::move(w));
}

}  // namespace

void placeModel(Scene& scene, Scene model, const Placement& placement) {
  joinModel(scene, std::move(model), placement, -1);
}

void placeModels(Scene& scene, const std::vector<AddedModel>& models) {
  // Each file once, in the order first named; how many placements name it.
  std::vector<std::string> files;
  std::vector<Scene> loaded;
  std::vector<size_t> uses;
  std::vector<size_t> fileOf(models.size());
  for (size_t i = 0; i < models.size(); ++i) {
    const auto known = std::find(files.begin(), files.end(), models[i].path);
    fileOf[i] = size_t(known - files.begin());
    if (known != files.end()) {
      ++uses[fileOf[i]];
      continue;
    }
    files.push_back(models[i].path);
    uses.push_back(1);
    try {
      loaded.push_back(loadScene(models[i].path));
    } catch (const InputError& e) {
      throw InputError(std::string("--add: ") + e.what());
    }
  }
  // Every triangle the joined scene will hold, before any is joined.
  uint64_t triangles = scene.triangleCount();
  for (size_t f = 0; f < files.size(); ++f) triangles += uint64_t(loaded[f].triangleCount()) * uses[f];
  const std::string problem = scene_internal::triangleBudgetProblem(triangles);
  if (!problem.empty()) {
    throw InputError("--add: the scene and its " + std::to_string(models.size()) +
                     " added objects make " + problem + " (" +
                     formatCount(scene.triangleCount()) + " in the scene; add fewer or smaller " +
                     "models)");
  }
  // The first copy of a model brings its textures; the others share them.
  std::vector<int> texturesOf(files.size(), -1);
  for (size_t i = 0; i < models.size(); ++i) {
    const size_t f = fileOf[i];
    const int shared = texturesOf[f];
    if (shared < 0) texturesOf[f] = int(scene.textures.size());
    if (--uses[f] == 0) {
      joinModel(scene, std::move(loaded[f]), models[i].placement, shared);
    } else {
      std::vector<Texture> textures = std::move(loaded[f].textures);
      Scene copy = loaded[f];
      if (shared < 0) copy.textures = std::move(textures);
      joinModel(scene, std::move(copy), models[i].placement, shared);
    }
  }
}

}  // namespace lo
