// Light Octree lightmaps in three.js (r151 or later; tested with r187): a
// GLTFLoader plugin that reads each material's `extras.lightmap`, written by
// `lightoctree lightmap` (docs/lightmap.md), loads its page and sets it as the
// material's light map on TEXCOORD_1.
//
//   import { LightOctreeLightmaps } from './lightoctree-lightmap.js';
//   const loader = new GLTFLoader();
//   loader.register((parser) => new LightOctreeLightmaps(parser, { renderer }));
//   const gltf = await loader.loadAsync('cornell.glb');   // lit as baked
//
// Pages: `linear-exr` through three's EXRLoader (half floats); `rgbm-png`
// decoded once on the GPU into a half-float texture (RGB x A x rgbmRange,
// read texel by texel, unpremultiplied, as data), so the light map holds E in
// W/m^2 either way and bilinear filtering works on E, not on its encoding.
// three's light map is irradiance: its standard materials add it to what the
// diffuse BRDF (baseColor / pi) multiplies, the shading the extras name, so
// the intensity is 1 with physically based lights (the default since r155;
// pass `intensity: 1 / Math.PI` for `renderer.useLegacyLights = true`).
// Direction pages (`extras.lightmap.direction`, written by default): the
// mean direction the light of each texel comes from. With them the light map
// is not added as flat irradiance; each fragment gets one directional light
// of colour E / max(n_vertex . d, 0.05) from d through the material's BRDF
// (three's RE_Direct: glTF's Fresnel mix of the diffuse and GGX lobes), as
// `lightoctree render --lighting atlas` does, so normal maps show their
// relief and glossy surfaces a highlight. A texel without a direction, or a
// page that cannot be read, is used as irradiance alone. Pass
// `directions: false` to use the irradiance alone everywhere.
// Materials of the unlit preview (`extras.lightmapPreview`) already show the
// bake and are left alone. A `content: "full"` map holds the direct light
// too: remove the scene's lights then (`result.userData.lightOctree.content`
// says which, for the whole file).

import * as THREE from 'three';
import { EXRLoader } from 'three/addons/loaders/EXRLoader.js';

const decodeVertex = /* glsl */ `
varying vec2 vUv;
void main() {
  vUv = uv;
  gl_Position = vec4(position.xy, 0.0, 1.0);
}`;

// One texel of the page per fragment (nearest sampling at texel centres).
const decodeFragment = /* glsl */ `
uniform sampler2D page;
uniform float range;
varying vec2 vUv;
void main() {
  vec4 rgbm = texture2D(page, vUv);
  gl_FragColor = vec4(rgbm.rgb * rgbm.a * range, 1.0);
}`;

// three's light-map chunk with the irradiance turned into one light from the
// texel's direction (shared by every material that has direction pages).
const directionalLightMap = /* glsl */ `
#if defined( RE_IndirectDiffuse ) && defined( USE_LIGHTMAP )
	{
		vec3 loE = texture2D( lightMap, vLightMapUv ).rgb * lightMapIntensity;
		vec2 loUv = vec2( vLightMapUv.x, mix( vLightMapUv.y, 1.0 - vLightMapUv.y, loDirectionFlip ) );
		vec3 loD = texture2D( loDirectionMap, loUv ).rgb * ( 255.0 / 127.0 ) - 128.0 / 127.0;
		float loLength = length( loD );
		if ( loLength > 1e-3 ) {
			IncidentLight loLight;
			loLight.direction = normalize( ( viewMatrix * vec4( loD / loLength, 0.0 ) ).xyz );
			loLight.color = loE / max( dot( nonPerturbedNormal, loLight.direction ), 0.05 );
			loLight.visible = true;
			#ifdef STANDARD
				// three sets this only when the scene has punctual lights: the
				// same multiple-scattering compensation, from material.dfg.
				material.multiScatteringCompensation = 1.0 + material.specularColorBlended *
					( 1.0 / ( material.dfg.x + material.dfg.y ) - 1.0 );
			#endif
			RE_Direct( loLight, geometryPosition, geometryNormal, geometryViewDir, geometryClearcoatNormal, material, reflectedLight );
		} else {
			irradiance += loE;  // no direction: the irradiance as it is
		}
	}
#endif
`;

export class LightOctreeLightmaps {
  /**
   * @param parser the GLTFParser GLTFLoader passes to its plugins
   * @param options.renderer the WebGLRenderer (needed for RGBM pages)
   * @param options.intensity the light maps' intensity (1: physical lights)
   */
  constructor(parser, { renderer = null, intensity = 1, directions = true } = {}) {
    this.name = 'LIGHTOCTREE_lightmap';  // reads extras, not a glTF extension
    this.parser = parser;
    this.renderer = renderer;
    this.intensity = intensity;
    this.directions = directions;
    this.pages = new Map();  // uri -> Promise<THREE.Texture>
    this.directionPages = new Map();  // uri -> Promise<THREE.Texture>
  }

  async afterRoot(result) {
    const uses = [];
    const contents = new Set();
    result.scene.traverse((object) => {
      if (!object.isMesh) return;
      const materials = Array.isArray(object.material) ? object.material : [object.material];
      for (const material of materials) {
        const lightmap = material.userData.lightmap;
        if (!lightmap || material.userData.lightmapPreview) continue;
        uses.push([material, lightmap]);
        contents.add(lightmap.content);
      }
    });
    await Promise.all(uses.map(async ([material, lightmap]) => {
      material.lightMap = await this.page(lightmap);
      material.lightMapIntensity = this.intensity;
      const directionMap = this.directions && lightmap.direction
        ? await this.directionPage(lightmap.direction) : null;
      if (directionMap) this.useDirections(material, directionMap, lightmap.encoding === 'linear-exr');
      material.needsUpdate = true;
    }));
    result.userData.lightOctree = {
      materials: uses.length,
      pages: this.pages.size,
      directionPages: this.directionPages.size,
      content: contents.size === 1 ? [...contents][0] : [...contents].join(','),
    };
  }

  page(lightmap) {
    if (!this.pages.has(lightmap.uri)) {
      const url = THREE.LoaderUtils.resolveURL(lightmap.uri, this.parser.options.path);
      let texture;
      if (lightmap.encoding === 'linear-exr') {
        texture = this.exrPage(url);
      } else if (lightmap.encoding === 'rgbm-png') {
        texture = this.rgbmPage(url, lightmap.rgbmRange);
      } else {
        texture = Promise.reject(new Error(`lightmap ${lightmap.uri}: unknown encoding '${lightmap.encoding}'`));
      }
      this.pages.set(lightmap.uri, texture.then((t) => {
        t.channel = lightmap.texCoord;  // TEXCOORD_1, three's uv1
        return t;
      }));
    }
    return this.pages.get(lightmap.uri);
  }

  // The light map as one light per fragment from the texel's direction
  // (directionalLightMap). `flipped`: the page texture flips v (EXR), the
  // direction page does not.
  useDirections(material, directionMap, flipped) {
    material.onBeforeCompile = (shader) => {
      shader.uniforms.loDirectionMap = { value: directionMap };
      shader.uniforms.loDirectionFlip = { value: flipped ? 1 : 0 };
      shader.fragmentShader = shader.fragmentShader
        .replace('#include <common>', '#include <common>\nuniform sampler2D loDirectionMap;\nuniform float loDirectionFlip;')
        .replace('#include <lights_fragment_maps>',
                 THREE.ShaderChunk.lights_fragment_maps.replace(
                   /#ifdef USE_LIGHTMAP[\s\S]*?#endif/, '') + directionalLightMap);
    };
    material.customProgramCacheKey = () => 'lightoctree-direction';
  }

  // The direction page, or null (with a warning) when it cannot be used: the
  // light map then lights the material by its irradiance alone.
  directionPage(direction) {
    if (!this.directionPages.has(direction.uri)) {
      const url = THREE.LoaderUtils.resolveURL(direction.uri, this.parser.options.path);
      const page = direction.encoding !== 'unit-vector-png'
        ? Promise.reject(new Error(`unknown encoding '${direction.encoding}'`))
        : this.dataPng(url, THREE.LinearFilter);
      this.directionPages.set(direction.uri, page.catch((e) => {
        console.warn(`lightmap direction ${direction.uri}: ${e.message || e}; using the irradiance alone`);
        return null;
      }));
    }
    return this.directionPages.get(direction.uri);
  }

  // A PNG that holds data: read as stored (no colour conversion, no
  // premultiplication), row 0 at v = 0 as glTF has it, no mipmaps.
  async dataPng(url, filter) {
    const bitmap = await new THREE.ImageBitmapLoader()
      .setOptions({ imageOrientation: 'none', premultiplyAlpha: 'none', colorSpaceConversion: 'none' })
      .loadAsync(url);
    const texture = new THREE.Texture(bitmap);
    texture.flipY = false;
    texture.premultiplyAlpha = false;
    texture.colorSpace = THREE.NoColorSpace;
    texture.minFilter = texture.magFilter = filter;
    texture.generateMipmaps = false;
    texture.channel = 1;
    texture.needsUpdate = true;
    return texture;
  }

  async exrPage(url) {
    const texture = await new EXRLoader().setDataType(THREE.HalfFloatType).loadAsync(url);
    texture.generateMipmaps = false;  // the dilated gutter is one ring wide
    texture.minFilter = texture.magFilter = THREE.LinearFilter;
    texture.needsUpdate = true;
    // EXRLoader keeps the file's rows bottom-up (OpenGL's habit); glTF's v
    // runs top-down: flip v.
    texture.repeat.set(1, -1);
    texture.offset.set(0, 1);
    return texture;
  }

  async rgbmPage(url, range) {
    if (!this.renderer) throw new Error(`lightmap ${url}: RGBM pages need the renderer (options.renderer)`);
    if (!(range > 0)) throw new Error(`lightmap ${url}: rgbmRange ${range} is not a positive range`);
    const source = await this.dataPng(url, THREE.NearestFilter);
    const bitmap = source.image;
    const target = new THREE.WebGLRenderTarget(bitmap.width, bitmap.height, {
      type: THREE.HalfFloatType, depthBuffer: false, generateMipmaps: false,
      minFilter: THREE.LinearFilter, magFilter: THREE.LinearFilter,
    });
    const quad = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), new THREE.ShaderMaterial({
      uniforms: { page: { value: source }, range: { value: range } },
      vertexShader: decodeVertex, fragmentShader: decodeFragment,
      depthTest: false, depthWrite: false,
    }));
    const scene = new THREE.Scene();
    scene.add(quad);
    const previous = this.renderer.getRenderTarget();
    this.renderer.setRenderTarget(target);
    this.renderer.render(scene, new THREE.Camera());
    this.renderer.setRenderTarget(previous);
    quad.geometry.dispose();
    quad.material.dispose();
    source.dispose();
    bitmap.close();
    // Row 0 of the target is the page's first row: v = 0, as glTF has it.
    return target.texture;
  }
}
