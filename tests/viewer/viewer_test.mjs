// Issue 62: gvio view's page in a real browser (Debian's chromium, headless, software GL: Mesa's
// llvmpipe, or SwiftShader with --gl swiftshader; chromium_gl.mjs), driven by playwright-core
// (pinned in app/view/web/package-lock.json). Opened from its folder (file://), the page must
//   - load with no console error and no failed data file,
//   - draw its first picture (the root node and the layers) and report when (first_picture_ms),
//   - draw non-background pixels in the 3-D view,
//   - show the expected trajectories, and the expected number of points in its octree,
//   - load and draw deeper octree levels when the camera moves in,
//   - show a keyframe's panel (and its image, when the site has images) when one is clicked,
//   - draw its tracks on the 2-D map (offline: the UTM grid) and the expected plots, and, with a
//     tile URL set, the web map tiles under the tracks (checkWebTiles),
//   - offer to colour the map by the image check's scores exactly when the site has them
//     (--image-check), and colour it so.
// Screenshots go to --shots. Prints one JSON line of figures; exits 1 on a failed check, 77 when
// chromium is missing (ctest: skipped).
//
// node viewer_test.mjs --site DIR --shots DIR [--trajectories a,b] [--points N] [--keyframes]
//                      [--plots N] [--image-check]
//                      [--chromium PATH] [--max-first-picture-ms MS] [--gl llvmpipe|swiftshader]
import { existsSync, mkdirSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { createRequire } from 'node:module';
import { chromiumArgs, rendererOf } from './chromium_gl.mjs';

const args = Object.fromEntries(
  process.argv.slice(2).reduce((acc, a, i, all) => {
    if (a.startsWith('--')) acc.push([a.slice(2), all[i + 1]?.startsWith('--') ? true : all[i + 1] ?? true]);
    return acc;
  }, []),
);
const chromiumPath = args.chromium ?? '/usr/bin/chromium';
if (!existsSync(chromiumPath)) {
  console.log(`skipped: no chromium at ${chromiumPath} (./setup.sh test installs Debian's)`);
  process.exit(77);
}
// playwright-core lives in the viewer's node_modules (one lock file for the page and its tests).
const require = createRequire(resolve(args.web ?? 'app/view/web', 'package.json'));
const { chromium } = require('playwright-core');

const failures = [];
const check = (ok, what) => {
  if (!ok) failures.push(what);
  console.error(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
};

// The 2-D map over web map tiles from a URL the user sets, the tile server stood in by the test:
// every tile one flat colour, served with CORS as public tile servers serve them. The tiles under
// every track point must be requested, at one zoom, by the slippy-map formula (OpenStreetMap's,
// not the page's code), at the deepest zoom whose extent of the tracks fits the 440 x 300 map
// with a 20 px margin; then drawn, with the tracks over them.
const kTileRgb = [214, 160, 64];
async function checkWebTiles(page, figures) {
  const png = await page.evaluate((rgb) => {
    const c = document.createElement('canvas');
    c.width = c.height = 256;
    const g = c.getContext('2d');
    g.fillStyle = `rgb(${rgb.join(',')})`;
    g.fillRect(0, 0, 256, 256);
    return c.toDataURL('image/png').split(',')[1];
  }, kTileRgb);
  const requested = [];
  await page.route('https://tiles.gvio.test/**', (route) => {
    requested.push(route.request().url());
    route.fulfill({ status: 200, contentType: 'image/png', body: Buffer.from(png, 'base64'),
      headers: { 'Access-Control-Allow-Origin': '*' } });
  });
  await page.evaluate(() => {
    const input = document.getElementById('map2d-canvas').nextElementSibling;
    input.value = 'https://tiles.gvio.test/{z}/{x}/{y}.png';
    input.dispatchEvent(new Event('change'));
  });
  // The tracks are drawn once every tile has answered: wait for pixels of neither kind.
  const countPixels = (rgb) => {
    const c = document.getElementById('map2d-canvas');
    const px = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let tile = 0, other = 0;
    for (let i = 0; i < px.length; i += 4) {
      const d = Math.abs(px[i] - rgb[0]) + Math.abs(px[i + 1] - rgb[1]) + Math.abs(px[i + 2] - rgb[2]);
      if (d <= 6) ++tile;
      else ++other;
    }
    return { tile, other, all: px.length / 4 };
  };
  await page.evaluate(`window.gvioTestCountPixels = ${countPixels}`);
  await page.waitForFunction((rgb) => window.gvioTestCountPixels(rgb).other > 200, kTileRgb, {
    timeout: 20000,
  });
  const drawn = await page.evaluate((rgb) => window.gvioTestCountPixels(rgb), kTileRgb);
  // Every track point as [lat, lon].
  const points = (await page.evaluate(() => window.gvioViewer.viewer.side2d.map.tracks.map((t) => t.lat_lon)))
    .flatMap((ll) => Array.from({ length: ll.length / 2 }, (_, i) => [ll[2 * i], ll[2 * i + 1]]));
  const tiles = requested.map((u) => u.match(/\/(\d+)\/(\d+)\/(\d+)\.png$/).slice(1).map(Number));
  const zooms = [...new Set(tiles.map((t) => t[0]))];
  check(zooms.length === 1, `the web tiles are requested at one zoom (${zooms})`);
  const z = zooms[0];
  // OpenStreetMap's slippy-map tile names, in world pixels at zoom z.
  const world = (lat, lon, zoom) => {
    const r = (lat * Math.PI) / 180, n = 256 * 2 ** zoom;
    return [((lon + 180) / 360) * n, ((1 - Math.log(Math.tan(r) + 1 / Math.cos(r)) / Math.PI) / 2) * n];
  };
  const have = new Set(tiles.map((t) => `${t[1]}/${t[2]}`));
  const extent = (zoom) => {
    const px = points.map(([lat, lon]) => world(lat, lon, zoom));
    const span = (k) => Math.max(...px.map((p) => p[k])) - Math.min(...px.map((p) => p[k]));
    return [span(0), span(1)];
  };
  const total = points.length;
  const missing = points.filter(([lat, lon]) => {
    const [x, y] = world(lat, lon, z);
    return !have.has(`${Math.floor(x / 256)}/${Math.floor(y / 256)}`);
  }).length;
  figures.web_tiles = { zoom: z, tiles: tiles.length, tile_share: +(drawn.tile / drawn.all).toFixed(3) };
  check(total > 0 && missing === 0,
    `web tiles: ${tiles.length} at zoom ${z}; ${missing} of ${total} track points on a tile not requested`);
  const [w, h] = extent(z), [w1, h1] = extent(z + 1);
  check(w < 400 && h < 260 && (z === 19 || w1 >= 400 || h1 >= 260),
    `zoom ${z} fits the tracks (${w.toFixed(0)} x ${h.toFixed(0)} px; ${w1.toFixed(0)} x ${h1.toFixed(0)} at ${z + 1})`);
  check(drawn.tile > 0.5 * drawn.all && drawn.other > 200,
    `the tiles drawn under the tracks (${drawn.tile} tile pixels, ${drawn.other} others of ${drawn.all})`);
  await page.screenshot({ path: `${shots}/map2d_tiles.png` });
}

const shots = resolve(args.shots);
mkdirSync(shots, { recursive: true });
const gl = args.gl ?? 'llvmpipe';
const browser = await chromium.launch({ executablePath: chromiumPath, args: chromiumArgs(gl) });
const figures = {};
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const errors = [];
  page.on('console', (m) => m.type() === 'error' && errors.push(m.text()));
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('requestfailed', (r) => errors.push(`failed: ${r.url()}`));
  const url = pathToFileURL(resolve(args.site, 'index.html')).href;
  await page.goto(url);
  figures.renderer = await rendererOf(page);
  check(figures.renderer.toLowerCase().includes(gl), `WebGL renders with ${gl}: ${figures.renderer}`);
  await page.waitForFunction(() => window.gvioViewer?.stats().firstPictureMs != null, null, {
    timeout: 30000,
  });
  const settle = () =>
    page.waitForFunction(
      () => {
        const s = window.gvioViewer.stats();
        return s.settled && s.frames > 0;
      },
      null,
      { timeout: 60000 },
    );
  await settle();
  await page.waitForTimeout(300);
  const first = await page.evaluate(() => window.gvioViewer.stats());
  figures.first_picture_ms = Math.round(first.firstPictureMs);
  const pixels = await page.evaluate(() => window.gvioViewer.nonBackgroundPixels());
  figures.overview_pixels = pixels;
  check(pixels > 1000, `the 3-D view draws ${pixels} non-background pixels (> 1000)`);
  if (args['max-first-picture-ms']) {
    const limit = Number(args['max-first-picture-ms']);
    check(first.firstPictureMs <= limit, `first picture ${figures.first_picture_ms} ms (<= ${limit})`);
  }
  if (args.trajectories) {
    const want = String(args.trajectories).split(',').sort();
    check(JSON.stringify([...first.trajectories].sort()) === JSON.stringify(want),
      `trajectories ${first.trajectories} (expected ${want})`);
  }
  if (args.points) {
    check(first.pointsTotal === Number(args.points), `octree points ${first.pointsTotal} (expected ${args.points})`);
  }
  await page.screenshot({ path: `${shots}/overview.png` });

  // The map coloured by the image check's scores: offered only where the site has them, and then
  // the points take colours they do not have by intensity.
  const modes = await page.evaluate(() => window.gvioViewer.colorModes());
  if (args['image-check']) {
    check(modes.includes('image check'), `colour modes ${modes} include the image check`);
    const grey = await page.evaluate(() => window.gvioViewer.pixelColors());
    await page.evaluate(() => window.gvioViewer.setColorMode('image check'));
    const scored = await page.evaluate(() => window.gvioViewer.pixelColors());
    figures.image_check_coloured_pixels = [grey.coloured, scored.coloured];
    check(scored.coloured > grey.coloured + 1000,
      `coloured by the image check: ${scored.coloured} coloured pixels (by intensity ${grey.coloured})`);
    await page.screenshot({ path: `${shots}/image_check.png` });
    await page.evaluate(() => window.gvioViewer.setColorMode('intensity'));
  } else {
    check(!modes.includes('image check'), `colour modes ${modes}: no image check without its scores`);
  }

  if (first.nodesTotal > 1) {
    // From far away only the top of the tree is drawn; in close to the densest leaf, deeper
    // nodes must load and be drawn.
    const far = await page.evaluate(() => {
      const b = window.gvioViewer.viewer.octree.root.bounds;
      const c = [(b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2];
      window.gvioViewer.lookAt(c, 20 * Math.hypot(b[3] - b[0], b[4] - b[1], b[5] - b[2]));
      return c;
    });
    await page.waitForTimeout(200);
    await settle();
    const distant = await page.evaluate(() => window.gvioViewer.stats());
    figures.deepest_far = distant.deepestDrawn;
    check(far !== null && distant.deepestDrawn >= 0, `from far away the root is drawn (deepest ${distant.deepestDrawn})`);
    const target = await page.evaluate(() => {
      const nodes = window.gvioViewer.viewer.octree.nodes;
      const leaf = nodes.filter((n) => n.children.length === 0).sort((a, b) => b.points - a.points)[0];
      const b = leaf.bounds;
      return { centre: [(b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2],
        size: Math.hypot(b[3] - b[0], b[4] - b[1], b[5] - b[2]), depth: leaf.depth };
    });
    await page.evaluate(([c, d]) => window.gvioViewer.lookAt(c, d), [target.centre, Math.max(target.size, 5)]);
    await page.waitForTimeout(200);
    await settle();
    await page.evaluate(() => window.gvioViewer.nonBackgroundPixels()); // one more frame
    await settle();
    const near = await page.evaluate(() => window.gvioViewer.stats());
    figures.deepest_overview = first.deepestDrawn;
    figures.deepest_near = near.deepestDrawn;
    check(near.deepestDrawn > distant.deepestDrawn,
      `moving in draws deeper levels (${distant.deepestDrawn} far -> ${near.deepestDrawn} near)`);
    // (Not "more nodes loaded than at the overview": the overview may already have loaded the
    // nodes drawn in close, whether it did depends on the timing of the loads.)
    figures.nodes_loaded_near = near.nodesLoaded;
    await page.screenshot({ path: `${shots}/near.png` });
    await page.evaluate(() => document.getElementById('app') && window.gvioViewer.viewer.resetView());
    await settle();
  }

  if (args.keyframes) {
    check(first.keyframes > 0, `${first.keyframes} keyframes`);
    await page.evaluate(() => window.gvioViewer.showKeyframes(true));
    await page.waitForTimeout(100);
    // A keyframe on screen and clear of the panel, clicked with the mouse.
    const pick = await page.evaluate(() => {
      const n = window.gvioViewer.stats().keyframes;
      for (let k = Math.floor(n / 2), i = 0; i < n; ++i, k = (k + 1) % n) {
        const p = window.gvioViewer.keyframeScreen(k);
        if (p && p[0] > 300 && p[0] < innerWidth - 20 && p[1] > 20 && p[1] < innerHeight - 20) return [k, p];
      }
      return null;
    });
    check(pick !== null, 'a keyframe is on screen');
    if (pick) {
      await page.mouse.click(pick[1][0], pick[1][1]);
      await page.waitForTimeout(200);
      const shown = await page.evaluate(() => ({
        selected: window.gvioViewer.selectedKeyframe(),
        visible: getComputedStyle(document.getElementById('keyframe')).display !== 'none',
        image: document.querySelector('#keyframe img')?.naturalWidth ?? null,
      }));
      check(shown.visible && shown.selected !== null, `clicking shows keyframe ${shown.selected}`);
      if (shown.image !== null) {
        await page.waitForFunction(() => document.querySelector('#keyframe img').complete);
        const w = await page.evaluate(() => document.querySelector('#keyframe img').naturalWidth);
        figures.keyframe_image_px = w;
        check(w > 0, `its image loads (${w} px wide)`);
      }
      await page.screenshot({ path: `${shots}/keyframe.png` });
    }
  }
  // The 2-D map (offline: the UTM grid) and the plots along the drive.
  const side = await page.evaluate(() => window.gvioViewer.show2d());
  figures.map2d_pixels = side.drawn;
  check(side.tracks === first.trajectories.length && side.drawn > 500,
    `the 2-D map draws ${side.tracks} tracks (${side.drawn} pixels)`);
  if (args.plots) {
    check(side.plots === Number(args.plots), `${side.plots} plots along the drive (expected ${args.plots})`);
  }
  await page.screenshot({ path: `${shots}/map2d.png` });
  if (side.tracks > 0) await checkWebTiles(page, figures);
  const last = await page.evaluate(() => window.gvioViewer.stats());
  check(last.failed.length === 0, `no data file failed (${last.failed.join('; ')})`);
  check(errors.length === 0, `no console error (${errors.join(' | ')})`);
  figures.points_total = last.pointsTotal;
  figures.nodes_total = last.nodesTotal;
  figures.js_heap_mb = Math.round(
    (await page.evaluate(() => performance.memory?.usedJSHeapSize ?? 0)) / 1e6,
  );
} finally {
  await browser.close();
}
console.log(JSON.stringify(figures));
if (failures.length > 0) {
  console.error(`${failures.length} check(s) failed`);
  process.exit(1);
}
