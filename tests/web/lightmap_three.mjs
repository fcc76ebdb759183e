// The three.js module (web/lightoctree-lightmap.js) in a real browser: headless
// Chromium (Debian's) draws the Cornell box's lightmapped glTF, EXR pages and
// RGBM PNG pages, from the file's camera, and each picture's mean brightness
// is compared with the project's own `render --lighting atlas --mode
// indirect` of the same camera and light (`lightoctree compare`, the light
// fixture's pixels left out): within 3% (docs/lightmap.md).
// The pictures are written to OUT either way (three-exr.png, three-rgbm.png,
// ours-*.png).
//
//   node lightmap_three.mjs LIGHTOCTREE SCENE OUT NODE_MODULES
import { execFileSync } from 'node:child_process';
import { createServer } from 'node:http';
import { existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, extname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { createRequire } from 'node:module';

const [cli, sceneFile, out, modules] = process.argv.slice(2).map((a) => resolve(a));
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

// The bake, its lightmaps (indirect light, EXR and RGBM pages), and the
// project's picture of the same light: the atlas's indirect light.
run(['bake', sceneFile, '-o', join(out, 'grid.vdb'), '--depth', '5', '--photons', '200000', '--quiet']);
for (const image of ['exr', 'png']) {
  run(['lightmap', sceneFile, join(out, 'grid.vdb'), '-o', join(out, `cornell-${image}.glb`),
       '--image', image, '--quiet']);
}
run(['render', sceneFile, join(out, 'grid.vdb'), '--lighting', 'atlas', '--mode', 'indirect',
     '--width', String(size), '--height', String(size), '-o', join(out, 'ours-indirect.png'), '--quiet']);
// The light fixture's own pixels are left out: the renderer's indirect mode
// draws it black, three.js its emission.
run(['reference', sceneFile, '-o', join(out, 'first-hit.exr'), '--width', String(size), '--height',
     String(size), '--spp', '1', '--emitter-mask', join(out, 'emitter-mask.png'), '--quiet']);

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
  for (const [name, glb] of [['exr', 'cornell-exr.glb'], ['rgbm', 'cornell-png.glb']]) {
    const page = await browser.newPage();
    page.on('console', (m) => { if (m.type() === 'error') console.log(`  browser: ${m.text()}`); });
    await page.goto(`${origin}/tests/web/lightmap.html?scene=/out/${glb}&width=${size}&height=${size}`);
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
    run(['compare', picture, join(out, 'ours-indirect.png'), '--mask', join(out, 'emitter-mask.png'),
         '--json', json]);
    const c = JSON.parse(readFileSync(json, 'utf8'));
    const ratio = c.mean_test_luminance / c.mean_reference_luminance;
    const ok = Math.abs(ratio - 1) <= 0.03 && result.info.materials > 0;
    console.log(`three.js ${name}: ${result.info.materials} materials, ${result.info.pages} page(s); ` +
                `mean brightness ${ratio.toFixed(4)} of render --lighting atlas --mode indirect, the fixture's ` +
                `pixels left out ` +
                `(target 0.97-1.03; rel. RMSE per pixel ${c.channels.Y.rel_rmse.toFixed(4)}): ` +
                `${ok ? 'ok' : 'FAILED'}; ${picture}`);
    if (!ok) failures++;
  }
} finally {
  await browser.close();
  server.close();
}
console.log(failures === 0 ? 'three.js lightmaps: all pictures match' : `${failures} failure(s)`);
process.exit(failures === 0 ? 0 : 1);
