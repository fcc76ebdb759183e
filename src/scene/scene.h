#pragma once
/// @file scene/scene.h
/// @brief The scene every later stage reads: triangles in world space,
/// materials, punctual lights and cameras. Loaded from glTF 2.0 (.gltf/.glb)
/// through tinygltf or from OBJ/MTL through tinyobjloader; neither library is
/// visible outside src/scene.
///
/// Units and spaces: positions in scene units (glTF: metres), world space
/// (every node transform already applied). Colours are linear RGB.
/// Light units follow glTF KHR_lights_punctual, read radiometrically with the
/// photometric constant dropped (1 cd == 1 W/sr, 1 lx == 1 W/m^2), and emissive
/// surfaces emit radiance emissiveFactor * emissive_strength (W/(m^2 sr)), so
/// that a 1 cd point light and a 1 W/(m^2 sr) emitter are in the same units.

#include <cstdint>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "core/math.h"
#include "core/number_range.h"

namespace lo {

/// A decoded texture: linear RGB floats, row-major, row 0 at the top
/// (glTF's UV (0,0) is the top-left corner).
/// A glTF sampler: how a texture is filtered and wrapped, in glTF's (and
/// OpenGL's) codes. The GL renderer sets them on its texture; the tracers
/// filter bilinearly unless magFilter is NEAREST (9728) and wrap as asked,
/// at full resolution (no mipmaps: their rays carry no footprint).
struct TextureSampler {
  static constexpr int kNearest = 9728, kLinear = 9729;
  static constexpr int kRepeat = 10497, kClampToEdge = 33071, kMirroredRepeat = 33648;
  int magFilter = kLinear;
  /// glTF minFilter (NEAREST, LINEAR or one of the four *_MIPMAP_*); 0 =
  /// undefined, which the renderer draws as LINEAR_MIPMAP_LINEAR.
  int minFilter = 0;
  int wrapS = kRepeat, wrapT = kRepeat;
  bool operator<(const TextureSampler& o) const {
    return std::tie(magFilter, minFilter, wrapS, wrapT) <
           std::tie(o.magFilter, o.minFilter, o.wrapS, o.wrapT);
  }
};

/// How a Texture keeps its texels: as the image file gives them.
enum class TexelFormat : uint8_t {
  Unorm8,   ///< 8 bits per channel (Texture::unorm8), value / 255
  Unorm16,  ///< 16 bits per channel (Texture::unorm16), value / 65535
  Float32,  ///< floats as they are (Texture::floats): HDR images, textures made in code
};

/// An image as a texture. Texels stay as the file stores them (one byte per
/// channel for the usual 8-bit PNG or JPEG, not 16 bytes of linear floats
/// per texel), and are decoded at each fetch: sRGB colour maps through a
/// 256-entry table (8-bit) or the transfer function (16-bit), so the
/// tracers, the bake and the GL renderer (which uploads 8-bit sRGB texels to
/// an sRGB texture format) read the same linear values.
struct Texture {
  std::string name;
  TextureSampler sampler;
  int width = 0, height = 0;
  /// Channels per texel as stored: 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA.
  /// A grey value is its texel's R, G and B.
  int channels = 0;
  TexelFormat format = TexelFormat::Float32;
  /// The colour channels hold sRGB-encoded values (colour maps of 8- and
  /// 16-bit images): fetches return them linear. Alpha is always linear, as
  /// glTF defines it; data maps (normal, metallic-roughness) are not sRGB.
  bool srgb = false;
  /// width * height * channels values, row 0 first; only the vector of
  /// `format` is filled.
  std::vector<uint8_t> unorm8;
  std::vector<uint16_t> unorm16;
  std::vector<float> floats;
  /// The image file's own bytes and MIME type ("image/png", "image/jpeg"),
  /// when the texture was decoded from a file: what an export embeds again
  /// instead of encoding the texels anew. Shared, as several textures (two
  /// samplers, colour and data) may decode one image.
  std::shared_ptr<const std::vector<uint8_t>> encoded;
  std::string mimeType;

  /// A Float32 texture of linear RGB (width * height values) and, when not
  /// empty, alpha: what code that makes textures (tests, the sky) holds.
  static Texture fromLinear(int width, int height, const std::vector<Vec3>& rgb,
                            const std::vector<float>& alpha = {});

  bool empty() const { return width <= 0 || height <= 0 || channels <= 0; }
  bool hasAlpha() const { return channels == 2 || channels == 4; }
  size_t texelCount() const { return size_t(width) * size_t(height); }
  /// The bytes the texels take in memory.
  size_t byteSize() const {
    return unorm8.size() + 2 * unorm16.size() + 4 * floats.size();
  }
  /// Texel i = y * width + x (in range), linear RGB; the same for its alpha
  /// (1 when none).
  Vec3 texelAt(size_t i) const;
  float alphaAt(size_t i) const;
  Vec3 texel(int x, int y) const { return texelAt(size_t(y) * size_t(width) + size_t(x)); }
  float texelAlpha(int x, int y) const { return alphaAt(size_t(y) * size_t(width) + size_t(x)); }
  /// The texture at (u, v) through its sampler: bilinear (or the nearest
  /// texel), wrapped as the sampler says; white when empty.
  Vec3 lookup(float u, float v) const;
  float lookupAlpha(float u, float v) const;  ///< the same for alpha (1 when none)
};

/// glTF metallic-roughness material (the subset the bake and renderer use).
/// KHR_texture_transform of a texture reference: (u', v') = offset +
/// R(rotation) S(scale) (u, v), with R = [cos sin; -sin cos] as the extension
/// defines it. Affine, so it may be applied to vertex UVs before
/// interpolation (the renderer) or to interpolated UVs (the bake): the same.
struct TextureTransform {
  float offset[2] = {0, 0};
  float rotation = 0;  ///< radians
  float scale[2] = {1, 1};
  void apply(float& u, float& v) const;
};

/// glTF alphaMode: how the base colour's alpha (factor x texture) is read.
enum class AlphaMode {
  Opaque,  ///< alpha ignored
  Mask,    ///< alpha >= alphaCutoff: opaque, else no surface at all
  Blend,   ///< alpha is the surface's coverage (drawn sorted and blended; the
           ///< tracers pass through with probability 1 - alpha)
};

struct Material {
  std::string name;
  Vec3 baseColor{0.8f, 0.8f, 0.8f};  ///< linear RGB albedo factor
  float baseAlpha = 1.0f;            ///< baseColorFactor's alpha
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;          ///< glTF alphaCutoff (Mask only)
  int baseColorTexture = -1;         ///< index into Scene::textures, -1 = none
  int baseColorTexCoord = 0;         ///< which UV set (0 or 1) the texture uses
  TextureTransform baseColorTransform;  ///< KHR_texture_transform of the base colour texture
  int normalTexture = -1;            ///< tangent-space normal map (linear texels), -1 = none
  int normalTexCoord = 0;            ///< its UV set (0 or 1)
  float normalScale = 1.0f;          ///< glTF normalTexture.scale (scales the map's x and y)
  TextureTransform normalTransform;  ///< its KHR_texture_transform
  /// metallicRoughnessTexture (linear): G scales roughness, B metallic.
  int metallicRoughnessTexture = -1;
  int metallicRoughnessTexCoord = 0;
  TextureTransform metallicRoughnessTransform;
  /// occlusionTexture (linear): R, weighted by occlusionStrength, darkens the
  /// indirect light only (glTF).
  int occlusionTexture = -1;
  int occlusionTexCoord = 0;
  float occlusionStrength = 1.0f;
  TextureTransform occlusionTransform;
  float metallic = 0.0f;             ///< [0,1]
  float roughness = 1.0f;            ///< [0,1], perceptual (alpha = roughness^2)
  Vec3 emission{0, 0, 0};            ///< radiance W/(m^2 sr): emissiveFactor * strength
  /// emissiveTexture (sRGB colour, decoded to linear): multiplies `emission`.
  int emissiveTexture = -1;
  int emissiveTexCoord = 0;
  TextureTransform emissiveTransform;
  float transmission = 0.0f;         ///< KHR_materials_transmission, [0,1]
  float ior = 1.5f;                  ///< KHR_materials_ior
  /// KHR_materials_volume thicknessFactor (scene units). 0 (no volume): a
  /// transmissive surface is thin-walled, as glTF defines it: light passes
  /// straight through it. > 0: the surface bounds a solid that refracts.
  float thickness = 0.0f;
  /// glTF doubleSided. false: the back of the surface is culled from the
  /// camera's view (render, view), as glTF viewers do. Light transport (bake,
  /// path tracer, shadows) treats every surface as two-sided except emission,
  /// which leaves one-sided emitters on their front only.
  bool doubleSided = false;
  /// Whether the rasterisers may cull the back of a surface that is not
  /// doubleSided: glTF's rule. An OBJ file has no such flag and DCC tools
  /// and path tracers draw both sides of its faces, whatever their winding
  /// (load_obj sets false): then every side of the surface is drawn.
  bool backFaceCulling = true;
  /// KHR_materials_specular specularFactor: the weight of the dielectric's
  /// specular layer (its F0 comes from `ior`). 0: a pure Lambert base, in
  /// every renderer (scenes whose answers are analytic only for Lambert).
  float specular = 1.0f;
  /// KHR_materials_unlit, read the way Blender imports it: the camera sees
  /// the base colour (texture and alpha included) as radiance, and every
  /// other ray passes through (no light, no shadow, no emission into the
  /// scene): photons, shadow and path-tracer rays go on, the GL renderer
  /// draws it unshaded and leaves it out of its shadow maps.
  bool unlit = false;

  /// The dielectric's F0 at normal incidence, ((ior - 1) / (ior + 1))^2
  /// (0.04 at glTF's default ior 1.5).
  float dielectricF0() const {
    const float r = (ior - 1.0f) / (ior + 1.0f);
    return r * r;
  }

  bool isEmissive() const { return maxComponent(emission) > 0; }
  /// Whether alpha can hide part of the surface (Mask or Blend).
  bool hasAlpha() const { return alphaMode != AlphaMode::Opaque; }
  std::string ToString() const;
};

/// KHR_lights_punctual light, in world space.
struct Light {
  enum class Type { Point, Spot, Directional };
  Type type = Type::Point;
  std::string name;
  Vec3 position{0, 0, 0};    ///< world space (point, spot)
  Vec3 direction{0, 0, -1};  ///< unit, world space, the way the light travels (spot, directional)
  Vec3 color{1, 1, 1};       ///< linear RGB
  float intensity = 1.0f;    ///< point/spot: W/sr (cd); directional: W/m^2 (lx)
  float range = 0.0f;        ///< 0 = infinite
  float innerConeAngle = 0.0f;        ///< radians (spot)
  float outerConeAngle = kPi / 4.0f;  ///< radians (spot)

  /// Total emitted power in W (RGB). Directional lights need the scene's
  /// bounds: their power is the flux through the bounds' silhouette seen
  /// from the light (the box's projection along the light's direction).
  Vec3 power(const Bounds3& sceneBounds) const;
  std::string ToString() const;
};

/// Light from infinitely far away (a sky): uniform radiance from every
/// direction of the upper hemisphere (+Y, glTF's up) that geometry does not
/// block; nothing from below the horizon (the ground is the scene's, or
/// nothing). Read from the glTF scene's `extras.lightoctree_sky` or set by
/// the commands' --sky flag (docs/scene.md, "Sky").
struct Sky {
  /// W/(m^2 sr), linear RGB: the uniform sky's radiance, or the image's
  /// multiplier; zero = no sky.
  Vec3 radiance{0, 0, 0};
  /// An equirectangular (latitude-longitude) radiance map, linear RGB: row 0
  /// looks at the zenith (+Y), the middle row at the horizon, column u at the
  /// azimuth 2 pi (u - 1/2) from -Z towards +X (skyPixelDirection). Its upper
  /// half is used, texel by texel (no filtering: the photon tracer samples
  /// the texels exactly). Null: a uniform sky.
  std::shared_ptr<const Texture> image;

  bool present() const { return maxComponent(radiance) > 0; }
  /// Radiance arriving from direction `towards` (unit, pointing at the sky).
  Vec3 radianceFrom(const Vec3& towards) const;
  /// Total power entering `box` through its faces: the integral over the
  /// sky's directions of L times the box's projected area; for a uniform sky
  /// pi L S / 2, S the box's surface area (each face sees the sky's cosine
  /// integral, pi, over its half of the directions); for an image, the sum
  /// over its texels.
  Vec3 power(const Bounds3& box) const;
  /// A hash of what this sky sends (its radiance and its image's texels),
  /// as 16 hex digits; "none" for no sky. A bake records it
  /// (BakeMetadata::skyHash) so that a renderer given another sky can say
  /// that the surfaces keep the baked one's light.
  std::string fingerprint() const;
};

/// A sky image (Sky::image) from an .exr or .hdr file of linear radiance.
/// @throws InputError naming `path` when it cannot be read, is smaller than
/// 2 x 2 or larger than 16384 x 8192, or holds a negative or non-finite value.
std::shared_ptr<const Texture> loadSkyImage(const std::string& path);

/// The one check of a sky's brightness, whatever made it (the scene file,
/// --sky, --sky-image, --physical-sky, --sky-mesh), so that every command and
/// the bake take the same skies: the radiance it gives in any direction above
/// the horizon (Sky::radiance times the image's texel) is finite and at most
/// kMaxRadiance, as emission is. Beyond it the bake's sky power overflows
/// while the path tracer would still draw it. @throws InputError naming `what`.
void checkSkyRadiance(const Sky& sky, const std::string& what);

/// The texel (x, y) of a w x h sky image that direction `towards` looks at.
void skyPixelOf(const Vec3& towards, int w, int h, int& x, int& y);
/// The direction at (x + fx, y + fy) of a w x h sky image (fx, fy in [0, 1]).
Vec3 skyPixelDirection(float x, float y, int w, int h);
/// The solid angle of row y's texels of a w x h sky image, above the horizon
/// only (0 for rows below it).
float skyPixelSolidAngle(int y, int w, int h);

/// The vertical fields of view a camera takes, degrees: a scene's camera
/// (glTF `yfov`), `render --fov`, a camera path's keys and Python's `fov`
/// alike. Narrower than a degree the image is a few texels of the scene
/// (a yfov of 1e-30 made a projection of 1e30); 180 and wider is no
/// perspective projection.
constexpr NumberRange kFovDegreesRange{1, 179};

/// A perspective camera in world space.
struct Camera {
  std::string name;
  Vec3 position{0, 0, 0};
  Vec3 forward{0, 0, -1};  ///< unit, view direction
  Vec3 up{0, 1, 0};        ///< unit, orthogonal to forward
  float yfov = 0.8f;       ///< vertical field of view, radians
  float aspectRatio = 0;   ///< width/height; 0 = take it from the image
  float znear = 0.01f;
  float zfar = 0;  ///< 0 = infinite
};

/// Triangle soup in world space, one material index per triangle. Every
/// position (vertices, lights, cameras, the region) is stored relative to
/// `origin`, which is (0, 0, 0) unless the loader rebased a scene far from
/// the world's origin.
struct Scene {
  std::string sourcePath;
  /// sceneContentHash of the files as loadScene read them ("" for a scene
  /// made in code): what a bake records, whatever the files hold later.
  std::string contentHash;
  /// Where the stored positions are measured from, in the file's world
  /// coordinates (world = stored + origin). loadScene keeps (0, 0, 0) unless
  /// the scene's centre lies farther from the world origin than 128x its size
  /// (a building in projected coordinates, 1e5-1e6 m): then the centre of its
  /// geometry, the positions taken to it in double before they are rounded to
  /// float, so that the scene bakes and renders as it would at the origin.
  /// World-space inputs (--eye, --target, --bounds, camera paths) go through
  /// toLocal; outputs (the .vdb's transform, glTF exports) carry it back.
  Vec3d origin;
  Vec3 toLocal(const Vec3d& world) const { return (world - origin).toVec3(); }
  Vec3d toWorld(const Vec3& local) const { return Vec3d(local) + origin; }
  bool rebased() const { return origin.x != 0 || origin.y != 0 || origin.z != 0; }
  /// What loading corrected and a user should hear of (e.g. a base colour
  /// above 1 clamped): one sentence each, naming the file and the thing.
  std::vector<std::string> warnings;
  std::vector<Vec3> positions;    ///< world space
  /// Per vertex, unit, world space; empty = use face normals. A zero vector
  /// stands for the face's normal too (the part of a scene that had none,
  /// joined to one that has them: placeModel, scene/place_model.cpp).
  std::vector<Vec3> normals;
  std::vector<float> texcoords0;  ///< 2 floats per vertex, or empty
  std::vector<float> texcoords1;  ///< 2 floats per vertex, or empty
  /// glTF TANGENT, 4 floats per vertex: the unit world-space tangent and w =
  /// +-1 (bitangent = w cross(normal, tangent)); w = 0 on vertices of
  /// primitives that had none (their tangent is derived from the UVs). Empty
  /// when no primitive had one.
  std::vector<float> tangents;
  /// glTF COLOR_0, 4 floats per vertex: linear RGBA in [0, 1], which
  /// multiplies the base colour and its alpha. Empty when no primitive had
  /// one (white); the vertices of primitives without one are white.
  std::vector<float> colors;
  std::vector<uint32_t> indices;  ///< 3 per triangle, into positions
  std::vector<int32_t> triangleMaterial;  ///< one per triangle, into materials
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Light> lights;
  Sky sky;  ///< light from beyond the scene; none by default
  std::vector<Camera> cameras;
  /// A region of interest marked in the file (glTF: a node whose `extras`
  /// hold `"lightoctree_region": true`; docs/scene.md): the world-space bounds
  /// of the marker nodes' meshes, which are not part of the scene. Empty =
  /// none. The bake uses it when `--bounds` gives none.
  Bounds3 region;
  /// Materials from this index on belong to objects added after the bake
  /// (scene/place_model.h): the renderer lights them from the free-space
  /// light, not the surfaces'. SIZE_MAX: none.
  size_t movingMaterialsFrom = SIZE_MAX;
  /// Whether triangle t belongs to an object added after the bake.
  bool isAdded(size_t t) const { return size_t(triangleMaterial[t]) >= movingMaterialsFrom; }
  /// Whether any object was added after the bake.
  bool hasAddedObjects() const { return movingMaterialsFrom < materials.size(); }
  /// Frees every texture's texels and file bytes: each becomes empty (a
  /// lookup reads white), its name and sampler kept. For a caller that has
  /// handed the texels to the GPU and reads them no more (`render`).
  void releaseTexels();
  /// The same for textures[index] alone.
  void releaseTexels(size_t index);

  size_t triangleCount() const { return indices.size() / 3; }
  Bounds3 bounds() const;
  /// Geometric normal (unit, from the winding) and area of triangle t.
  Vec3 faceNormal(size_t t) const;
  float triangleArea(size_t t) const;
  /// Base colour of triangle t at barycentrics (b1, b2), texture and
  /// vertex colour applied.
  Vec3 albedo(size_t t, float b1, float b2) const;
  /// The vertex colour (COLOR_0) of triangle t at (b1, b2), and its alpha
  /// into `alpha` when given: white and 1 without vertex colours.
  Vec3 vertexColor(size_t t, float b1, float b2, float* alpha = nullptr) const;
  /// Coverage of triangle t at (b1, b2) as its material's alpha mode reads
  /// it: 1 for Opaque; 1 or 0 against the cutoff for Mask; alpha for Blend.
  float coverage(size_t t, float b1, float b2) const;
  /// The shading normal of triangle t at (b1, b2), as the renderer shades:
  /// the interpolated vertex normal (when the scene has normals; else `n`,
  /// the unit geometric normal turned to the side being shaded), turned to
  /// n's side, then tilted by the material's normal map in the tangent frame
  /// the renderer uses (tangent = the surface direction of +u of the map's
  /// UVs, bitangent = cross(normal, tangent): glTF's convention for
  /// tangent.w = 1; render_scene.frag perturbNormal).
  Vec3 shadingNormal(size_t t, float b1, float b2, const Vec3& n) const;
  /// Metallic and roughness of triangle t at (b1, b2): the factors times the
  /// metallicRoughnessTexture's B and G channels where there is one.
  void metallicRoughness(size_t t, float b1, float b2, float& metallic, float& roughness) const;
  /// Emitted radiance of triangle t at (b1, b2) (W/(m^2 sr)), emissive
  /// texture applied.
  Vec3 emission(size_t t, float b1, float b2) const;
  /// Mean emitted radiance over triangle t: `emission` of its material
  /// exactly when it has no emissive texture, else the mean of 256
  /// stratified samples, the centroids of its 16 x 16 sub-triangles (what
  /// emitter sampling picks triangles by).
  Vec3 triangleEmission(size_t t) const;
  /// Texture coordinates of UV set `texCoord` (0 or 1) of triangle t at
  /// (b1, b2) after `transform`; false when the set is missing.
  bool texcoord(size_t t, float b1, float b2, int texCoord, const TextureTransform& transform,
                float& u, float& v) const;
  std::string ToString() const;  ///< one-line summary

  /// Where ray tracing in float should put its origin: the bounds' centre
  /// when the scene lies farther from the world origin than 4x its own size
  /// (a float coordinate of magnitude m is only m * 2^-23 precise, so a small
  /// scene far away loses its geometry to rounding), else (0, 0, 0).
  Vec3 tracingOrigin() const;
  /// A copy moved by `offset`: vertex positions, light and camera positions
  /// (directions, areas and powers are unchanged by a translation).
  Scene translated(const Vec3& offset) const;
};

/// Takes the triangles of material `material` (a sky box or dome: a closed
/// mesh around the scene) out of the geometry and makes them the scene's
/// sky: an equirectangular image `width` x `width`/2 of what the centre of
/// the remaining geometry sees of them along each texel's centre direction
/// (nearest triangle, either face), their emission as radiance, or their
/// base colour (texture included) when the material does not emit (a plain
/// textured sky box, shown unlit as glTF viewers show it); multiplier 1.
/// Like every sky, only its upper hemisphere lights the scene. Vertices no
/// other triangle uses go too. @throws InputError naming the scene when no
/// material has that name (listing those it has), it covers no triangle, or
/// it covers them all.
void skyFromMaterial(Scene& scene, const std::string& material, int width = 1024);

/// A daylight sky for the scene's sun (its first directional light):
/// Preetham, Shirley and Smits' analytic model ("A Practical Analytic Model
/// for Daylight", 1999) at `turbidity` (2: very clear, 3: clear, 6: hazy),
/// drawn into a `width` x `width`/2 equirectangular image (upper half; the
/// luminance in cd/m^2 = W/(m^2 sr) in the project's units, the model's
/// chromaticity, to linear Rec. 709), scaled so that the sky stands to the
/// scene's sun as the model's sky to the sun that reaches the ground through
/// the same air: sky x E_scene / directSunIlluminance, E_scene the
/// luminance of the sun's colour x intensity (lx). The sun itself stays the
/// scene's light. @throws InputError naming the scene when it has no
/// directional light, the sun is not above the horizon, or the turbidity
/// lies outside [kMinTurbidity, kMaxTurbidity].
void physicalSky(Scene& scene, float turbidity, int width = 512);

constexpr float kMinTurbidity = 1.7f;  ///< below it the model's sky turns negative
constexpr float kMaxTurbidity = 10.0f;
/// The sun's illuminance above the atmosphere, lx (its mean distance).
constexpr double kSolarIlluminance = 128000.0;

/// The model's zenith: luminance (cd/m^2) and chromaticity (x, y), for the
/// sun `sunZenith` radians from the zenith (Preetham et al. 1999, A.2).
struct DaylightZenith {
  double luminance = 0, x = 0, y = 0;
};
DaylightZenith daylightZenith(double sunZenith, double turbidity);

/// The sun's direct normal illuminance at the ground, lx: kSolarIlluminance
/// through Kasten and Young's air mass with Kasten's Rayleigh optical depth
/// and `turbidity` taken as Linke's (the ESRA clear-sky formula).
double directSunIlluminance(double sunZenith, double turbidity);

/// Largest |coordinate| a scene may have, scene units (glTF metres): 1e12
/// (a million km). The tracers work in single precision in a frame centred
/// on the scene; loadScene refuses vertices beyond this, naming the vertex.
constexpr float kMaxCoordinate = 1e12f;
/// Ray origins move off their surface by this fraction of the scene's size
/// (its diagonal plus its largest absolute coordinate in the tracers' frame),
/// in the photon tracer and the path tracer alike; the loader warns where
/// that offset passes small parts by (scene.cpp, checkTriangleSizes).
constexpr float kRayEpsilonScale = 1e-5f;

/// Largest emitted radiance a material may have, W/(m^2 sr) (emissive
/// factor x KHR_materials_emissive_strength, OBJ Ke): 1e9, fifty times the
/// sun's disc; loadScene refuses more, naming the material.
constexpr float kMaxRadiance = 1e9f;
/// Largest light intensity, W/sr (cd) for point and spot lights, W/m^2 (lx)
/// for directional ones: 1e12 (the sun gives about 1.2e5 lx); loadScene
/// refuses more, or a negative one, naming the light.
constexpr float kMaxLightIntensity = 1e12f;

/// Deepest nesting of objects and arrays a glTF's JSON may have: both JSON
/// parsers recurse once per level, and nothing in glTF needs more.
constexpr size_t kMaxJsonDepth = 256;

/// A glTF accessor without a bufferView (zeros but for its sparse values)
/// may hold at most max(kMinImplicitElements, kMaxImplicitElementsPerSparse x
/// its sparse count) elements: a few hundred bytes must not stand for
/// gigabytes of zeros. Accessors with a bufferView are bounded by its bytes.
constexpr size_t kMinImplicitElements = size_t(1) << 16;
constexpr size_t kMaxImplicitElementsPerSparse = 1024;

/// @brief The index checks every stage that walks the triangles relies on:
/// index count a multiple of 3, fewer than 2^32 - 1 triangles, every vertex
/// index inside `positions`, every vertex position finite, one material index
/// per triangle, each inside `materials`. Loaders run it on what they load;
/// stages run it on scenes built in code. @throws InputError naming the first
/// offending triangle, index or vertex (and the scene's file, if any).
void checkSceneIndices(const Scene& scene);

/// Loads a .gltf, .glb or .obj file. External resources (buffers, images,
/// .mtl files) resolve only inside the scene file's own folder.
/// @throws InputError naming the file and the problem (missing buffer, index
/// out of range, non-finite vertex, unsupported primitive mode, unreadable
/// image, unknown extension). `skyMesh`: a material to take as the scene's
/// sky (skyFromMaterial), replacing the file's sky; in a glTF its vertices
/// do not count when the loader decides whether to rebase (Scene::origin),
/// in an OBJ they do (its v lines are rebased before faces are read).
Scene loadScene(const std::string& path, const std::string& skyMesh = "");

}  // namespace lo
