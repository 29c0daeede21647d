// One screenshot of a gvio view site for the docs, in Debian's chromium (headless, llvmpipe),
// driven by playwright-core as viewer_test.mjs is: the page settled at its overview, the map
// coloured as asked, and, with --keyframe K, keyframe K clicked with the mouse (its panel and
// image shown). Writes a JPEG (or a PNG when FILE ends in .png); exits 1 when the page reports an
// error or keyframe K is not on screen.
// node docs_shot.mjs --site DIR --shot FILE [--color intensity|height|drive|kind|image check]
//                    [--keyframe K] [--web app/view/web] [--chromium PATH]
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { createRequire } from 'node:module';
import { chromiumArgs } from './chromium_gl.mjs';

const args = Object.fromEntries(
  process.argv.slice(2).reduce((acc, a, i, all) => {
    if (a.startsWith('--')) acc.push([a.slice(2), all[i + 1]]);
    return acc;
  }, []),
);
const require = createRequire(resolve(args.web ?? 'app/view/web', 'package.json'));
const { chromium } = require('playwright-core');

const browser = await chromium.launch({
  executablePath: args.chromium ?? '/usr/bin/chromium',
  args: chromiumArgs('llvmpipe'),
});
let failed = null;
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const errors = [];
  page.on('console', (m) => m.type() === 'error' && errors.push(m.text()));
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(pathToFileURL(resolve(args.site, 'index.html')).href);
  const settle = () =>
    page.waitForFunction(() => window.gvioViewer?.stats().settled && window.gvioViewer.stats().frames > 0,
      null, { timeout: 60000 });
  await settle();
  // setColorMode also shows the mode in the panel's select, as when a user picks it.
  if (args.color) await page.evaluate((mode) => window.gvioViewer.setColorMode(mode), args.color);
  if (args.keyframe !== undefined) {
    await page.evaluate(() => window.gvioViewer.showKeyframes(true));
    await page.waitForTimeout(200);
    const at = await page.evaluate((k) => window.gvioViewer.keyframeScreen(k), Number(args.keyframe));
    if (!at) throw new Error(`keyframe ${args.keyframe} is not on screen`);
    await page.mouse.click(at[0], at[1]);
    await page.waitForFunction(() => document.querySelector('#keyframe img')?.complete ?? true);
  }
  await page.evaluate(() => window.gvioViewer.nonBackgroundPixels()); // one more frame
  await settle();
  const png = String(args.shot).endsWith('.png');
  await page.screenshot({ path: args.shot, type: png ? 'png' : 'jpeg', ...(png ? {} : { quality: 85 }) });
  if (errors.length > 0) failed = `the page reported errors: ${errors.join(' | ')}`;
} finally {
  await browser.close();
}
if (failed) {
  console.error(`docs_shot: ${failed}`);
  process.exit(1);
}
console.log(`docs_shot: ${args.shot}`);
