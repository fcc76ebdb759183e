#include "test_util.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "core/error.h"
#include "core/resources.h"

namespace lo::test {

std::string sharedScenesDir() { return std::string(LO_SHARED_DIR) + "/scenes"; }
std::string dataDir() { return LO_DATA_DIR; }

std::string outputDir(const std::string& testName) {
  std::filesystem::path p = std::filesystem::path(LO_TEST_OUTPUT_DIR) / testName;
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p.string();
}

Scene oneMaterialScene() {
  Scene scene;
  scene.materials.push_back(Material{});
  return scene;
}

void addQuad(Scene& scene, const Vec3& corner, const Vec3& edgeU, const Vec3& edgeV,
             const Vec3& normal, int material) {
  uint32_t base = uint32_t(scene.positions.size());
  scene.positions.push_back(corner);
  scene.positions.push_back(corner + edgeU);
  scene.positions.push_back(corner + edgeU + edgeV);
  scene.positions.push_back(corner + edgeV);
  bool flip = dot(cross(edgeU, edgeV), normal) < 0;
  uint32_t tris[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (auto& t : tris) {
    if (flip) std::swap(t[1], t[2]);
    for (uint32_t i : t) scene.indices.push_back(base + i);
    scene.triangleMaterial.push_back(material);
  }
}

Light pointLight(const Vec3& position, float intensity, const Vec3& color) {
  Light l;
  l.type = Light::Type::Point;
  l.position = position;
  l.color = color;
  l.intensity = intensity;
  return l;
}

Light sun(const Vec3& direction, float irradiance) {
  Light l;
  l.type = Light::Type::Directional;
  l.direction = normalize(direction);
  l.intensity = irradiance;
  return l;
}

Scene boxWithTwoBlocks(const Bounds3& block1, const Bounds3& block2) {
  Scene scene = oneMaterialScene();
  addClosedBox(scene, {0, 0, 0}, {1, 1, 1}, 0);
  addBlock(scene, block1.lower, block1.upper, 0);
  addBlock(scene, block2.lower, block2.upper, 0);
  return scene;
}

Vec3 randomUnit(Rng& rng) {
  const float z = 2.0f * rng.uniform() - 1.0f;
  const float phi = 2.0f * kPi * rng.uniform();
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

void expectRefusal(const std::function<void()>& run, const std::vector<std::string>& parts) {
  try {
    run();
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const std::string& part : parts) {
      EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
    }
  }
}

void forCosineGrid(int steps, const std::function<void(const Vec3& l, float z)>& at) {
  for (int i = 0; i < steps; ++i) {
    const float u1 = (float(i) + 0.5f) / float(steps);
    const float r = std::sqrt(u1), z = std::sqrt(1.0f - u1);
    for (int j = 0; j < steps; ++j) {
      const float phi = 2.0f * kPi * (float(j) + 0.5f) / float(steps);
      at(Vec3(r * std::cos(phi), r * std::sin(phi), z), z);
    }
  }
}

std::optional<std::string> messageUnderAddressSpaceLimit(size_t headroom,
                                                         const std::function<void()>& run) {
  rlimit saved{};
  if (getrlimit(RLIMIT_AS, &saved) != 0) return std::nullopt;
  const size_t mapped = mappedBytes();
  if (mapped == 0) return std::nullopt;
  rlimit lower = saved;
  lower.rlim_cur = rlim_t(mapped + headroom);
  if (saved.rlim_cur != RLIM_INFINITY && saved.rlim_cur < lower.rlim_cur) return std::nullopt;
  if (setrlimit(RLIMIT_AS, &lower) != 0) return std::nullopt;
  std::string message = "no error";
  try {
    run();
  } catch (const InputError& e) {
    message = e.what();
  } catch (const std::exception& e) {
    message = std::string("not an InputError: ") + e.what();
  }
  setrlimit(RLIMIT_AS, &saved);
  return message;
}

std::string textFromChild(const std::function<std::string()>& child) {
  int channel[2];
  if (pipe(channel) != 0) return "child failed: no pipe";
  const pid_t pid = fork();
  if (pid < 0) return "child failed: no fork";
  if (pid == 0) {
    close(channel[0]);
    const std::string text = child();
    if (write(channel[1], text.data(), text.size()) < 0) std::_Exit(3);
    std::_Exit(0);
  }
  close(channel[1]);
  std::string text;
  char buffer[256];
  for (ssize_t r; (r = read(channel[0], buffer, sizeof buffer)) > 0;) text.append(buffer, size_t(r));
  close(channel[0]);
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return "child failed: not waited for";
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    return "child failed: status " + std::to_string(status) + ", said '" + text + "'";
  }
  return text;
}

std::string runCommand(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return out;
  char buffer[4096];
  size_t got;
  while ((got = fread(buffer, 1, sizeof(buffer), pipe)) > 0) out.append(buffer, got);
  pclose(pipe);
  return out;
}

void addClosedBox(Scene& scene, const Vec3& lo, const Vec3& hi, int material) {
  Vec3 d = hi - lo;
  Vec3 ex{d.x, 0, 0}, ey{0, d.y, 0}, ez{0, 0, d.z};
  addQuad(scene, lo, ex, ez, {0, 1, 0}, material);                      // floor, facing up
  addQuad(scene, lo + ey, ex, ez, {0, -1, 0}, material);                // ceiling, facing down
  addQuad(scene, lo, ey, ez, {1, 0, 0}, material);                      // x = lo, facing +x
  addQuad(scene, lo + ex, ey, ez, {-1, 0, 0}, material);                // x = hi, facing -x
  addQuad(scene, lo, ex, ey, {0, 0, 1}, material);                      // z = lo, facing +z
  addQuad(scene, lo + ez, ex, ey, {0, 0, -1}, material);                // z = hi, facing -z
}

void addBlock(Scene& scene, const Vec3& lo, const Vec3& hi, int material) {
  Vec3 d = hi - lo;
  Vec3 ex{d.x, 0, 0}, ey{0, d.y, 0}, ez{0, 0, d.z};
  addQuad(scene, lo + ey, ex, ez, {0, 1, 0}, material);
  addQuad(scene, lo, ey, ez, {-1, 0, 0}, material);
  addQuad(scene, lo + ex, ey, ez, {1, 0, 0}, material);
  addQuad(scene, lo, ex, ey, {0, 0, -1}, material);
  addQuad(scene, lo + ez, ex, ey, {0, 0, 1}, material);
}

std::shared_ptr<const Texture> twoBandSkyImage() {
  std::vector<Vec3> rows;
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) rows.push_back(Vec3(y < 2 ? 4.0f : y < 4 ? 1.0f : 7.0f));
  }
  return std::make_shared<Texture>(Texture::fromLinear(8, 8, rows));
}

Scene sealedRooms() {
  Scene scene;
  Material grey;
  grey.baseColor = Vec3(0.7f);
  scene.materials.push_back(grey);
  addClosedBox(scene, Vec3{0, 0, 0}, Vec3{2, 1, 1}, 0);
  addQuad(scene, Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}, Vec3{-1, 0, 0}, 0);
  addQuad(scene, Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}, Vec3{1, 0, 0}, 0);
  Light light;
  light.position = Vec3{0.5f, 0.7f, 0.5f};
  light.intensity = 1.0f;
  scene.lights.push_back(light);
  return scene;
}

Scene pointLitRoom() {
  Scene scene;
  Material grey;
  grey.baseColor = Vec3(0.6f);
  scene.materials.push_back(grey);
  addClosedBox(scene, Vec3(0.0f), Vec3(1.0f), 0);
  addBlock(scene, Vec3(0.2f, 0.0f, 0.3f), Vec3(0.5f, 0.4f, 0.6f), 0);
  Light light;
  light.position = Vec3(0.5f, 0.8f, 0.5f);
  light.intensity = 1.0f;
  scene.lights.push_back(light);
  return scene;
}

}  // namespace lo::test
