#pragma once
/// @file scene/scene_files.h
/// @brief Every file loading a scene reads: the scene file itself and, for
/// glTF, its external buffers and images; for OBJ, its material libraries
/// and their map_Kd textures. What a command's outputs must never replace
/// (docs/robustness.md, "An output that is an input").

#include <string>
#include <vector>

namespace lo {

/// The files loadScene(path) reads, `path` first, each once, as paths
/// resolved against the scene's folder. Reads only the scene's JSON (or
/// OBJ and MTL text); a file it cannot parse lists what it found so far,
/// and the load that follows says what is wrong. Files named but missing
/// are listed too (an output must not appear in their place either).
std::vector<std::string> sceneFiles(const std::string& path);

/// A hash of the scene's content: FNV-1a (64 bits) over every file of
/// sceneFiles(path) in order, each as its name relative to the scene's
/// folder (none for the scene file itself: a renamed copy is the same
/// scene), its size and its bytes (a missing file as its name and "missing"),
/// written "fnv1a64:" and 16 hex digits. The same files give the same hash
/// wherever they lie; a change to any byte the load reads changes it.
std::string sceneContentHash(const std::string& path);
/// sceneContentHash over `files` (sceneFiles(path), listed once by the caller).
std::string sceneContentHash(const std::string& path, const std::vector<std::string>& files);

/// What the file system says of each of `files` now (device, inode, size and
/// time of the last change, or that it is missing): unchanged while no
/// file of them is written. The load compares it before and after reading.
std::string sceneFilesStamp(const std::vector<std::string>& files);

}  // namespace lo
