/// @file distributed/rank_agreement.cpp
/// @brief The ranks of a distributed bake agree on what they bake
/// (distributed/rank_agreement.h).

#include "distributed/rank_agreement.h"

#include <string>
#include <vector>

#include "core/error.h"
#include "core/fnv.h"
#include "distributed/mpi_session.h"

namespace lo {
namespace {

/// FNV-1a over the bytes of values added one by one (never over a struct's
/// padding).
class Fingerprint {
 public:
  void bytes(const void* data, size_t n) { hash_.bytes(data, n); }
  template <typename T>
  void add(const T& value) {
    bytes(&value, sizeof value);
  }
  void add(const Vec3& v) {
    add(v.x);
    add(v.y);
    add(v.z);
  }
  uint64_t value() const { return hash_.value(); }

 private:
  Fnv1a64 hash_;
};

/// "1, 3" for the ranks whose value differs from rank 0's.
std::string ranksThatDiffer(const std::vector<uint64_t>& values) {
  std::string out;
  for (size_t r = 1; r < values.size(); ++r) {
    if (values[r] == values[0]) continue;
    if (!out.empty()) out += ", ";
    out += std::to_string(r);
  }
  return out;
}

}  // namespace

uint64_t bakeSettingsFingerprint(const BakeParams& p, const TileParams& tiles) {
  Fingerprint f;
  f.add(p.depth);
  f.add(uint64_t(p.photons));
  f.add(p.targetError);
  f.add(p.targetSeenLight);
  f.add(uint64_t(p.maxPhotons));
  f.add(p.maxSeconds);
  f.add(p.knn);
  f.add(p.radius);
  f.add(p.vdls.count);
  f.add(p.vdls.automatic);
  f.add(p.autoCap);
  f.add(p.autoThreshold);
  f.add(int(p.representation));
  f.add(p.seed);
  f.add(p.includeDirect);
  f.add(p.keepPhotons);
  f.add(p.layers);
  f.add(p.occlusion);
  f.add(p.edgeCorrection);
  f.add(p.separateCaustics);
  f.add(p.smoothing);
  f.add(p.freeSpace);
  f.add(p.freeSpaceLevels);
  f.add(p.freeSpaceOrder);
  f.add(uint64_t(p.freeSpaceRays));
  f.add(p.region.lower);
  f.add(p.region.upper);
  f.add(tiles.tilesPerAxis);
  f.add(uint64_t(tiles.owner.size()));
  for (int32_t o : tiles.owner) f.add(o);
  f.add(tiles.assumedMarginVoxels);
  return f.value();
}

uint64_t sceneFingerprint(const Scene& scene) {
  Fingerprint f;
  f.add(uint64_t(scene.positions.size()));
  for (const Vec3& p : scene.positions) f.add(p);
  f.add(uint64_t(scene.indices.size()));
  f.bytes(scene.indices.data(), scene.indices.size() * sizeof(scene.indices[0]));
  f.add(uint64_t(scene.triangleMaterial.size()));
  f.bytes(scene.triangleMaterial.data(),
          scene.triangleMaterial.size() * sizeof(scene.triangleMaterial[0]));
  // What the photons read at a hit: shading normals, UVs, vertex colours.
  auto floats = [&f](const std::vector<float>& v) {
    f.add(uint64_t(v.size()));
    f.bytes(v.data(), v.size() * sizeof(float));
  };
  f.add(uint64_t(scene.normals.size()));
  for (const Vec3& n : scene.normals) f.add(n);
  floats(scene.texcoords0);
  floats(scene.texcoords1);
  floats(scene.colors);
  f.add(uint64_t(scene.materials.size()));
  auto transform = [&f](const TextureTransform& t) {
    f.add(t.offset[0]);
    f.add(t.offset[1]);
    f.add(t.rotation);
    f.add(t.scale[0]);
    f.add(t.scale[1]);
  };
  for (const Material& m : scene.materials) {
    f.add(m.baseColor);
    f.add(m.baseAlpha);
    f.add(int(m.alphaMode));
    f.add(m.alphaCutoff);
    f.add(m.emission);
    f.add(m.metallic);
    f.add(m.roughness);
    f.add(m.transmission);
    f.add(m.ior);
    f.add(m.thickness);
    f.add(m.specular);
    f.add(m.doubleSided);
    f.add(m.backFaceCulling);
    f.add(m.unlit);
    for (int t : {m.baseColorTexture, m.baseColorTexCoord, m.normalTexture, m.normalTexCoord,
                  m.metallicRoughnessTexture, m.metallicRoughnessTexCoord, m.occlusionTexture,
                  m.occlusionTexCoord, m.emissiveTexture, m.emissiveTexCoord}) {
      f.add(t);
    }
    f.add(m.normalScale);
    f.add(m.occlusionStrength);
    for (const TextureTransform* t : {&m.baseColorTransform, &m.normalTransform,
                                      &m.metallicRoughnessTransform, &m.occlusionTransform,
                                      &m.emissiveTransform}) {
      transform(*t);
    }
  }
  // Every texel: another albedo.png under the same name is another scene.
  auto texels = [&f](const Texture& t) {
    f.add(t.width);
    f.add(t.height);
    f.add(t.channels);
    f.add(int(t.format));
    f.add(t.srgb);
    f.add(uint64_t(t.unorm8.size()));
    f.bytes(t.unorm8.data(), t.unorm8.size());
    f.add(uint64_t(t.unorm16.size()));
    f.bytes(t.unorm16.data(), t.unorm16.size() * sizeof(uint16_t));
    f.add(uint64_t(t.floats.size()));
    f.bytes(t.floats.data(), t.floats.size() * sizeof(float));
  };
  f.add(uint64_t(scene.textures.size()));
  for (const Texture& t : scene.textures) texels(t);
  f.add(uint64_t(scene.lights.size()));
  for (const Light& l : scene.lights) {
    f.add(int(l.type));
    f.add(l.position);
    f.add(l.direction);
    f.add(l.color);
    f.add(l.intensity);
    f.add(l.range);
    f.add(l.innerConeAngle);
    f.add(l.outerConeAngle);
  }
  f.add(scene.sky.radiance);
  f.add(bool(scene.sky.image));
  if (scene.sky.image) texels(*scene.sky.image);
  return f.value();
}

void checkRanksSucceeded(Communicator& comm, const std::string& failure) {
  if (comm.size() < 2) {
    if (!failure.empty()) throw InputError(failure);
    return;
  }
  const std::vector<uint64_t> failed = comm.allgather(failure.empty() ? 0 : 1);
  int first = -1;
  for (size_t r = 0; r < failed.size() && first < 0; ++r) {
    if (failed[r]) first = int(r);
  }
  if (first < 0) return;
  // Rank 0 is the one that speaks: it needs the first failing rank's words.
  const std::vector<std::vector<char>> messages =
      comm.gatherBytes(std::vector<char>(failure.begin(), failure.end()), 0);
  std::string message = "a rank failed";
  if (comm.rank() == 0) {
    const std::vector<char>& m = messages[size_t(first)];
    message = (first == 0 ? "" : "rank " + std::to_string(first) + ": ") +
              std::string(m.begin(), m.end());
  }
  throw RanksRefuseError(message);
}

bool refuseBakeRanks(const std::string& given, std::string& message) {
  MpiSession session;
  if (session.world().size() < 2) return false;
  const int rank = session.world().rank();
  try {
    checkRanksSucceeded(session.world(),
                        "`lightoctree " + given +
                            "` given, not `bake`: under mpirun every rank runs the same "
                            "`lightoctree bake`, the one command that runs on several ranks");
  } catch (const InputError& e) {  // always: the step above failed here
    message = rank == 0 ? e.what() : "";
  }
  return true;
}

void checkRanksAgree(const Scene& scene, const BakeParams& params, const TileParams& tiles,
                     Communicator& comm, const std::string& outputs) {
  if (comm.size() < 2) return;
  const std::vector<uint64_t> settings = comm.allgather(bakeSettingsFingerprint(params, tiles));
  const std::vector<uint64_t> scenes = comm.allgather(sceneFingerprint(scene));
  Fingerprint outputNames;
  outputNames.bytes(outputs.data(), outputs.size());
  const std::vector<uint64_t> written = comm.allgather(outputNames.value());
  const std::string settingsDiffer = ranksThatDiffer(settings);
  const std::string scenesDiffer = ranksThatDiffer(scenes);
  const std::string outputsDiffer = ranksThatDiffer(written);
  if (settingsDiffer.empty() && scenesDiffer.empty() && outputsDiffer.empty()) return;
  std::string message = "the ranks of this bake do not agree:";
  if (!settingsDiffer.empty()) {
    message += " the settings of rank(s) " + settingsDiffer + " differ from rank 0's;";
  }
  if (!scenesDiffer.empty()) {
    message += " the scene read by rank(s) " + scenesDiffer + " differs from rank 0's;";
  }
  if (!outputsDiffer.empty()) {
    message += " the output files (-o, --stats-json) given to rank(s) " + outputsDiffer +
               " differ from rank 0's, which rank 0 alone writes;";
  }
  message += " every rank must run the same command on the same scene (one mpirun command line, "
             "the scene's files the same on every machine)";
  throw RanksRefuseError(message);
}

}  // namespace lo
