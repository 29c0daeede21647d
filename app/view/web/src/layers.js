// The scene's small layers, built once from data/scene.js: trajectories, GNSS fixes, loop edges,
// keyframe cameras (frusta), and the OctoMap voxels (data/voxels.js, loaded when first shown).
import * as THREE from 'three';
import { fixColors, trajectoryColor } from './colors.js';
import { decodeBase64, loadDataScript } from './data.js';

export function trajectoryLine(t, index) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(t.p, 3));
  const line = new THREE.Line(
    geometry,
    new THREE.LineBasicMaterial({ color: trajectoryColor(t, index) }),
  );
  line.name = t.name;
  return line;
}

export function fixPoints(fixes) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(fixes.p, 3));
  const colors = [];
  const c = new THREE.Color();
  for (const s of fixes.status) {
    c.setHex(fixColors[s] ?? 0x7f7f7f);
    colors.push(c.r, c.g, c.b);
  }
  geometry.setAttribute('color', new THREE.Float32BufferAttribute(colors, 3));
  return new THREE.Points(
    geometry,
    new THREE.PointsMaterial({ size: 6, sizeAttenuation: false, vertexColors: true }),
  );
}

export function loopEdges(loops) {
  const positions = [];
  const colors = [];
  const accepted = new THREE.Color(0xe377c2),
    rejected = new THREE.Color(0x999999);
  for (let i = 0; i < loops.accepted.length; ++i) {
    positions.push(...loops.a.slice(3 * i, 3 * i + 3), ...loops.b.slice(3 * i, 3 * i + 3));
    const c = loops.accepted[i] ? accepted : rejected;
    colors.push(c.r, c.g, c.b, c.r, c.g, c.b);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  geometry.setAttribute('color', new THREE.Float32BufferAttribute(colors, 3));
  return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ vertexColors: true }));
}

// Each keyframe's camera as a pyramid `depth` metres deep (the image's corners through the
// intrinsics), and its centre as a pickable point.
export function keyframeCameras(keyframes, depth) {
  const { width, height, fx, fy, cx, cy } = keyframes.camera;
  const corners = [
    [0, 0],
    [width, 0],
    [width, height],
    [0, height],
  ].map(([u, v]) => new THREE.Vector3(((u - cx) / fx) * depth, ((v - cy) / fy) * depth, depth));
  const lines = [];
  const centres = [];
  const pose = keyframes.pose;
  const q = new THREE.Quaternion(),
    o = new THREE.Vector3(),
    p = new THREE.Vector3();
  for (let k = 0; k < keyframes.t.length; ++k) {
    const b = 7 * k;
    o.set(pose[b], pose[b + 1], pose[b + 2]);
    q.set(pose[b + 4], pose[b + 5], pose[b + 6], pose[b + 3]);
    centres.push(o.x, o.y, o.z);
    const w = corners.map((c) => p.copy(c).applyQuaternion(q).add(o).clone());
    for (let i = 0; i < 4; ++i) {
      lines.push(o.x, o.y, o.z, w[i].x, w[i].y, w[i].z);
      const n = w[(i + 1) % 4];
      lines.push(w[i].x, w[i].y, w[i].z, n.x, n.y, n.z);
    }
  }
  const frusta = new THREE.BufferGeometry();
  frusta.setAttribute('position', new THREE.Float32BufferAttribute(lines, 3));
  const group = new THREE.Group();
  group.add(new THREE.LineSegments(frusta, new THREE.LineBasicMaterial({ color: 0xffd700 })));
  const pick = new THREE.BufferGeometry();
  pick.setAttribute('position', new THREE.Float32BufferAttribute(centres, 3));
  const points = new THREE.Points(
    pick,
    new THREE.PointsMaterial({ size: 5, sizeAttenuation: false, color: 0xffd700 }),
  );
  points.name = 'keyframe-centres';
  group.add(points);
  return group;
}

// data/voxels.js as one instanced cube per occupied leaf.
export async function loadVoxels() {
  const [n, base64, rgbBase64] = await loadDataScript('data/voxels.js', 'voxels');
  const bytes = decodeBase64(base64);
  const v = new Float32Array(bytes.buffer, bytes.byteOffset, 4 * n);
  const rgb = decodeBase64(rgbBase64);
  const mesh = new THREE.InstancedMesh(
    new THREE.BoxGeometry(1, 1, 1),
    new THREE.MeshBasicMaterial({ transparent: true, opacity: 0.35, depthWrite: false }),
    n,
  );
  const m = new THREE.Matrix4(),
    c = new THREE.Color();
  for (let i = 0; i < n; ++i) {
    const s = v[4 * i + 3];
    m.makeScale(s, s, s).setPosition(v[4 * i], v[4 * i + 1], v[4 * i + 2]);
    mesh.setMatrixAt(i, m);
    mesh.setColorAt(i, c.setRGB(rgb[3 * i] / 255, rgb[3 * i + 1] / 255, rgb[3 * i + 2] / 255));
  }
  mesh.frustumCulled = false;
  return mesh;
}

// The image check's keyframes (gvio consistency --images) where they were checked: ZNCC from red
// (0) through yellow to green (1), the flagged ones magenta and larger, unscored ones grey.
export function imageCheckMarkers(c) {
  const positions = [],
    colors = [];
  const color = new THREE.Color();
  for (let i = 0; i < c.t.length; ++i) {
    const p = c.p.slice(3 * i, 3 * i + 3);
    if (p.some((v) => v === null)) continue;
    positions.push(...p);
    if (c.flagged[i]) color.setHex(0xff00ff);
    else if (c.ncc[i] === null) color.setHex(0x808080);
    else color.setHSL((Math.min(Math.max(c.ncc[i], 0), 1) * 120) / 360, 0.9, 0.5);
    colors.push(color.r, color.g, color.b);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  geometry.setAttribute('color', new THREE.Float32BufferAttribute(colors, 3));
  return new THREE.Points(
    geometry,
    new THREE.PointsMaterial({ size: 7, sizeAttenuation: false, vertexColors: true }),
  );
}
