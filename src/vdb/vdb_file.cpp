// .vdb files as files: opening one whole (in a child process first), writing
// one grid by grid with a deterministic identity, and the light grid's file
// metadata both ways (docs/vdb-contract.md).

#include <openvdb/io/File.h>
#include <openvdb/io/GridDescriptor.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "core/isolate.h"
#include "core/resources.h"
#include "vdb/vdb_contract.h"
#include "vdb/vdb_file.h"

namespace lo {
namespace vdb_internal {

void initOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

std::string clipped(const std::string& text) {
  constexpr size_t kMax = 400;
  if (text.size() <= kMax) return text;
  return text.substr(0, kMax) + "... (" + std::to_string(text.size() - kMax) + " more characters)";
}

IsolationLimits readLimits(uintmax_t fileBytes) {
  IsolationLimits limits;
  limits.memoryBytes = kReadMemoryBaseBytes + size_t(kReadMemoryPerFileByte * double(fileBytes));
  limits.seconds = kReadSecondsBase + double(fileBytes) * kReadSecondsPerByte;
  return limits;
}

namespace {

/// An anonymous file in memory that a forked child writes and its parent
/// reads (closed with the object), both through its /proc/self/fd name.
struct MemoryFile {
  int fd = ::memfd_create("lightoctree-vdb", MFD_CLOEXEC);
  ~MemoryFile() {
    if (fd >= 0) ::close(fd);
  }
  std::string name() const { return "/proc/self/fd/" + std::to_string(fd); }
};

/// The refusal of a file OpenVDB could not read. One that starts as a .vdb
/// (OpenVDB's magic number) is damaged or truncated, whatever OpenVDB says
/// of it ("Grid type  is not registered" for a cut grid file, a count of
/// 2^64 - 1 bytes for a cut photon map); another is likely not a .vdb.
InputError unreadable(const std::string& path, const std::string& what) {
  const char kMagic[8] = {0x20, 0x42, 0x44, 0x56, 0, 0, 0, 0};  // int64 0x56444220
  char head[8] = {};
  std::ifstream in(path, std::ios::binary);
  const bool vdb = in.read(head, sizeof head) && std::memcmp(head, kMagic, sizeof head) == 0;
  return InputError(path + ": cannot read as an OpenVDB file: " +
                    (vdb ? "damaged or truncated (it starts as a .vdb, then OpenVDB fails: " +
                               clipped(what) + ")"
                         : clipped(what)));
}

}  // namespace

OpenedFile openFile(const std::string& path) {
  initOpenVdb();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path + ": file does not exist");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": not a regular file");
  // OpenVDB trusts the sizes a file states: a damaged file can make it
  // allocate gigabytes, loop for minutes or corrupt the heap. A child
  // process reads it under limits and hands back the grids it built,
  // written anew by OpenVDB's own writer (every size and offset derived
  // from the trees in memory): the parent never reads the file's own bytes
  // (docs/robustness.md, "Reading untrusted files").
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  const IsolationLimits limits = readLimits(ec ? 0 : bytes);
  const MemoryFile handover;
  // OpenVDB says only "could not open file" when the open fails (too many
  // open files, a permission taken away): the open is tried first, and its
  // failure reported with the system's reason (exit code 2 of the child).
  constexpr int kCannotOpen = 2;
  // The grids cross in a file in memory, which a file-size limit (ulimit -f)
  // counts: the child lifts its own soft limit to the hard one (it writes
  // nothing else), and past the hard one says so (exit code 3): a healthy
  // grid was called damaged.
  constexpr int kBeyondFileSizeLimit = 3;
  auto trialRead = [&](std::string& message) {
    struct rlimit fileSize {};
    if (::getrlimit(RLIMIT_FSIZE, &fileSize) == 0 && fileSize.rlim_cur != fileSize.rlim_max) {
      fileSize.rlim_cur = fileSize.rlim_max;
      ::setrlimit(RLIMIT_FSIZE, &fileSize);
    }
    try {
      requireOpenable(path);
    } catch (const IoError& e) {
      message = e.what();
      return kCannotOpen;
    }
    openvdb::io::File file(path);
    file.open(false);
    openvdb::MetaMap::Ptr meta = file.getMetadata();
    openvdb::GridPtrVecPtr grids = file.getGrids();
    file.close();
    std::ofstream os(handover.name(), std::ios_base::out | std::ios_base::binary | std::ios_base::trunc);
    openvdb::io::Stream out(os);
    out.setCompression(openvdb::io::COMPRESS_ACTIVE_MASK);  // no zip: it only crosses memory
    out.write(*grids, *meta);
    os.close();
    if (os.fail()) {
      const int error = errno;
      if (error == EFBIG && ::getrlimit(RLIMIT_FSIZE, &fileSize) == 0 &&
          fileSize.rlim_max != RLIM_INFINITY) {
        message = path + ": not read: its grids cross from the reading process in a file in " +
                  "memory, which the file-size limit (ulimit -f: " +
                  formatBytes(size_t(fileSize.rlim_max)) + ") does not hold: raise it";
        return kBeyondFileSizeLimit;
      }
      message = std::string("cannot hand the grids back: ") + std::strerror(error);
      return 1;
    }
    return 0;
  };
  IsolatedRun trial = handover.fd >= 0 ? runIsolated(trialRead, limits) : IsolatedRun{};
  // A child forked from a process with other threads can, rarely, wait
  // forever on a lock one of them held at the fork: a wait past the time
  // limit, or a crash, is tried once more before the file is refused (a
  // damaged file fails again). A child that spent its whole CPU time reading
  // was not waiting: the file is refused at once.
  if ((trial.outcome == IsolatedRun::Outcome::TimedOut && !trial.usedItsCpu) ||
      trial.outcome == IsolatedRun::Outcome::Crashed) {
    trial = runIsolated(trialRead, limits);
  }
  if (trial.outcome == IsolatedRun::Outcome::Finished && trial.exitCode == kCannotOpen) {
    throw IoError(trial.message);
  }
  if (trial.outcome == IsolatedRun::Outcome::Finished && trial.exitCode == kBeyondFileSizeLimit) {
    throw InputError(trial.message);
  }
  if (trial.outcome == IsolatedRun::Outcome::Finished && trial.exitCode != 0) {
    throw unreadable(path, trial.message);
  }
  // Out of memory under the process's own limit (ulimit -v) says nothing
  // about the file: a valid one was called damaged.
  if (trial.outOfTheProcessMemory(limits)) {
    throw InputError(path + ": not read: reading it " + trial.ToString(limits));
  }
  if (trial.outcome != IsolatedRun::Outcome::Finished &&
      trial.outcome != IsolatedRun::Outcome::NotIsolated) {
    throw InputError(path + ": damaged or not an OpenVDB file: reading it " +
                     trial.ToString(limits));
  }
  if (trial.outcome == IsolatedRun::Outcome::NotIsolated) requireOpenable(path);
  std::ifstream is;
  if (trial.outcome == IsolatedRun::Outcome::Finished) {
    is.open(handover.name(), std::ios_base::in | std::ios_base::binary);
    if (!is) {
      throw IoError(path + ": cannot open the grids read from it (" + handover.name() +
                    "): " + openFailureText(errno));
    }
  }
  OpenedFile f;
  try {
    if (trial.outcome == IsolatedRun::Outcome::Finished) {
      // The child's grids, as OpenVDB's writer wrote them.
      openvdb::io::Stream stream(is, /*delayLoad=*/false);
      f.meta = stream.getMetadata();
      f.grids = stream.getGrids();
    } else {
      // No child could be started (fork failed): read here, as before.
      openvdb::io::File file(path);
      // No delayed loading: every read error surfaces here, inside the try,
      // rather than on first access to a leaf.
      file.open(false);
      f.meta = file.getMetadata();
      f.grids = file.getGrids();
      file.close();
    }
  } catch (const std::exception& e) {
    // The child's grids are whole (OpenVDB's writer made them): failing to
    // take them is this process's want of memory (ulimit -v), not damage.
    if (trial.outcome == IsolatedRun::Outcome::Finished &&
        std::strstr(e.what(), "bad_alloc") != nullptr) {
      throw InputError(path + ": not read: this process ran out of memory taking its grids: " +
                       memoryShortfall());
    }
    throw unreadable(path, e.what());
  }
  if (!f.grids || !f.meta) throw InputError(path + ": cannot read as an OpenVDB file");
  return f;
}

openvdb::GridBase::Ptr findGrid(const OpenedFile& f, const std::string& name) {
  for (const auto& g : *f.grids) {
    if (g && g->getName() == name) return g;
  }
  return nullptr;
}

bool isFreeSpaceGrid(const std::string& name) { return name.rfind("volume_", 0) == 0; }

GridsCheck sameTransform(const OpenedFile& f) {
  const openvdb::GridBase* ref[2] = {nullptr, nullptr};
  for (const auto& g : *f.grids) {
    if (!g) continue;
    const openvdb::GridBase*& r = ref[isFreeSpaceGrid(g->getName()) ? 1 : 0];
    if (!r) {
      r = g.get();
    } else if (!(g->transform() == r->transform())) {
      return {false, "grid '" + g->getName() + "' differs from '" + r->getName() + "'"};
    }
  }
  return {true, ref[1] ? "every grid on one transform, the free-space grids on theirs"
                       : "every grid on one transform"};
}

namespace {

/// Which active set a grid shares: the voxels' (0), or surface layer l's
/// (layer 0's points go with layer 1: the voxels that have layers).
int layerGroup(const std::string& name) {
  if (name == gridNameOf(&VdlGrid::points)) return 1;
  if (name.rfind("layer", 0) == 0 && name.size() > 6 && name[6] == '_' && name[5] >= '1' &&
      name[5] <= '9') {
    return name[5] - '0';
  }
  return 0;
}

/// The VDL grids of one slot ("vdl2", "layer1_vdl0"): active where the
/// voxel (or layer) has that VDL (sparse since format version 2).
std::string vdlSlot(const std::string& name) {
  const size_t at = name.find("vdl");
  if (at == std::string::npos || (at != 0 && at != 7)) return "";
  const size_t under = name.find('_', at);
  if (under == std::string::npos || under == at + 3) return "";
  const std::string tail = name.substr(under);
  if (tail != "_irradiance" && tail != "_direction") return "";
  return name.substr(0, under);
}

}  // namespace

GridsCheck sameActiveVoxels(const OpenedFile& f) {
  std::map<std::string, const openvdb::GridBase*> ref;
  std::string counts;
  for (const auto& g : *f.grids) {
    if (!g) continue;
    const std::string slot = vdlSlot(g->getName());
    const int group = layerGroup(g->getName());
    const bool volume = isFreeSpaceGrid(g->getName());
    const std::string key =
        volume ? "volume" : !slot.empty() ? slot : "layer" + std::to_string(group);
    const openvdb::GridBase*& r = ref[key];
    if (!r) {
      r = g.get();
      if (volume) {
        counts += (counts.empty() ? "" : ", ") + std::to_string(g->activeVoxelCount()) +
                  " in every free-space grid";
      } else if (slot.empty()) {
        counts += (counts.empty() ? "" : ", ") + std::to_string(g->activeVoxelCount()) +
                  (group == 0 ? " in every voxel grid"
                              : " in every layer" + std::to_string(group) + " grid");
      }
    } else if (g->activeVoxelCount() != r->activeVoxelCount() ||
               g->evalActiveVoxelBoundingBox() != r->evalActiveVoxelBoundingBox()) {
      return {false, "grid '" + g->getName() + "' has " + std::to_string(g->activeVoxelCount()) +
                         " active voxels, '" + r->getName() + "' " +
                         std::to_string(r->activeVoxelCount())};
    }
  }
  return {true, counts.empty() ? "no grids" : counts};
}

namespace {

namespace fs = std::filesystem;

/// io::File::write's archive, but each grid is built just before it is
/// written and freed after: the bytes io::Archive::write gives a file of
/// grids with distinct names (header, file metadata, grid count, then each
/// grid's descriptor, offsets and data), without every grid in memory at
/// once (a depth-8 Cornell box's grids take ~1 KB per voxel in OpenVDB's
/// dense 8^3 leaves).
class GridByGridArchive : public openvdb::io::Archive {
 public:
  void writeGrids(std::ostream& os, const std::vector<GridSource>& sources,
             const openvdb::MetaMap& meta) const {
    openvdb::io::StreamMetadata::Ptr streamMetadata(new openvdb::io::StreamMetadata);
    openvdb::io::setStreamMetadataPtr(os, streamMetadata, /*transfer=*/false);
    openvdb::io::setDataCompression(os, compression());
    openvdb::io::setWriteGridStatsMetadata(os, isGridStatsMetadataEnabled());
    writeHeader(os, /*seekable=*/true);
    meta.writeMeta(os);
    const int32_t count = int32_t(sources.size());
    os.write(reinterpret_cast<const char*>(&count), sizeof count);
    std::set<std::string> names;
    for (const GridSource& source : sources) {
      openvdb::GridBase::ConstPtr grid = source.make();
      // Archive::write would rename a repeated or empty name.
      LO_CHECK(!grid->getName().empty() && names.insert(grid->getName()).second);
      openvdb::io::GridDescriptor descriptor(grid->getName(), grid->type(),
                                             grid->saveFloatAsHalf());
      writeGrid(descriptor, grid, os, /*seekable=*/true);
      openvdb::io::setDataCompression(os, compression());
    }
  }
};

}  // namespace

// Writes through a temporary file (core/file.h), grid by grid: a reader
// never sees a half file.
void writeVdbFile(const std::string& path, const std::vector<GridSource>& sources,
                  const openvdb::MetaMap& meta, AtomicFileSet* into) {
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent)) {
    throw IoError(path + ": cannot write: folder '" + parent.string() + "' does not exist");
  }
  const auto write = [&](const std::string& tmp) {
    {
      std::ofstream file(tmp, std::ios_base::out | std::ios_base::binary);
      if (!file) throw std::runtime_error("cannot open the file: " + openFailureText(errno));
      GridByGridArchive().writeGrids(file, sources, meta);
      file.close();
      if (file.fail()) throw std::runtime_error(std::string("cannot write the file: ") + std::strerror(errno));
    }
    makeUuidDeterministic(tmp);
  };
  writeOutput(into, path, write);
}

// ---------------------------------------------------------------------------
// The file metadata.

openvdb::MetaMap fileMetadata(const BakeMetadata& meta, const VdlGrid& grid) {
  openvdb::MetaMap m;
  m.insertMeta("generator", openvdb::StringMetadata(meta.generator));
  m.insertMeta("version", openvdb::StringMetadata(meta.version));
  m.insertMeta("source_scene", openvdb::StringMetadata(meta.sourceScene));
  if (!meta.sourceScenePath.empty())
    m.insertMeta("source_scene_path", openvdb::StringMetadata(meta.sourceScenePath));
  if (!meta.sourceSceneHash.empty())
    m.insertMeta("source_scene_hash", openvdb::StringMetadata(meta.sourceSceneHash));
  if (!meta.skyHash.empty()) m.insertMeta("sky_hash", openvdb::StringMetadata(meta.skyHash));
  // The frame the coordinates are in, for tools that would guess (Blender is
  // Z up): the scene file's, and a glTF's is Y up, right-handed, metres.
  m.insertMeta("up_axis", openvdb::StringMetadata("+Y"));
  m.insertMeta("handedness", openvdb::StringMetadata("right"));
  m.insertMeta("units", openvdb::StringMetadata("the scene file's (glTF: metres)"));
  // The grid's own frame is the truth for depth; see the check in writeVdlGrid.
  m.insertMeta(kMetaDepth, openvdb::Int32Metadata(grid.frame.depth));
  m.insertMeta("photons", openvdb::Int64Metadata(meta.photons));
  m.insertMeta("emitted_paths", openvdb::Int64Metadata(meta.emittedPaths));
  // 0: not recorded (a grid made in code); a reader refuses a recorded 0.
  if (meta.knn != 0) m.insertMeta("knn", openvdb::Int32Metadata(meta.knn));
  if (meta.radius != 0) m.insertMeta("radius", openvdb::FloatMetadata(meta.radius));
  m.insertMeta("vdls", openvdb::StringMetadata(meta.vdls));
  m.insertMeta("seed", openvdb::Int64Metadata(meta.seed));
  m.insertMeta("scene_bounds_min", openvdb::Vec3SMetadata(toVdb(meta.sceneBounds.lower)));
  m.insertMeta("scene_bounds_max", openvdb::Vec3SMetadata(toVdb(meta.sceneBounds.upper)));
  m.insertMeta("units", openvdb::StringMetadata(meta.units));
  const Vec3d& o = grid.frame.offset;
  if (o.x != 0 || o.y != 0 || o.z != 0) {
    m.insertMeta("scene_origin", openvdb::Vec3DMetadata(openvdb::Vec3d(o.x, o.y, o.z)));
  }
  m.insertMeta(kMetaMaxVdls, openvdb::Int32Metadata(grid.maxVdls));
  // The lowest version that holds the file (lightgrid/vdl_grid.h).
  m.insertMeta(kMetaFormatVersion, openvdb::Int32Metadata(grid.shTerms > 0 ? kVdlFormatVersion
                                                                          : kVdlFormatVersionVdl));
  if (grid.shTerms > 0) {
    m.insertMeta(kMetaRepresentation,
                 openvdb::StringMetadata(representationName(grid.representation())));
  }
  if (!meta.convertedFrom.empty()) {
    m.insertMeta("converted_from", openvdb::StringMetadata(meta.convertedFrom));
  }
  if (meta.surfaceLayers >= 0) m.insertMeta("surface_layers", openvdb::Int32Metadata(meta.surfaceLayers));
  if (meta.gatherOcclusion >= 0) {
    m.insertMeta("gather_occlusion", openvdb::Int32Metadata(meta.gatherOcclusion));
  }
  if (meta.edgeCorrection >= 0) m.insertMeta("edge_correction", openvdb::Int32Metadata(meta.edgeCorrection));
  if (meta.includeDirect >= 0) m.insertMeta("include_direct", openvdb::Int32Metadata(meta.includeDirect));
  if (!meta.region.empty()) {
    m.insertMeta("region_min", openvdb::Vec3SMetadata(toVdb(meta.region.lower)));
    m.insertMeta("region_max", openvdb::Vec3SMetadata(toVdb(meta.region.upper)));
  }
  return m;
}

namespace {

template <typename T>
T metaValue(const std::string& path, const openvdb::MetaMap& meta, const std::string& key,
            bool required, T fallback) {
  openvdb::Metadata::ConstPtr m = meta[key];
  if (!m) {
    if (required) throw InputError(path + ": missing file metadata '" + key + "'");
    return fallback;
  }
  auto typed = openvdb::DynamicPtrCast<const openvdb::TypedMetadata<T>>(m);
  if (!typed) {
    // Integers of the other width (pyopenvdb writes every Python int as
    // int32 when it fits, and int64 otherwise): the same value.
    if constexpr (std::is_same_v<T, int64_t>) {
      if (auto narrow = openvdb::DynamicPtrCast<const openvdb::Int32Metadata>(m)) {
        return int64_t(narrow->value());
      }
    }
    if constexpr (std::is_same_v<T, int32_t>) {
      if (auto wide = openvdb::DynamicPtrCast<const openvdb::Int64Metadata>(m)) {
        if (wide->value() >= std::numeric_limits<int32_t>::min() &&
            wide->value() <= std::numeric_limits<int32_t>::max()) {
          return int32_t(wide->value());
        }
      }
    }
    // Floats of the other width: pyopenvdb writes every Python float as a
    // double and every tuple of them as a vec3d, so a file read and written
    // back unchanged in Python holds doubles where we wrote floats; a file
    // another tool wrote may hold floats where we wrote doubles.
    auto narrowed = [&](double v) {
      if (std::isfinite(v) && std::fabs(v) > double(std::numeric_limits<float>::max())) {
        throw InputError(path + ": file metadata '" + key + "' = " + std::to_string(v) +
                         " is beyond the range of a float");
      }
      return float(v);
    };
    if constexpr (std::is_same_v<T, float>) {
      if (auto wide = openvdb::DynamicPtrCast<const openvdb::DoubleMetadata>(m)) {
        return narrowed(wide->value());
      }
    }
    if constexpr (std::is_same_v<T, double>) {
      if (auto narrow = openvdb::DynamicPtrCast<const openvdb::FloatMetadata>(m)) {
        return double(narrow->value());
      }
    }
    if constexpr (std::is_same_v<T, openvdb::Vec3s>) {
      if (auto wide = openvdb::DynamicPtrCast<const openvdb::Vec3DMetadata>(m)) {
        const openvdb::Vec3d v = wide->value();
        return openvdb::Vec3s(narrowed(v.x()), narrowed(v.y()), narrowed(v.z()));
      }
    }
    if constexpr (std::is_same_v<T, openvdb::Vec3d>) {
      if (auto narrow = openvdb::DynamicPtrCast<const openvdb::Vec3SMetadata>(m)) {
        const openvdb::Vec3s v = narrow->value();
        return openvdb::Vec3d(double(v.x()), double(v.y()), double(v.z()));
      }
    }
    throw InputError(path + ": file metadata '" + key + "' has type " + m->typeName() +
                     ", expected " + openvdb::typeNameAsString<T>());
  }
  return typed->value();
}

}  // namespace

int32_t metaInt(const std::string& path, const openvdb::MetaMap& m, const std::string& key,
                bool required, int32_t fallback) {
  return metaValue<int32_t>(path, m, key, required, fallback);
}

int32_t metaOnOff(const std::string& path, const openvdb::MetaMap& m, const std::string& key) {
  // Any other integer was read as off (include_direct = 7 hid render's
  // warning that the direct light is counted twice).
  const int32_t v = metaValue<int32_t>(path, m, key, false, -1);
  if (m[key] && v != 0 && v != 1) {
    throw InputError(path + ": file metadata '" + key + "' = " + std::to_string(v) +
                     " is neither 0 (off) nor 1 (on)");
  }
  return v;
}

FormatVersion formatVersionOf(const openvdb::MetaMap& m) {
  FormatVersion out;
  if (!m[kMetaFormatVersion]) {
    out.absent = true;
    return out;
  }
  try {
    out.version = metaValue<int32_t>("", m, kMetaFormatVersion, true, 0);
  } catch (const InputError&) {
    out.problem = "file metadata '" + std::string(kMetaFormatVersion) + "' has type " +
                  m[kMetaFormatVersion]->typeName() + ", expected an integer";
    return out;
  }
  if (out.version < 1 || out.version > kVdlFormatVersion) {
    out.problem = std::string(kMetaFormatVersion) + " " + std::to_string(out.version) +
                  " is not supported: this lightoctree (" LO_VERSION
                  ") reads VDL files of format version 1 to " +
                  std::to_string(kVdlFormatVersion) +
                  (out.version > kVdlFormatVersion ? "; use a newer lightoctree" : "");
  }
  return out;
}

BakeMetadata readMetadata(const std::string& path, const openvdb::MetaMap& m) {
  BakeMetadata meta;
  meta.generator = metaValue<std::string>(path, m, "generator", false, "");
  meta.version = metaValue<std::string>(path, m, "version", false, "");
  meta.sourceScene = metaValue<std::string>(path, m, "source_scene", false, "");
  meta.sourceScenePath = metaValue<std::string>(path, m, "source_scene_path", false, "");
  meta.sourceSceneHash = metaValue<std::string>(path, m, "source_scene_hash", false, "");
  meta.skyHash = metaValue<std::string>(path, m, "sky_hash", false, "");
  meta.depth = metaValue<int32_t>(path, m, kMetaDepth, true, 0);
  meta.photons = metaValue<int64_t>(path, m, "photons", false, 0);
  meta.emittedPaths = metaValue<int64_t>(path, m, "emitted_paths", false, 0);
  meta.knn = metaValue<int32_t>(path, m, "knn", false, 0);
  meta.radius = metaValue<float>(path, m, "radius", false, 0.0f);
  meta.vdls = metaValue<std::string>(path, m, "vdls", false, "");
  meta.representation = metaValue<std::string>(
      path, m, kMetaRepresentation, false, representationName(LightRepresentation::Vdl));
  meta.seed = metaValue<int64_t>(path, m, "seed", false, 0);
  meta.sceneBounds.lower = fromVdb(
      metaValue<openvdb::Vec3s>(path, m, "scene_bounds_min", false, openvdb::Vec3s(INFINITY)));
  meta.sceneBounds.upper = fromVdb(
      metaValue<openvdb::Vec3s>(path, m, "scene_bounds_max", false, openvdb::Vec3s(-INFINITY)));
  meta.units = metaValue<std::string>(path, m, "units", false, "");
  const openvdb::Vec3d origin =
      metaValue<openvdb::Vec3d>(path, m, "scene_origin", false, openvdb::Vec3d(0.0));
  if (!origin.isFinite()) throw InputError(path + ": file metadata 'scene_origin' is not finite");
  meta.sceneOrigin = Vec3d(origin.x(), origin.y(), origin.z());
  const FormatVersion version = formatVersionOf(m);
  if (!version.problem.empty()) throw InputError(path + ": " + version.problem);
  meta.formatVersion = version.version;
  meta.convertedFrom = metaValue<std::string>(path, m, "converted_from", false, "");
  // The bake's switches: 0 or 1, -1 when not recorded.
  meta.surfaceLayers = metaOnOff(path, m, "surface_layers");
  meta.gatherOcclusion = metaOnOff(path, m, "gather_occlusion");
  meta.edgeCorrection = metaOnOff(path, m, "edge_correction");
  meta.includeDirect = metaOnOff(path, m, "include_direct");
  meta.region.lower = fromVdb(
      metaValue<openvdb::Vec3s>(path, m, "region_min", false, openvdb::Vec3s(INFINITY)));
  meta.region.upper = fromVdb(
      metaValue<openvdb::Vec3s>(path, m, "region_max", false, openvdb::Vec3s(-INFINITY)));
  // Values the commands rely on, refused when another tool left them out of
  // range: a NaN bound let a depth the voxels do not have through (convert
  // then wrote a grid of the wrong size), a NaN radius was copied on, and
  // a gather of k = 0 neighbours or of radius 0 passed inspect.
  if (m["knn"] && meta.knn < 1) {
    throw InputError(path + ": file metadata 'knn' = " + std::to_string(meta.knn) +
                     " is not a number of neighbours >= 1");
  }
  if (m["radius"] && (!(meta.radius > 0) || !std::isfinite(meta.radius))) {
    throw InputError(path + ": file metadata 'radius' = " + formatNumber(double(meta.radius)) +
                     " is not a finite radius > 0");
  }
  if (meta.photons < 0 || meta.emittedPaths < 0) {
    throw InputError(path + ": file metadata 'photons' or 'emitted_paths' is negative");
  }
  for (const auto& [bounds, name] : {std::pair<const Bounds3*, const char*>{&meta.sceneBounds,
                                                                             "scene_bounds"},
                                     {&meta.region, "region"}}) {
    // The empty bounds a bake without bounds writes (+inf, -inf), or finite ones.
    const bool none = bounds->lower == Vec3(INFINITY) && bounds->upper == Vec3(-INFINITY);
    const bool ordered = isFinite(bounds->lower) && isFinite(bounds->upper) && !bounds->empty();
    if (!none && !ordered) {
      throw InputError(path + ": file metadata '" + name + "_min' and '" + name +
                       "_max' are not finite bounds with min <= max");
    }
  }
  return meta;
}

}  // namespace vdb_internal
}  // namespace lo
