#pragma once
/// @file scene/gltf_internal.h
/// @brief The glTF loader's pieces (internal to src/scene; loadGltf in
/// scene_internal.h is its entry): GltfReader, which checks each accessor
/// against its bufferView and buffer before it reads a byte, and
/// SceneBuilder, which turns a parsed tinygltf::Model into a Scene. One file
/// per concern:
///   load_gltf.cpp           the document: tinygltf's callbacks, loadGltf,
///                           SceneBuilder::build (the steps in order), rebase
///   gltf_accessors.cpp      GltfReader
///   gltf_materials.cpp      materials, textures and their samplers
///   gltf_nodes.cpp          the node tree: roots, triangle budget, traversal,
///                           region markers
///   gltf_meshes.cpp         primitives and their vertex attributes
///   gltf_lights_cameras.cpp KHR_lights_punctual lights, perspective cameras
///   gltf_sky.cpp            the scene's sky (extras.lightoctree_sky*)
/// tinygltf is included here, and this header only by those files.

// Images are decoded by src/image (decodeImageBytes), the project's one copy
// of stb_image; tinygltf only hands over the encoded bytes (storeEncodedImage).
// Defined here, for every file that includes tinygltf: they change the
// members of its TinyGLTF class. load_gltf.cpp defines TINYGLTF_IMPLEMENTATION
// before it includes this header.
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#include <tiny_gltf.h>

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "scene/gltf_transform.h"
#include "scene/scene_internal.h"

namespace lo::scene_internal::gltf_internal {

// ---------------------------------------------------------------------------
// Accessors.

class GltfReader {
 public:
  GltfReader(const std::string& path, const tinygltf::Model& model) : path_(path), model_(model) {}

  /// Reads accessor `index` as doubles, count * components values, with the
  /// normalization of integer types applied. `type` is the required
  /// TINYGLTF_TYPE_*; `what` names the use in error messages.
  std::vector<double> read(int index, int type, const std::string& what) const;

  /// Reads an index accessor (SCALAR of unsigned byte/short/int).
  std::vector<uint32_t> readIndices(int index, const std::string& what) const;

  size_t count(int index) const;

 private:
  const unsigned char* viewData(int view, const std::string& name) const;

  void readSparse(const tinygltf::Accessor& acc, int comps, int csize, const std::string& name,
                  std::vector<double>& out) const;

  template <typename T>
  static T load(const unsigned char* p);

  /// glTF 2.0 spec, "Animations / normalized integers": c / (2^(n-1) - 1)
  /// clamped at -1 for signed, c / (2^n - 1) for unsigned.
  static double component(const unsigned char* p, int type, bool normalized);

  const std::string& path_;
  const tinygltf::Model& model_;
};

// ---------------------------------------------------------------------------
// Scene assembly.

/// The first three values of `v`, or `fallback` when it holds fewer.
inline Vec3 vec3From(const std::vector<double>& v, const Vec3& fallback) {
  if (v.size() < 3) return fallback;
  return {float(v[0]), float(v[1]), float(v[2])};
}

class SceneBuilder {
 public:
  SceneBuilder(const std::string& path, const tinygltf::Model& model, const std::string& skyMesh)
      : path_(path), model_(model), reader_(path, model), skyMeshFlag_(skyMesh) {}

  Scene build();

 private:
  struct Pending {
    std::vector<Vec3> positions, normals;
    std::vector<float> uv0, uv1;
    bool hasNormals = false, hasUv0 = false, hasUv1 = false;
  };

  // Materials and textures (gltf_materials.cpp).

  void convertMaterials();

  /// KHR_materials_pbrSpecularGlossiness (archived, written by older
  /// exporters) read approximately, as a dielectric: the diffuse factor and
  /// texture as the base colour, 1 - glossiness as the roughness (0.5 where
  /// a specular-glossiness texture holds the glossiness, which is not read),
  /// metallic 0; the specular colour is not read. Warned once per file.
  bool readSpecularGlossiness(const tinygltf::ExtensionMap& extensions, size_t i, Material& m);

  /// A texture reference `what` of material i: its index checked, its
  /// KHR_texture_transform into `transform`, and its texture (sRGB colour
  /// or linear data) into `texture` and `texCoordOut` where it names UV set
  /// 0 or 1 (other sets are not loaded: the factor alone is used). Nothing
  /// for a negative index.
  void textureReference(size_t i, const std::string& what, int index, int texCoord,
                        const tinygltf::ExtensionMap& extensions, bool srgb, int& texture,
                        int& texCoordOut, TextureTransform& transform);

  /// KHR_texture_transform of a texture reference into `out`; its texCoord
  /// overrides `texCoord`. @throws InputError naming the material.
  void readTextureTransform(const tinygltf::ExtensionMap& extensions, size_t i,
                            TextureTransform& tt, int& texCoord);

  /// The sampler of glTF texture `tex` (glTF's defaults where it has none).
  TextureSampler samplerOf(int tex) const;

  int textureFromImage(int source, int tex, bool srgb = true);

  int defaultMaterial();

  // The sky (gltf_sky.cpp).

  /// The sky: the glTF scene's `"extras": {"lightoctree_sky": [r, g, b]}`,
  /// radiance in W/(m^2 sr), and `"lightoctree_sky_image": "sky.hdr"`, an
  /// equirectangular map beside the file that the colour then scales (no
  /// glTF extension describes a sky's radiance; docs/scene.md, "Sky").
  void readSky();

  // The node tree (gltf_nodes.cpp).

  std::vector<int> sceneRoots() const;

  /// The triangles the node tree will make, from the accessors' counts, and
  /// the memory they will take, before any is built: ten thousand nodes
  /// instancing a 200k-triangle mesh are 2e9 triangles, built only to be
  /// refused (32-bit indices) after minutes and gigabytes.
  void checkTriangleBudget();

  void traverse();

  /// A region-of-interest marker: `"extras": {"lightoctree_region": true}`.
  /// Refuses a node matrix whose bottom row is not (0, 0, 0, 1), naming the node.
  void checkAffine(const tinygltf::Node& node, int nodeIndex) const;
  bool isRegionMarker(const tinygltf::Node& node, int nodeIndex) const;

  /// The marker's mesh, loaded like any other for its world-space bounds, then
  /// taken out of the scene again: it marks the region, it is not geometry.
  void addRegion(const tinygltf::Node& node, int nodeIndex, const Mat4& world);

  // Lights and cameras (gltf_lights_cameras.cpp).

  void addCamera(const tinygltf::Node& node, int nodeIndex, const Mat4& world);

  void addLight(const tinygltf::Node& node, int nodeIndex, int lightIndex, const Mat4& world);

  // Meshes and vertex attributes (gltf_meshes.cpp).

  /// `nodeWeights`: the node's morph target weights (glTF: they override
  /// the mesh's), null or empty for the mesh's own.
  void addMesh(int meshIndex, const Mat4& world, const std::vector<double>* nodeWeights = nullptr);
  /// Adds the morph targets of `prim` at `weights` to its positions and
  /// normals (those it has). @throws InputError for a target of another count.
  void morph(const tinygltf::Primitive& prim, const std::vector<double>& weights,
             const std::string& what, size_t nverts, std::vector<double>& pos,
             std::vector<double>& nrm);
  /// Warns once per material and set of a texture on a UV set that the
  /// primitive `what` lacks (`has(set)`).
  void warnMissingUvSets(int material, const std::function<bool(int)>& has,
                         const std::string& what);

  /// Triangle list from TRIANGLES / TRIANGLE_STRIP / TRIANGLE_FAN (glTF 2.0
  /// spec 3.7.2.1); triangles with a repeated index (strip restarts) dropped.
  static std::vector<std::array<uint32_t, 3>> triangulate(const std::vector<uint32_t>& idx,
                                                          int mode);

  void appendNormals(const std::vector<double>& nrm, const Mat4& normalMatrix, size_t nverts,
                     uint32_t base);

  void appendUv(std::vector<float>& dst, bool& has, const std::vector<double>& uv, size_t nverts,
                uint32_t base);

  /// An attribute only some primitives carry, `width` floats a vertex, in
  /// `dst`: from the first primitive that has one (`present`), the vertices
  /// before it get `fill`, as do those of a later primitive without one.
  /// Returns whether this primitive's values are to be appended.
  bool optionalAttribute(std::vector<float>& dst, bool& seen, bool present, uint32_t base,
                         size_t nverts, size_t width, float fill);

  /// TANGENT of a primitive into Scene::tangents (xyz by the node's linear
  /// part, normalised; w flipped with the winding under a mirroring
  /// transform); vertices of primitives without one get w = 0.
  void appendTangents(const std::vector<double>& tan, const Mat4& world, size_t nverts,
                      uint32_t base, bool flip);

  /// COLOR_0 of a primitive (RGB, alpha 1, or RGBA) into Scene::colors,
  /// clamped to [0, 1] (glTF's range); vertices of primitives without one
  /// are white.
  void appendColors(const std::vector<double>& color, size_t nverts, uint32_t base,
                    const std::string& what);

  /// Normals of the vertices that have none in the file (`normalFromFaces_`):
  /// the normalised sum of the face normals (area-weighted) of every
  /// triangle that uses them, whichever primitive it belongs to.
  void finishVertexAttributes();

  /// Refuses a primitive whose `nverts` vertices of its own (not shared)
  /// would take the scene's vertices beyond half the memory available.
  void checkVertexBudget(size_t nverts);

  /// The accessor that reads the same values as accessor `index` (the first
  /// of those with its bufferView, byteOffset, componentType, normalized,
  /// type and count, none sparse), `index` itself otherwise; -1 for -1.
  int sameValues(int index);

  // The finished scene (load_gltf.cpp).

  /// Positions were gathered in double (world_): a scene far from the
  /// origin is stored relative to its centre (Scene::origin), the rest as
  /// the file places it.
  void rebase();

  const std::string& path_;
  const tinygltf::Model& model_;
  GltfReader reader_;
  Scene scene_;
  /// World positions in double, parallel to scene_'s vertices, lights and
  /// cameras, and the region marker's vertices: what rebase() starts from.
  struct {
    std::vector<Vec3d> vertices, lights, cameras, region;
  } world_;
  /// A decoded texture: its image, whether as sRGB colour, its sampler.
  struct TextureKey {
    int image;
    bool srgb;
    TextureSampler sampler;
    bool operator<(const TextureKey& o) const {
      if (image != o.image) return image < o.image;
      if (srgb != o.srgb) return srgb < o.srgb;
      return sampler < o.sampler;
    }
  };
  std::map<TextureKey, int> imageToTexture_;
  /// The vertices already in scene_ per (world transform, the accessors of
  /// POSITION, NORMAL, TANGENT, TEXCOORD_0, TEXCOORD_1, COLOR_0 by
  /// sameValues): their first vertex. Primitives that share a vertex buffer
  /// share its vertices once converted, so the scene's vertices follow the
  /// file and not primitives x buffer (issue 43: 10,000 primitives of one
  /// 4 MB buffer took gigabytes).
  struct VertexBlockKey {
    std::array<double, 16> world;
    std::array<int, 6> accessors;
    bool operator<(const VertexBlockKey& o) const {
      return world != o.world ? world < o.world : accessors < o.accessors;
    }
  };
  std::map<VertexBlockKey, uint32_t> vertexBlocks_;
  std::map<std::array<size_t, 6>, int> accessorValues_;  ///< sameValues' first accessors
  std::vector<int> sameValues_;  ///< per accessor: sameValues, -2 = not yet known
  /// Per vertex of scene_ (once some primitive has normals): 1 where the
  /// file gives no normal, which finishVertexAttributes computes.
  std::vector<uint8_t> normalFromFaces_;
  std::optional<size_t> availableMemory_;  ///< availableMemoryBytes, asked once
  std::string skyMeshFlag_;  ///< the command line's sky mesh (loadScene's skyMesh)
  std::string skyMesh_;    ///< extras.lightoctree_sky_mesh, or the flag's: a material to take as the sky
  bool skyScale_ = false;  ///< extras.lightoctree_sky was given
  float turbidity_ = 0;    ///< extras.lightoctree_physical_sky; 0 = none
  std::set<int> missingImages_;  ///< images whose file is missing, warned once
  /// (material, UV set) pairs whose texture a primitive without that set
  /// uses, warned once.
  std::set<std::pair<int, int>> missingUvSets_;
  std::set<int> morphCountsWarned_;  ///< meshes whose weights and targets differ in count, warned once
  /// Each image's file bytes, kept by the textures that decode it (Texture::encoded).
  std::map<int, std::shared_ptr<const std::vector<uint8_t>>> imageBytes_;
  /// The first image of each source (its file, its data URI, its
  /// bufferView): images that name one source are one image, decoded once.
  std::map<std::string, int> imageBySource_;
  int sharedImage(int image);
  std::vector<PendingTexture> pendingTextures_;  ///< textureFromImage's, for decodeTextures
  int defaultMaterial_ = -1;
  bool hasNormals_ = false, hasUv0_ = false, hasUv1_ = false, hasTangents_ = false,
       hasColors_ = false, warnedSpecularGlossiness_ = false;
};

}  // namespace lo::scene_internal::gltf_internal
