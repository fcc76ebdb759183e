// The scene pass's inputs: the vertex shader's outputs (render_scene.vert) and
// the uniforms the renderer sets (render/scene_pass.cpp). Part of render_scene.frag.

in vec3 vPosition;  // world
in vec3 vNormal;    // world, interpolated
in vec3 vBaseColor;
in float vBaseAlpha;  // baseColorFactor's alpha x COLOR_0's
in vec2 vMetallicRoughness;
in vec3 vEmission;
in vec2 vUv;
in vec2 vNormalUv;
in vec2 vMetallicRoughnessUv;
in vec2 vOcclusionUv;
in vec2 vEmissiveUv;
in vec3 vLightmap;  // lightmap u, v, page
in vec4 vTangent;   // glTF TANGENT, w = +-1; w = 0: derive the tangent from the UVs
out vec4 fragColor;

uniform usampler3D uOctree;  // RGBA8UI pool of 2x2x2 tiles
uniform sampler2D uVdls;       // RGBA32F: irradiance, packed direction
uniform usampler2D uVdlsHalf;  // RGBA16UI: half-float bits of irradiance, packed direction
uniform bool uHalfVdls;        // which of the two holds the VDLs
uniform bool uCompactVdls;     // the 16-bit texels hold compact (RGB9E5) irradiance
uniform float uVdlScale;       // ... times this scale
uniform int uShTerms;          // 0: the leaves hold VDLs; else SH terms per leaf
uniform bool uSurfaceTexels;   // each leaf's (layer's) light ends in a surface texel
uniform sampler2DArrayShadow uShadowMaps;
uniform sampler2DArray uShadowDepths;  // the same maps read as depths (PCSS blocker search)
uniform vec3 uOctreeOrigin;  // world
uniform float uVoxelSize;    // world units
uniform int uDepth;
uniform vec3 uEye;
uniform int uMode;
uniform bool uInterpolation;
uniform bool uSpecular;
uniform int uMaxVdls;
uniform float uNormalOffset;  // voxel sizes
uniform float uExposureScale;
uniform bool uEncodeSrgb;
uniform sampler2D uBaseColorTexture;  // linear RGB (RGBA16F), mipmapped
uniform bool uHasBaseColorTexture;
uniform sampler2D uNormalTexture;  // tangent-space normal map, linear [0, 1] texels
uniform bool uHasNormalTexture;
uniform float uNormalScale;
uniform sampler2D uMetallicRoughnessTexture;  // linear: G roughness, B metallic
uniform bool uHasMetallicRoughnessTexture;
uniform sampler2D uOcclusionTexture;  // linear: R ambient occlusion
uniform bool uHasOcclusionTexture;
uniform float uOcclusionStrength;
uniform sampler2D uEmissiveTexture;  // linear RGB emission map (sRGB decoded at load)
uniform bool uHasEmissiveTexture;
uniform float uEmissionScale;  // 1; 0 while the probe is captured if emitters are lights
uniform bool uEmitsBothSides;  // glTF doubleSided: else emission shows on the winding's front only
uniform int uAlphaMode;      // LO_ALPHA_OPAQUE, LO_ALPHA_MASK or LO_ALPHA_BLEND (glTF alphaMode)
uniform float uAlphaCutoff;  // glTF alphaCutoff (mask)
uniform float uTransmission;  // KHR_materials_transmission of this draw; 0 = opaque
uniform bool uUnlit;          // KHR_materials_unlit: the base colour, unshaded (Material::unlit)
uniform vec2 uDielectric;     // the dielectric's specular layer: F0 (from the ior), weight (specular)
uniform vec3 uViewForward;     // the camera's unit view direction (render space)
uniform vec4 uCascadeFar;      // view depth where each sun cascade ends
uniform vec4 uCascadeTexel;    // world size of a texel of each cascade
uniform vec4 uCascadeDepth;    // world depth range of each cascade's map
uniform bool uAtlas;           // indirect light from the lightmap atlas, not the octree
uniform sampler2DArray uAtlasIrradiance;  // E (W/m^2) per texel, a layer per page (RGB9E5)
uniform sampler2DArray uAtlasDirection;   // unit mean VDL direction per texel (RGBA8 snorm)
uniform bool uHasProbe;        // environment reflections from the probe (RenderParams::reflections)
uniform samplerCube uProbe;    // the lit scene seen from the render-space origin, mipmapped
uniform vec3 uProbeBoxMin;     // the scene's bounds (render space): the parallax box
uniform vec3 uProbeBoxMax;
uniform float uProbeMaxLod;
uniform vec3 uProbeIrradiance[9];  // the probe's irradiance at its centre: SH terms E_i (octree_layout.h)
uniform vec2 uBehindScale;     // the share of uBehind's texels this frame fills (it only grows)
uniform sampler2D uBehind;    // the opaque image under transmissive surfaces (as output)
uniform float uThickness;     // KHR_materials_volume thickness; 0 = thin-walled
uniform bool uHasVolumeBacks;  // uBackFaces holds this frame's volume back faces
uniform sampler2D uBackFaces;  // nearest back face of a volume per pixel: render space, w its normal (0: none)
uniform bool uHasOpaqueDepth;  // uOpaqueDepth holds the opaque image's depth
uniform sampler2D uOpaqueDepth;   // window-space depth of the opaque image (as uBehind)
uniform float uIor;           // KHR_materials_ior
uniform mat4 uViewProj;       // render space -> clip (the vertex shader's)
