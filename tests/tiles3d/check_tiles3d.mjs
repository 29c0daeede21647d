// gvio's 3D Tiles read by Cesium's own 3d-tiles-tools (pinned by this folder's lock file):
//   - the tileset upgrades to 3D Tiles 1.1 (upgrade), every point tile becoming glTF with one
//     vertex per point of its header;
//   - updateAlignment leaves the first tiles byte for byte (their padding already as the spec
//     says; each call starts node anew, so not every tile).
// node check_tiles3d.mjs TILESET_DIR WORK_DIR; exit 1 on a failed check.
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, readdirSync, rmSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const [tileset, work] = process.argv.slice(2);
const tools = join(dirname(fileURLToPath(import.meta.url)), 'node_modules', '.bin', '3d-tiles-tools');
const run = (...args) => execFileSync(tools, args, { stdio: ['ignore', 'pipe', 'pipe'] });
const failures = [];
const check = (ok, what) => {
  if (!ok) failures.push(what);
  if (!ok) console.error(`FAIL ${what}`);
};

rmSync(work, { recursive: true, force: true });
mkdirSync(work, { recursive: true });
const pnts = readdirSync(join(tileset, 'tiles')).filter((f) => f.endsWith('.pnts'));
check(pnts.length > 0, 'the tileset has point tiles');
const upgraded = join(work, 'upgraded');
run('upgrade', '-i', tileset, '-o', upgraded, '--targetVersion', '1.1', '-f');
const root = JSON.parse(readFileSync(join(upgraded, 'tileset.json')));
check(root.asset.version === '1.1', `upgraded tileset version ${root.asset.version}`);
let points = 0;
for (const name of pnts) {
  const file = join(tileset, 'tiles', name);
  const bytes = readFileSync(file);
  const ftJsonLength = bytes.readUInt32LE(12);
  const ft = JSON.parse(bytes.subarray(28, 28 + ftJsonLength).toString());
  points += ft.POINTS_LENGTH;
  const glb = join(upgraded, 'tiles', name.replace('.pnts', '.glb'));
  if (!existsSync(glb)) {
    check(false, `${name}: not converted by upgrade`);
    continue;
  }
  const g = readFileSync(glb);
  const jsonLength = g.readUInt32LE(12);
  const gltf = JSON.parse(g.subarray(20, 20 + jsonLength).toString());
  const position = gltf.meshes[0].primitives[0].attributes.POSITION;
  check(gltf.accessors[position].count === ft.POINTS_LENGTH,
    `${name}: glTF has ${gltf.accessors[position].count} vertices for ${ft.POINTS_LENGTH} points`);
}
for (const name of pnts.slice(0, 3)) {
  const aligned = join(work, name);
  run('updateAlignment', '-i', join(tileset, 'tiles', name), '-o', aligned, '-f');
  check(readFileSync(aligned).equals(readFileSync(join(tileset, 'tiles', name))),
    `${name}: updateAlignment changed it`);
}
console.log(`${pnts.length} point tiles, ${points} points: read by 3d-tiles-tools` +
  (failures.length ? `, ${failures.length} check(s) failed` : ''));
process.exit(failures.length ? 1 : 0);
