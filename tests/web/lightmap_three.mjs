// The three.js module (web/lightoctree-lightmap.js) in a real browser: headless
// Chromium (Debian's) draws lightmapped glTF files from their camera, and each
// picture is compared with the project's own `render --lighting atlas --mode
// indirect --reflections off` of the same camera and light (three.js has no
// reflection probe unless the page adds one; `lightoctree compare`, emitters'
// pixels left out):
//  - the Cornell box, EXR pages and RGBM PNG pages: mean brightness within 3%;
//  - the material room (a normal-mapped panel, gloss, textures; its glass
//    and gold made matte), with its direction pages: mean brightness within
//    3%, and closer per pixel than the same file drawn without them (the
//    irradiance alone shades a normal map flat).
// The pictures are written to OUT either way (three-*.png, ours-*.png).
//
//   node lightmap_three.mjs LIGHTOCTREE CORNELL MATERIAL_ROOM OUT NODE_MODULES
import { execFileSync } from 'node:child_process';
import { createServer } from 'node:http';
import { existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, extname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { createRequire } from 'node:module';

const [cli, sceneFile, roomFile, out, modules] = process.argv.slice(2).map((a) => resolve(a));
const repo = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
const require = createRequire(join(modules, 'noop.js'));
const puppeteer = require('puppeteer-core');
const chromium = ['/usr/bin/chromium', '/usr/bin/chromium-browser'].find((p) => existsSync(p));
if (!chromium) {
  console.log('FAILED: no Chromium (tools/setup.sh installs Debian\'s chromium with the tests)');
  process.exit(1);
}
mkdirSync(out, { recursive: true });
const size = 256;
const run = (args) => execFileSync(cli, args, { encoding: 'utf8' });

// The bakes, their lightmaps (indirect light; the Cornell box's as EXR and
// RGBM pages) and the project's pictures of the same light: the atlas's
// indirect light. Emitters' own pixels are left out: the renderer's indirect
// mode draws them black, three.js their emission.
const prepare = (scene, name, images) => {
  run(['bake', scene, '-o', join(out, `${name}.vdb`), '--depth', '5', '--photons', '200000', '--quiet']);
  for (const image of images) {
    run(['lightmap', scene, join(out, `${name}.vdb`), '-o', join(out, `${name}-${image}.glb`),
         '--image', image, '--quiet']);
  }
  run(['render', scene, join(out, `${name}.vdb`), '--lighting', 'atlas', '--mode', 'indirect', '--reflections', 'off',
       '--width', String(size), '--height', String(size), '-o', join(out, `ours-${name}.png`), '--exposure', '0', '--tone-map', 'clamp', '--quiet']);
  run(['reference', scene, '-o', join(out, `${name}-first-hit.exr`), '--width', String(size), '--height',
       String(size), '--spp', '1', '--emitter-mask', join(out, `${name}-emitters.png`), '--quiet']);
};
prepare(sceneFile, 'cornell', ['exr', 'png']);
// The room with its glass and gold turned matte: three.js draws neither our
// reflection probe nor our transmission, which the comparison is not about.
const room = JSON.parse(readFileSync(roomFile, 'utf8'));
for (const material of room.materials) {
  for (const ext of ['KHR_materials_transmission', 'KHR_materials_ior', 'KHR_materials_volume']) {
    if (material.extensions) delete material.extensions[ext];
  }
  if (material.pbrMetallicRoughness) material.pbrMetallicRoughness.metallicFactor = 0;
}
room.extensionsUsed = (room.extensionsUsed || []).filter((e) => !e.includes('transmission') &&
                                                                 !e.includes('_ior') && !e.includes('volume'));
writeFileSync(join(out, 'room-matte.gltf'), JSON.stringify(room));
prepare(join(out, 'room-matte.gltf'), 'room', ['exr']);
// name, file, query, the project's picture and mask, whether the mean is checked
const cases = [
  ['exr', 'cornell-exr.glb', '', 'cornell', true],
  ['rgbm', 'cornell-png.glb', '', 'cornell', true],
  ['exr-flat', 'cornell-exr.glb', '&directions=off', 'cornell', false],
  ['room', 'room-exr.glb', '&lights=off', 'room', true],
  ['room-flat', 'room-exr.glb', '&lights=off&directions=off', 'room', false],
];

const types = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript',
                '.glb': 'model/gltf-binary', '.exr': 'image/x-exr', '.png': 'image/png' };
const roots = { '/three/': join(modules, 'three'), '/web/': join(repo, 'web'),
                '/tests/web/': join(repo, 'tests', 'web'), '/out/': out };
const server = createServer((request, response) => {
  const path = decodeURIComponent(new URL(request.url, 'http://x').pathname);
  if (path === '/favicon.ico') {
    response.writeHead(204);
    response.end();
    return;
  }
  const prefix = Object.keys(roots).find((p) => path.startsWith(p));
  const file = prefix && resolve(roots[prefix], '.' + path.slice(prefix.length - 1));
  if (!file || !file.startsWith(roots[prefix]) || !existsSync(file)) {
    response.writeHead(404);
    response.end();
    return;
  }
  response.writeHead(200, { 'Content-Type': types[extname(file)] || 'application/octet-stream' });
  response.end(readFileSync(file));
});
await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
const origin = `http://127.0.0.1:${server.address().port}`;

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ['--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
let failures = 0;
try {
  const rmse = {};
  for (const [name, glb, query, ours, checkMean] of cases) {
    const page = await browser.newPage();
    page.on('console', (m) => { if (m.type() === 'error') console.log(`  browser: ${m.text()}`); });
    await page.goto(`${origin}/tests/web/lightmap.html?scene=/out/${glb}&width=${size}&height=${size}${query}`);
    await page.waitForFunction('window.result', { timeout: 120000 });
    const result = await page.evaluate('window.result');
    await page.close();
    if (result.error) {
      console.log(`FAILED: three.js ${name}: ${result.error}`);
      failures++;
      continue;
    }
    const picture = join(out, `three-${name}.png`);
    writeFileSync(picture, Buffer.from(result.png.split(',')[1], 'base64'));
    const json = join(out, `compare-${name}.json`);
    run(['compare', picture, join(out, `ours-${ours}.png`), '--mask', join(out, `${ours}-emitters.png`),
         '--json', json]);
    const c = JSON.parse(readFileSync(json, 'utf8'));
    const ratio = c.mean_test_luminance / c.mean_reference_luminance;
    rmse[name] = c.channels.Y.rel_rmse;
    const ok = (!checkMean || Math.abs(ratio - 1) <= 0.03) && result.info.materials > 0;
    console.log(`three.js ${name}: ${result.info.materials} materials, ${result.info.pages} page(s), ` +
                `${result.info.directionPages} direction page(s) used; mean brightness ${ratio.toFixed(4)} ` +
                `of render --lighting atlas --mode indirect --reflections off, emitters' pixels left out ` +
                `(${checkMean ? 'target 0.97-1.03' : 'not checked'}; rel. RMSE per pixel ` +
                `${c.channels.Y.rel_rmse.toFixed(4)}): ${ok ? 'ok' : 'FAILED'}; ${picture}`);
    if (!ok) failures++;
  }
  // The direction pages bring the normal map's relief and the gloss back.
  if ('room' in rmse && 'room-flat' in rmse) {
    const ok = rmse.room <= 0.6 * rmse['room-flat'];
    console.log(`three.js material room: rel. RMSE per pixel ${rmse.room.toFixed(4)} with direction pages, ` +
                `${rmse['room-flat'].toFixed(4)} without (target: at most 0.6x without): ${ok ? 'ok' : 'FAILED'}`);
    if (!ok) failures++;
  }
} finally {
  await browser.close();
  server.close();
}
console.log(failures === 0 ? 'three.js lightmaps: all pictures match' : `${failures} failure(s)`);
process.exit(failures === 0 ? 0 : 1);
