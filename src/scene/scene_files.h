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

}  // namespace lo
