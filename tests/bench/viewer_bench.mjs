// The viewer's benchmark in the real browser (Debian's chromium, headless, software GL: Mesa's
// llvmpipe, or SwiftShader with --gl swiftshader; tests/viewer/chromium_gl.mjs): from
// navigation to the first picture, and the browser's memory (every chromium process's resident
// proportional set, summed) at the first picture, once the overview has settled and after
// moving in close, beside the floor: the same browser showing one cleared WebGL canvas. Prints
// one JSON line.
// node viewer_bench.mjs --site DIR [--web app/view/web] [--chromium PATH] [--shot FILE]
//                       [--gl llvmpipe|swiftshader]
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { createRequire } from 'node:module';
import { chromiumArgs, rendererOf } from '../viewer/chromium_gl.mjs';

const args = Object.fromEntries(
  process.argv.slice(2).reduce((acc, a, i, all) => {
    if (a.startsWith('--')) acc.push([a.slice(2), all[i + 1]]);
    return acc;
  }, []),
);
const require = createRequire(resolve(args.web ?? 'app/view/web', 'package.json'));
const { chromium } = require('playwright-core');

// The memory of the chromium processes started for this browser (their command lines hold
// playwright's temporary profile folder), in MB: the sum of their proportional set sizes (PSS,
// /proc/PID/smaps_rollup: a page shared by n processes counts 1/n in each, so the sum is what
// the browser holds in RAM; resident sizes would count the shared libraries once per process).
function browserPssMb(marker) {
  const out = execFileSync('ps', ['-eo', 'pid=,args='], { encoding: 'utf8' });
  let kb = 0;
  for (const line of out.split('\n')) {
    if (!line.includes(marker)) continue;
    try {
      const rollup = readFileSync(`/proc/${line.trim().split(/\s+/)[0]}/smaps_rollup`, 'utf8');
      kb += Number(/^Pss:\s+(\d+)/m.exec(rollup)?.[1] ?? 0);
    } catch {
      // the process ended meanwhile
    }
  }
  return Math.round(kb / 1024);
}

const gl = args.gl ?? 'llvmpipe';
const marker = 'playwright_chromiumdev_profile';
const viewport = { width: 1280, height: 800 };
const launch = () =>
  chromium.launch({ executablePath: args.chromium ?? '/usr/bin/chromium', args: chromiumArgs(gl) });
const figures = {};

// The floor no page of ours can go below: the same browser showing a page that only clears one
// WebGL 2 canvas of the view's size (the GL driver loaded, one context, its framebuffers), in a
// browser of its own so that no process of it lingers into the viewer's figures.
const floorPage = `<!doctype html><body style="margin:0"><canvas id="c"></canvas><script>
const c = document.getElementById('c'); c.width = innerWidth; c.height = innerHeight;
const g = c.getContext('webgl2'); g.clearColor(0, 0, 1, 1); g.clear(g.COLOR_BUFFER_BIT);
requestAnimationFrame(() => requestAnimationFrame(() => { window.drawn = true; }));
</script>`;
{
  const browser = await launch();
  try {
    const page = await browser.newPage({ viewport });
    await page.setContent(floorPage);
    await page.waitForFunction(() => window.drawn === true, null, { timeout: 60000 });
    await page.waitForTimeout(200);
    figures.pss_webgl_page_mb = browserPssMb(marker);
  } finally {
    await browser.close();
  }
}

const browser = await launch();
try {
  const page = await browser.newPage({ viewport });
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(pathToFileURL(resolve(args.site, 'index.html')).href);
  await page.waitForFunction(() => window.gvioViewer?.stats().firstPictureMs != null, null,
    { timeout: 120000, polling: 20 });
  figures.first_picture_ms = Math.round(await page.evaluate(() => window.gvioViewer.stats().firstPictureMs));
  figures.pss_first_picture_mb = browserPssMb(marker);
  const settle = () => page.waitForFunction(() => window.gvioViewer.stats().settled, null,
    { timeout: 120000 });
  await settle();
  let s = await page.evaluate(() => window.gvioViewer.stats());
  figures.overview = { points_drawn: s.pointsDrawn, nodes_loaded: s.nodesLoaded, deepest: s.deepestDrawn };
  figures.pss_overview_mb = browserPssMb(marker);
  // In close to the densest leaf.
  await page.evaluate(() => {
    const nodes = window.gvioViewer.viewer.octree.nodes;
    const leaf = nodes.filter((n) => n.children.length === 0).sort((a, b) => b.points - a.points)[0];
    const b = leaf.bounds;
    window.gvioViewer.lookAt([(b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2],
      Math.max(Math.hypot(b[3] - b[0], b[4] - b[1], b[5] - b[2]), 5));
  });
  await page.waitForTimeout(300);
  await settle();
  s = await page.evaluate(() => window.gvioViewer.stats());
  figures.near = { points_drawn: s.pointsDrawn, nodes_loaded: s.nodesLoaded, deepest: s.deepestDrawn };
  figures.pss_near_mb = browserPssMb(marker);
  figures.points_total = s.pointsTotal;
  figures.nodes_total = s.nodesTotal;
  figures.errors = errors.length + s.failed.length;
  // Asked last: its canvas would otherwise count in the figures above.
  figures.renderer = await rendererOf(page);
  if (!figures.renderer.toLowerCase().includes(gl)) {
    throw new Error(`WebGL rendered with ${figures.renderer}, not ${gl}`);
  }
  if (args.shot) await page.screenshot({ path: args.shot });
} finally {
  await browser.close();
}
console.log(JSON.stringify(figures));
