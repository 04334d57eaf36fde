// The web viewer in a real browser, against the product's relight renderer.
//
//   node browser_test.mjs --project P.mlp --work DIR --node-modules DIR --fit vbrdf_fit
//                         --export vbrdf-web-export --reference vbrdf_web_reference --model-glsl FILE
//                         --grid-glsl FILE
//
// Steps (each fails the test with the reason):
//  1. fits the project (vbrdf_fit) and exports the result (vbrdf-web-export: GLB and both pages);
//  2. reads the GLB back: every attribute equals the result PLY's, float32 bit for bit
//     (vbrdf_web_reference check);
//  3. the Khronos glTF validator (npm gltf-validator): 0 errors, 0 warnings;
//  4. opens the embedded page from file:// in Debian's chromium (headless, WebGL2 on SwiftShader),
//     offline, with every request but the page's own blocked, and checks that it reports SwiftShader
//     and that its GLSL model is the text of --model-glsl exactly, and its vertex grid the text of
//     --grid-glsl;
//  5. renders 3 cameras x 8 lights into a float target (renderLinear) and compares them with the
//     relight renderer's images at the same cameras and lights (vbrdf_web_reference render):
//     pass when >= 99.9 % of the surface pixels are within one 8-bit sRGB level (exposure 1,
//     clipped at 1), >= 99.9 % within 8 levels, and the silhouette IoU is >= 0.999. Surface pixels: either image has surface;
//     pixels the relight renderer puts in cast shadow while the viewer lights them are left out
//     (the viewer has no cast shadows, as the live view) and counted;
//  6. the hosted page, served over loopback, loads the GLB by URL and renders the same pixels;
//  7. with VBRDF_WEB_MUTATIONS=1: the comparison must FAIL for a changed lobe term, a changed
//     diffuse term, a swapped lobe form and a dropped attribute (so it can fail);
//  8. with VBRDF_WEB_SCREENSHOT=FILE: a screenshot of the viewer (README).
// Exit 77 (skipped) with the reason when chromium or the npm packages are missing.
import { spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync, copyFileSync } from 'node:fs';
import { createServer } from 'node:http';
import { join, basename } from 'node:path';
import { pathToFileURL } from 'node:url';
import { createRequire } from 'node:module';

const args = process.argv.slice(2);
const opt = (name, fallback) => {
  const i = args.indexOf(name);
  if (i >= 0 && i + 1 < args.length) return args[i + 1];
  if (fallback !== undefined) return fallback;
  console.error(`browser_test.mjs: missing ${name}`);
  process.exit(2);
};
const project = opt('--project'), work = opt('--work'), nodeModules = opt('--node-modules');
const fitTool = opt('--fit'), exportTool = opt('--export'), referenceTool = opt('--reference');
const modelGlsl = opt('--model-glsl');
const gridGlsl = opt('--grid-glsl');
const chromiumPath = process.env.VBRDF_CHROMIUM || '/usr/bin/chromium';
const CAMERAS = Number(opt('--cameras', '3')), LIGHTS = Number(opt('--lights', '8')), WIDTH = Number(opt('--width', '0'));
// Tolerance (docs/web.md#checked-in-a-browser): both renderers put their vertices on the same
// 1/16-pixel grid (shaders/subpixel_grid.glsl), so the two rasterisers (llvmpipe, SwiftShader) differ
// only by float rounding.
const MIN_WITHIN = 0.999, MIN_WITHIN_WIDE = 0.999, MIN_IOU = 0.999, WIDE_LEVELS = 8;
const hist = {};

const skip = (why) => { console.log(`SKIP: ${why}`); process.exit(77); };
if (!existsSync(chromiumPath)) skip(`no chromium at ${chromiumPath} (Debian: apt-get install chromium; .ci/test.sh installs it)`);
for (const pkg of ['playwright-core', 'gltf-validator', 'three'])
  if (!existsSync(join(nodeModules, pkg, 'package.json')))
    skip(`${pkg} is not installed in ${nodeModules} (run 'npm ci' in filter_vertex_brdf/web; .ci/test.sh does)`);
const requireHere = createRequire(join(nodeModules, 'package.json'));
const { chromium } = requireHere('playwright-core');
const validator = requireHere('gltf-validator');

const failures = [];
const fail = (why) => { failures.push(why); console.log(`FAIL: ${why}`); };
const run = (cmd, argv) => {
  const r = spawnSync(cmd, argv, { encoding: 'utf8' });
  process.stdout.write(r.stdout || '');
  process.stdout.write(r.stderr || '');
  if (r.status !== 0) { console.log(`FAIL: ${basename(cmd)} ${argv.join(' ')} exited ${r.status}`); process.exit(1); }
};

rmSync(work, { recursive: true, force: true });
mkdirSync(work, { recursive: true });
const result = join(work, 'result.ply'), glb = join(work, 'model.glb');

// 1-2. Fit, export, read back.
run(fitTool, [project, '--out', result]);
const t0 = Date.now();
run(exportTool, [result, '--project', project, '--out', glb, '--overwrite']);
console.log(`export: ${Date.now() - t0} ms`);
run(referenceTool, ['check', result, glb]);

// 3. Validator.
const report = await validator.validateBytes(new Uint8Array(readFileSync(glb)), { maxIssues: 50 });
console.log(`gltf-validator ${report.validatorVersion}: ${report.issues.numErrors} errors, ${report.issues.numWarnings} warnings, ` +
            `${report.issues.numInfos} infos, ${report.issues.numHints} hints`);
if (report.issues.numErrors || report.issues.numWarnings)
  fail(`gltf-validator: ${JSON.stringify(report.issues.messages.slice(0, 5))}`);

// Reference renders.
run(referenceTool, ['render', result, project, work, '--cameras', String(CAMERAS), '--lights', String(LIGHTS), '--width', String(WIDTH)]);
const ref = JSON.parse(readFileSync(join(work, 'reference.json'), 'utf8'));

// 4. The page from file://, offline.
const profile = mkdtempSync('/tmp/vbrdf-chromium-');
const context = await chromium.launchPersistentContext(profile, {
  executablePath: chromiumPath, headless: true, viewport: { width: 1000, height: 700 }, offline: true,
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-background-networking',
         '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-gpu-driver-bug-workarounds'],
});
const pageUrl = pathToFileURL(join(work, 'model.html')).href;
const foreign = [];
await context.route('**/*', (route) => {
  const url = route.request().url();
  if (url === pageUrl) return route.continue();
  foreign.push(url);
  return route.abort();
});
const page = await context.newPage();
page.on('request', (r) => { const u = r.url(); if (u !== pageUrl && !u.startsWith('data:') && !u.startsWith('blob:')) foreign.push(u); });
page.on('pageerror', (e) => fail(`page error: ${e.message}`));
page.on('console', (m) => { if (m.type() === 'error' || m.type() === 'warning') console.log(`console ${m.type()}: ${m.text().slice(0, 2000)}`); });

async function openViewer(p, url) {
  const start = Date.now();
  await p.goto(url);
  await p.waitForFunction(() => document.body.dataset.ready === '1' || window.vbrdfError, null, { timeout: 120000 });
  const error = await p.evaluate(() => window.vbrdfError);
  if (error) { fail(`viewer: ${error}`); return null; }
  return { wallMs: Date.now() - start, ...(await p.evaluate(() => ({ loadMs: window.vbrdfViewer.loadMs, renderer: window.vbrdfViewer.rendererName() }))) };
}
const opened = await openViewer(page, pageUrl);
if (!opened) { await context.close(); process.exit(1); }
console.log(`renderer: ${opened.renderer}`);
if (!/SwiftShader/i.test(opened.renderer)) fail(`the page does not report SwiftShader: ${opened.renderer}`);
const pageGlsl = await page.evaluate(() => document.getElementById('vbrdf-model-glsl').textContent);
if (pageGlsl !== readFileSync(modelGlsl, 'utf8')) fail(`the page's GLSL model is not the text of ${modelGlsl}`);
else console.log(`GLSL model: the page carries ${modelGlsl} verbatim (${pageGlsl.length} characters)`);
const pageGrid = await page.evaluate(() => document.getElementById('vbrdf-grid-glsl').textContent);
if (pageGrid !== readFileSync(gridGlsl, 'utf8')) fail(`the page's vertex grid is not the text of ${gridGlsl}`);

// 5. Browser renders against the reference.
const srgbLevel = (x) => {
  const c = Math.min(Math.max(x, 0), 1);
  return Math.round(255 * (c <= 0.0031308 ? 12.92 * c : 1.055 * Math.pow(c, 1 / 2.4) - 0.055));
};
async function renderInPage(p, camera, light) {
  const b64 = await p.evaluate(({ view, projection, width, height, light }) => {
    const px = window.vbrdfViewer.renderLinear(view, projection, width, height, light);
    const bytes = new Uint8Array(px.buffer);
    let s = '';
    for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
    return btoa(s);
  }, { ...camera, width: ref.width, height: ref.height, light });
  const buf = Buffer.from(b64, 'base64');
  return new Float32Array(buf.buffer, buf.byteOffset, buf.length / 4);
}
function compare(web, refPx) {
  let union = 0, inter = 0, surface = 0, within = 0, withinWide = 0, castShadow = 0, worst = 0, edge = 0, classes = 0, values = 0;
  for (let i = 0; i < refPx.length; i += 4) {
    const rc = Math.round(refPx[i + 3]), wc = Math.round(web[i + 3]);
    const rs = rc !== 0, ws = wc !== 0;
    if (rs || ws) union++;
    if (rs && ws) inter++;
    if (!rs && !ws) continue;
    if (rc === 2 && wc === 1) { castShadow++; continue; }
    surface++;
    let d = 0;
    if (rs && ws && (rc === wc || (rc !== 3 && wc !== 3)))
      for (let k = 0; k < 3; ++k) d = Math.max(d, Math.abs(srgbLevel(refPx[i + k]) - srgbLevel(web[i + k])));
    else d = 255;
    if (d <= 1) within++;
    if (d <= WIDE_LEVELS) withinWide++;
    if (d > 1 && d < 255) hist[Math.min(d, 64)] = (hist[Math.min(d, 64)] || 0) + 1;
    if (d <= 1) {}
    else if (rs !== ws) edge++;
    else if (d === 255) classes++;
    else values++;
    worst = Math.max(worst, d);
  }
  return { union, inter, surface, within, withinWide, castShadow, worst, edge, classes, values };
}
async function compareAll(p, cameras, lights, label) {
  const total = { union: 0, inter: 0, surface: 0, within: 0, withinWide: 0, castShadow: 0, worst: 0, edge: 0, classes: 0, values: 0 };
  const perImage = [];
  for (const img of ref.images) {
    if (!cameras.includes(img.camera) || !lights.includes(img.light)) continue;
    const web = await renderInPage(p, ref.cameras[img.camera], ref.lights[img.light]);
    if (process.env.VBRDF_WEB_DUMP) writeFileSync(join(work, img.file.replace('ref_', 'web_')), Buffer.from(web.buffer, web.byteOffset, web.byteLength));
    const buf = readFileSync(join(work, img.file));
    const refPx = new Float32Array(buf.buffer, buf.byteOffset, buf.length / 4);
    const c = compare(web, refPx);
    perImage.push(`c${img.camera}l${img.light}: ${(100 * c.within / Math.max(c.surface, 1)).toFixed(3)}% IoU ${(c.inter / Math.max(c.union, 1)).toFixed(5)}`);
    for (const k of ['union', 'inter', 'surface', 'within', 'withinWide', 'castShadow', 'edge', 'classes', 'values']) total[k] += c[k];
    total.worst = Math.max(total.worst, c.worst);
  }
  total.fraction = total.within / Math.max(total.surface, 1);
  total.iou = total.inter / Math.max(total.union, 1);
  total.fractionWide = total.withinWide / Math.max(total.surface, 1);
  total.pass = total.fraction >= MIN_WITHIN && total.fractionWide >= MIN_WITHIN_WIDE && total.iou >= MIN_IOU;
  console.log(`${label}: ${total.within} of ${total.surface} surface pixels within one 8-bit sRGB level ` +
              `(${(100 * total.fraction).toFixed(3)} %, need ${100 * MIN_WITHIN} %; within ${WIDE_LEVELS} levels ${(100 * total.fractionWide).toFixed(3)} %, need ${100 * MIN_WITHIN_WIDE} %), silhouette IoU ${total.iou.toFixed(5)} ` +
              `(need ${MIN_IOU}), largest difference ${total.worst} levels, ${total.castShadow} cast-shadow pixels left out; ` +
              `outside one level: ${total.edge} silhouette, ${total.classes} lit / shadowed / unfitted disagreements, ${total.values} values`);
  return { total, perImage };
}
const all = (n) => [...Array(n).keys()];
const main = await compareAll(page, all(ref.cameras.length), all(ref.lights.length),
                              `browser vs relight renderer, ${ref.cameras.length} cameras x ${ref.lights.length} lights, ${ref.width}x${ref.height}`);
console.log('  per image: ' + main.perImage.join('; '));
console.log(`  within ${WIDE_LEVELS} levels: ${(100 * main.total.withinWide / main.total.surface).toFixed(3)} %; pixels by difference, 2..63 levels (64: more): ${JSON.stringify(hist)}`);
if (!main.total.pass) fail('the browser render does not match the relight renderer');

// 6. The hosted page over loopback: the GLB by URL.
const server = createServer((req, res) => {
  const name = decodeURIComponent(new URL(req.url, 'http://x').pathname).slice(1);
  if (!['model_hosted.html', 'model.glb'].includes(name)) { res.writeHead(404); res.end(); return; }
  res.writeHead(200, { 'content-type': name.endsWith('.html') ? 'text/html' : 'model/gltf-binary' });
  res.end(readFileSync(join(work, name)));
});
await new Promise((r) => server.listen(0, '127.0.0.1', r));
const base = `http://127.0.0.1:${server.address().port}/`;
await context.unroute('**/*');
await context.setOffline(false);
await context.route('**/*', (route) => {
  const url = route.request().url();
  if (url === base + 'model_hosted.html' || url === base + 'model.glb') return route.continue();
  foreign.push(url);
  return route.abort();
});
const hosted = await context.newPage();
hosted.on('pageerror', (e) => fail(`hosted page error: ${e.message}`));
const hostedOpened = await openViewer(hosted, base + 'model_hosted.html');
if (hostedOpened) {
  const a = await renderInPage(page, ref.cameras[0], ref.lights[0]);
  const b = await renderInPage(hosted, ref.cameras[0], ref.lights[0]);
  const same = a.length === b.length && a.every((v, i) => Object.is(v, b[i]));
  console.log(`hosted page (GLB by URL over loopback): ${same ? 'renders the same pixels' : 'DIFFERS'}`);
  if (!same) fail('the hosted page renders other pixels than the embedded one');
}
await hosted.close();
server.close();
const ownRequests = new Set([pageUrl]);
const blocked = foreign.filter((u) => !ownRequests.has(u));
if (blocked.length) fail(`requests other than the page's own: ${blocked.slice(0, 5).join(', ')}`);
else console.log('network: no request but the page\'s own (file://, offline; hosted: the page and its GLB)');

// 7. The comparison can fail.
if (process.env.VBRDF_WEB_MUTATIONS === '1') {
  const mutations = [
    ['lobe term (alpha x 1.1)', 'specular = specular_term(ks, alpha, lobe_cosine(n, l, e), v);',
     'specular = specular_term(ks, alpha * 1.1, lobe_cosine(n, l, e), v);'],
    ['diffuse term (x 1.02)', 'diffuse = rho * diffuse_factor(dot(n, l), dot(n, e), coated);',
     'diffuse = rho * (1.02 * diffuse_factor(dot(n, l), dot(n, e), coated));'],
  ];
  const lightsHalf = all(ref.lights.length).filter((j) => j % 2 === 0);
  for (const [label, from, to] of mutations) {
    const ok = await page.evaluate(({ from, to }) => {
      const m = window.vbrdfViewer.material;
      if (!m.fragmentShader.includes(from)) return false;
      window.__saved = m.fragmentShader;
      m.fragmentShader = m.fragmentShader.replace(from, to);
      m.needsUpdate = true;
      return true;
    }, { from, to });
    if (!ok) { fail(`mutation '${label}': the model text no longer holds '${from}'`); continue; }
    const r = await compareAll(page, [0], lightsHalf, `  changed ${label}`);
    if (r.total.pass) fail(`the comparison passes with a changed ${label}: it cannot catch that change`);
    await page.evaluate(() => { const m = window.vbrdfViewer.material; m.fragmentShader = window.__saved; m.needsUpdate = true; });
  }
  await page.evaluate(() => { const u = window.vbrdfViewer.material.uniforms; u.u_ggx_lobe.value = 1 - u.u_ggx_lobe.value; u.u_half_angle_lobe.value = 1; });
  if ((await compareAll(page, [0], lightsHalf, '  other lobe form')).total.pass) fail('the comparison passes with the other lobe form');
  await page.evaluate(() => { const u = window.vbrdfViewer.material.uniforms; u.u_ggx_lobe.value = 1 - u.u_ggx_lobe.value; });
  await page.evaluate(() => { const g = window.vbrdfViewer.geometry; window.__ks = g.getAttribute('a_ks'); g.deleteAttribute('a_ks'); });
  if ((await compareAll(page, [0], lightsHalf, '  attribute _KS dropped')).total.pass) fail('the comparison passes with _KS dropped');
  await page.evaluate(() => { window.vbrdfViewer.geometry.setAttribute('a_ks', window.__ks); });
  const back = await compareAll(page, [0], lightsHalf, '  restored');
  if (!back.total.pass) fail('the restored viewer does not pass again');
}

// 8. Screenshot and timings.
const frameMs = await page.evaluate(() => window.vbrdfViewer.measureFrames(10));
console.log(`timing (SwiftShader, software rendering, 1000x700 view): load ${opened.loadMs.toFixed(0)} ms (page to first frame ${opened.wallMs} ms), ` +
            `frame ${frameMs.toFixed(1)} ms (median of 10)`);
if (process.env.VBRDF_WEB_SCREENSHOT) {
  await page.evaluate(() => window.vbrdfViewer.draw());
  await page.screenshot({ path: process.env.VBRDF_WEB_SCREENSHOT });
  console.log(`screenshot: ${process.env.VBRDF_WEB_SCREENSHOT}`);
}
await context.close();
rmSync(profile, { recursive: true, force: true });
if (failures.length) { console.log(`${failures.length} failure(s)`); process.exit(1); }
console.log('PASS');
