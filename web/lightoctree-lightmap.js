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

export class LightOctreeLightmaps {
  /**
   * @param parser the GLTFParser GLTFLoader passes to its plugins
   * @param options.renderer the WebGLRenderer (needed for RGBM pages)
   * @param options.intensity the light maps' intensity (1: physical lights)
   */
  constructor(parser, { renderer = null, intensity = 1 } = {}) {
    this.name = 'LIGHTOCTREE_lightmap';  // reads extras, not a glTF extension
    this.parser = parser;
    this.renderer = renderer;
    this.intensity = intensity;
    this.pages = new Map();  // uri -> Promise<THREE.Texture>
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
      material.needsUpdate = true;
    }));
    result.userData.lightOctree = {
      materials: uses.length,
      pages: this.pages.size,
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
    const bitmap = await new THREE.ImageBitmapLoader()
      .setOptions({ imageOrientation: 'none', premultiplyAlpha: 'none', colorSpaceConversion: 'none' })
      .loadAsync(url);
    const source = new THREE.Texture(bitmap);
    source.flipY = false;  // glTF: row 0 is v = 0
    source.premultiplyAlpha = false;
    source.colorSpace = THREE.NoColorSpace;
    source.minFilter = source.magFilter = THREE.NearestFilter;
    source.generateMipmaps = false;
    source.needsUpdate = true;
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
