#pragma once
/// @file scene/gltf_prevalidate.h
/// @brief Checks on a glTF file before tinygltf parses it (internal to
/// src/scene). Each throws InputError naming `path` and the problem.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lo::scene_internal {

/// Refuses JSON nested deeper than kMaxJsonDepth (both JSON parsers recurse
/// once per level), counted outside strings.
void checkJsonNesting(const std::string& path, const std::string& text);

/// The parsed JSON's required extensions (each one the loader reads:
/// refused naming it otherwise, where tinygltf would fail on what the
/// extension left out, or load a scene without it), buffers, buffer views
/// and images: indices and sizes in range, external files inside `baseDir`
/// and present.
void prevalidateJson(const std::string& path, const std::string& baseDir, const nlohmann::json& j);

/// The fields the loader reads (a material's factors, a light's colour,
/// intensity and cone, a node's transform, a camera's projection) of the JSON
/// type glTF gives them, and the project's extras keys (lightoctree_*) where
/// they are read: refused naming the JSON pointer and the value
/// ("/extensions/KHR_lights_punctual/lights/0/intensity is \"5\", expected a
/// number"), where tinygltf would take the field as absent. Part of
/// prevalidateJson.
void checkFieldTypes(const std::string& path, const nlohmann::json& j);

/// Whether the loader reads the glTF extension `name` (KHR_lights_punctual,
/// the KHR_materials_* it maps to Material, KHR_texture_transform,
/// KHR_mesh_quantization's integer attributes; the archived
/// KHR_materials_pbrSpecularGlossiness approximately).
bool readsGltfExtension(const std::string& name);

/// Checks the GLB container (https://registry.khronos.org/glTF/specs/2.0/
/// glTF-2.0.html#binary-gltf-layout) and returns the JSON chunk.
std::string glbJson(const std::string& path, const std::vector<unsigned char>& bytes);

/// The first line of a tinygltf message, at most 240 characters (it quotes
/// whole data: URIs).
std::string firstLine(std::string s);

}  // namespace lo::scene_internal
