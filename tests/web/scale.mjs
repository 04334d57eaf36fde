// Size and speed figures of the web export (docs/web.md#size-and-speed): for each vertex count, a
// synthetic result (vbrdf_web_reference synthesize: a bumpy sphere with a varied fit), exported
// with vbrdf-web-export, opened from file:// in headless chromium on SwiftShader (software
// rendering: a real GPU is far faster), 1000x700 view.
//   node scale.mjs --node-modules DIR --export vbrdf-web-export --reference vbrdf_web_reference --work DIR [N ...]
import { spawnSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, rmSync, statSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const args = process.argv.slice(2);
const opt = (n) => args[args.indexOf(n) + 1];
const counts = args.filter((a, i) => /^\d+$/.test(a) && !args[i - 1]?.startsWith('--'));
const work = opt('--work');
const { chromium } = createRequire(resolve(opt('--node-modules'), 'package.json'))('playwright-core');
mkdirSync(work, { recursive: true });
const run = (cmd, a) => {
  const t = Date.now();
  const r = spawnSync(cmd, a, { encoding: 'utf8' });
  if (r.status !== 0) throw new Error(`${cmd} ${a.join(' ')}: ${r.stderr}`);
  return Date.now() - t;
};
for (const n of counts.length ? counts : ['100000']) {
  const ply = join(work, `synth_${n}.ply`), glb = join(work, `synth_${n}.glb`);
  run(opt('--reference'), ['synthesize', n, ply]);
  const exportMs = run(opt('--export'), [ply, '--out', glb, '--overwrite']);
  const vertices = Number(spawnSync('head', ['-c', '400', ply], { encoding: 'latin1' }).stdout.match(/element vertex (\d+)/)[1]);
  const glbBytes = statSync(glb).size, htmlBytes = statSync(glb.replace(/\.glb$/, '.html')).size;
  const profile = mkdtempSync('/tmp/vbrdf-chromium-');
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.VBRDF_CHROMIUM || '/usr/bin/chromium', headless: true, offline: true,
    viewport: { width: 1000, height: 700 },
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox', '--disable-background-networking',
           '--disable-component-update', '--disable-sync', '--no-first-run'],
  });
  const page = await context.newPage();
  const t = Date.now();
  await page.goto(pathToFileURL(glb.replace(/\.glb$/, '.html')).href, { timeout: 600000 });
  await page.waitForFunction(() => document.body.dataset.ready === '1' || window.vbrdfError, null, { timeout: 600000 });
  const wallMs = Date.now() - t;
  const r = await page.evaluate(() => ({ load: window.vbrdfViewer.loadMs, frame: window.vbrdfViewer.measureFrames(10), renderer: window.vbrdfViewer.rendererName() }));
  await context.close();
  rmSync(profile, { recursive: true, force: true });
  console.log(`${vertices} vertices: GLB ${glbBytes} bytes (${(glbBytes / vertices).toFixed(1)} per vertex), page ${htmlBytes} bytes; ` +
              `export ${exportMs} ms; in chromium (SwiftShader, software): load ${r.load.toFixed(0)} ms (navigation to first frame ${wallMs} ms), ` +
              `frame ${r.frame.toFixed(0)} ms (median of 10, 1000x700)`);
}
