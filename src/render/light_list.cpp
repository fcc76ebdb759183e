// Emissive triangles as the scene shader's lights: area lights, or VPLs
// drawn from the tracers' emitter sampler.

#include "render/light_list.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include "scene/emitter_sampler.h"

namespace lo::render_internal {
namespace {

glm::vec4 toVec4(const Vec3& v, float w) { return {v.x, v.y, v.z, w}; }

/// Base-2 radical inverse of i in [0, 1).
float radicalInverse(uint32_t i) {
  uint32_t bits = i;
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return float(bits) * 2.3283064365386963e-10f;
}

}  // namespace

AreaLightSet areaLights(const Scene& scene, const EmitterSampler& sampler,
                        const RenderSpace& space) {
  // The emissive triangles, a double-sided one as two one-sided ones.
  struct Emitter {
    Vec3 p[3];
    Vec3 emission;
    size_t triangle;
  };
  std::vector<Emitter> emitters;
  for (size_t k = 0; k < sampler.size(); ++k) {
    const size_t t = sampler.triangles[k];
    const int m = scene.triangleMaterial[t];
    const Vec3 emission = sampler.emission[k];
    Emitter e{{space.toRender(scene.positions[scene.indices[t * 3]]),
               space.toRender(scene.positions[scene.indices[t * 3 + 1]]),
               space.toRender(scene.positions[scene.indices[t * 3 + 2]])},
              emission, t};
    emitters.push_back(e);
    if (scene.materials[size_t(m)].doubleSided) {
      std::swap(e.p[1], e.p[2]);
      emitters.push_back(e);
    }
    if (emitters.size() > size_t(shader::LO_MAX_AREA_TRIANGLES)) return {};
  }
  if (emitters.empty()) return {};

  // Groups: triangles that share a corner (by position: a cube's faces
  // have their own vertices) are one light; then the two groups whose
  // merged box is smallest merge until LO_MAX_AREA_LIGHTS are left.
  std::vector<size_t> parent(emitters.size());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto root = [&parent](size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  std::map<std::array<float, 3>, size_t> corners;
  for (size_t i = 0; i < emitters.size(); ++i) {
    for (const Vec3& c : emitters[i].p) {
      auto [it, inserted] = corners.emplace(std::array<float, 3>{c.x, c.y, c.z}, i);
      if (!inserted) parent[root(i)] = root(it->second);
    }
  }
  struct Group {
    std::vector<size_t> members;
    Bounds3 box;
    bool merged = false;  ///< of separate parts (their box holds space between them)
  };
  std::map<size_t, Group> byRoot;
  for (size_t i = 0; i < emitters.size(); ++i) {
    Group& g = byRoot[root(i)];
    g.members.push_back(i);
    for (const Vec3& c : emitters[i].p) g.box.extend(c);
  }
  std::vector<Group> groups;
  for (auto& [r, g] : byRoot) groups.push_back(std::move(g));
  std::sort(groups.begin(), groups.end(),
            [](const Group& a, const Group& b) { return a.members[0] < b.members[0]; });
  while (groups.size() > size_t(shader::LO_MAX_AREA_LIGHTS)) {
    size_t bestA = 0, bestB = 1;
    float best = std::numeric_limits<float>::max();
    for (size_t a = 0; a < groups.size(); ++a) {
      for (size_t b = a + 1; b < groups.size(); ++b) {
        Bounds3 merged = groups[a].box;
        merged.extend(groups[b].box);
        const float size = length(merged.upper - merged.lower);
        if (size < best) best = size, bestA = a, bestB = b;
      }
    }
    groups[bestA].box.extend(groups[bestB].box);
    groups[bestA].merged = true;
    groups[bestA].members.insert(groups[bestA].members.end(), groups[bestB].members.begin(),
                                 groups[bestB].members.end());
    groups.erase(groups.begin() + std::ptrdiff_t(bestB));
  }
  // Where the budget of shadow cubes allows, a flat group (a quad light)
  // gives each of its triangles a cube of its own: two smaller lights
  // sample the penumbra of a large one better than one (the Cornell box's
  // contact shadows: 4.8% against 4.4% of the full picture). A group that
  // faces several ways stays whole: its parts would shadow each other.
  auto facesOneWay = [&emitters](const Group& g) {
    Vec3 facing(0.0f);
    float area = 0;
    for (size_t i : g.members) {
      const Emitter& e = emitters[i];
      const Vec3 c = cross(e.p[1] - e.p[0], e.p[2] - e.p[0]);
      facing += c;
      area += length(c);
    }
    return length(facing) > 0.999f * area;
  };
  for (size_t i = 0; i < groups.size();) {
    const size_t parts = groups[i].members.size();
    if (parts > 1 && groups.size() - 1 + parts <= size_t(shader::LO_MAX_AREA_LIGHTS) &&
        facesOneWay(groups[i])) {
      for (size_t m : groups[i].members) {
        Group one;
        one.members = {m};
        for (const Vec3& c : emitters[m].p) one.box.extend(c);
        groups.push_back(one);
      }
      groups.erase(groups.begin() + std::ptrdiff_t(i));
    } else {
      ++i;
    }
  }
  std::sort(groups.begin(), groups.end(),
            [](const Group& a, const Group& b) { return a.members[0] < b.members[0]; });

  AreaLightSet out;
  const float eps = 1e-3f * space.sceneSize;
  for (Group& g : groups) {
    std::sort(g.members.begin(), g.members.end());
    GpuLight l{};
    double area = 0;
    Vec3 centroid(0.0f), facing(0.0f);
    const int first = int(out.triangles.size() / 3);
    for (size_t i : g.members) {
      const Emitter& e = emitters[i];
      const Vec3 c = cross(e.p[1] - e.p[0], e.p[2] - e.p[0]);
      const float a = 0.5f * length(c);
      area += a;
      centroid += (e.p[0] + e.p[1] + e.p[2]) * (a / 3.0f);
      facing += c * 0.5f;  // the normal times the area
      out.triangles.push_back(toVec4(e.p[0], e.emission.x));
      out.triangles.push_back(toVec4(e.p[1], e.emission.y));
      out.triangles.push_back(toVec4(e.p[2], e.emission.z));
    }
    centroid /= float(area);
    // A flat light (a quad, a panel) is seen from one side: its shadow
    // cube sits just in front of it; a light that faces every way (a
    // cube, a sphere, a double-sided sheet) has it at its centre. Its
    // size for the shadow's penumbra: the side of a square of its
    // silhouette's area (a convex body's mean silhouette is a quarter of
    // its surface).
    const float facingArea = length(facing);
    const bool flat = facingArea > 0.5f * float(area);
    const Vec3 front = flat ? facing / facingArea : Vec3(0.0f);
    l.positionType = toVec4(centroid + front * eps, float(shader::LO_LIGHT_AREA));
    l.directionRange = toVec4(front, 0);
    l.colorFar = toVec4(Vec3(0.0f), 0);
    l.params = toVec4(Vec3(-1, 1, -1), 0);
    // The light's own box, for one connected light that faces every way (a
    // glowing cube around its shadow cube's centre): what lies in it casts no
    // shadow on its light. None (lower > upper) for a flat light, whose cube
    // sits in front of it (its box would hold the space in front of a tilted
    // panel), nor for separate parts merged (the space between them).
    const bool ownBox = !flat && !g.merged;
    l.corner0 = toVec4(ownBox ? g.box.lower - Vec3(eps) : Vec3(1.0f),
                       std::sqrt(std::max(facingArea, float(area) / 4)));
    l.corner1 = toVec4(ownBox ? g.box.upper + Vec3(eps) : Vec3(0.0f), 0);
    l.corner2 = toVec4(Vec3(float(first), float(g.members.size()), 0), 0);
    out.lights.push_back(l);
  }
  return out;
}

std::vector<GpuLight> emitterVpls(const Scene& scene, const EmitterSampler& emitters,
                                  const RenderSpace& space, int count) {
  std::vector<GpuLight> out;
  if (emitters.empty() || count <= 0) return out;
  const double total = emitters.total();
  for (int i = 0; i < count; ++i) {
    double u = (i + 0.5) / count;
    double remapped = 0;
    size_t k = emitters.distribution.sample(u, &remapped);
    size_t t = emitters.triangles[k];
    float s = float(remapped);
    // Second coordinate from the base-2 radical inverse of i.
    float r = radicalInverse(uint32_t(i));
    float su = std::sqrt(std::clamp(s, 0.0f, 1.0f));
    float b1 = su * (1 - r), b2 = su * r;
    const Vec3 p0 = space.toRender(scene.positions[scene.indices[t * 3]]);
    const Vec3 p1 = space.toRender(scene.positions[scene.indices[t * 3 + 1]]);
    const Vec3 p2 = space.toRender(scene.positions[scene.indices[t * 3 + 2]]);
    const bool back = scene.materials[size_t(scene.triangleMaterial[t])].doubleSided && (i & 1);
    Vec3 n = back ? -scene.faceNormal(t) : scene.faceNormal(t);
    Vec3 p = p0 * (1 - b1 - b2) + p1 * b1 + p2 * b2 + n * (1e-3f * space.sceneSize);
    const Vec3 emission = scene.triangleEmission(t);
    // Area this sample stands for: the emitted power shared by count, as
    // one side of a Lambertian patch (power pi L A).
    float area = float(total / (kPi * double(average(emission))) / count);
    GpuLight l{};
    l.positionType = toVec4(p, float(shader::LO_LIGHT_EMITTER));
    l.directionRange = toVec4(n, 0);
    l.colorFar = toVec4(emission * area, 0);
    l.params = toVec4(Vec3(-1, 1, -1), area);
    out.push_back(l);
  }
  return out;
}

}  // namespace lo::render_internal
