// gvio view's page: the scene of data/scene.js in three.js, the point octree streamed from
// data/points, and a test interface (window.gvioViewer) for the browser tests.
import * as THREE from 'three';
import css from './style.css';
import { CameraRig } from './controls.js';
import { fixColors, trajectoryColor } from './colors.js';
import { deliver } from './data.js';
import {
  fixPoints,
  imageCheckMarkers,
  keyframeCameras,
  loadVoxels,
  loopEdges,
  trajectoryLine,
} from './layers.js';
import { CheckScores } from './check_scores.js';
import { PointOctree } from './octree.js';
import { colorModes, makePointMaterial } from './point_material.js';
import { buildPanel } from './ui.js';
import { Map2d } from './map2d.js';
import { buildPlots } from './plots.js';
import uplotCss from 'uplot/dist/uPlot.min.css';

const kBackground = 0x101418;

class Viewer {
  constructor(root, scene) {
    this.data = scene;
    this.renderer = new THREE.WebGLRenderer({ antialias: false });
    this.renderer.setPixelRatio(1);
    this.renderer.setClearColor(kBackground);
    this.renderer.domElement.id = 'view';
    this.renderer.domElement.tabIndex = 0;
    root.append(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(60, 1, 0.1, 1e5);
    this.rig = new CameraRig(this.camera, this.renderer.domElement);
    this.rig.addEventListener('change', () => this.requestRender());
    this.layers = [];
    this.material = makePointMaterial();
    this.octree = null;
    this.frames = 0;
    this.firstPictureMs = null;
    this.errors = [];
    this.build(scene);
    this.panel = buildPanel(root, this, scene);
    this.bounds = this.sceneBounds();
    this.resetView();
    addEventListener('resize', () => this.resize());
    this.resize();
    this.renderer.domElement.addEventListener('pointerdown', (e) => (this.down = [e.clientX, e.clientY]));
    this.renderer.domElement.addEventListener('pointerup', (e) => this.onClick(e));
    this.last = performance.now();
    this.loop();
  }

  addLayer(label, object, visible, color, onShow) {
    const layer = { label, object, visible, color, onShow };
    if (object) {
      object.visible = visible;
      this.scene.add(object);
    }
    this.layers.push(layer);
    return layer;
  }

  build(s) {
    if (s.points) {
      this.octree = new PointOctree(s.points, this.material, this.scene);
      this.octree.onLoad = () => this.requestRender();
      // Set before any node loads: a node's arrays are freed once on the GPU.
      if (s.consistency && s.consistency.t.length > 0) {
        const scores = new CheckScores(s.consistency);
        if (scores.size > 0) this.octree.scores = scores;
      }
      const b = this.octree.root.bounds;
      this.material.uniforms.uHeightRange.value.set(b[2], b[5]);
      this.addLayer('dense points', null, true, undefined);
      this.layers.at(-1).setVisible = (on) => (this.material.uniforms.uShowDense.value = on);
      this.addLayer('landmarks', null, true, 0xe63333);
      this.layers.at(-1).setVisible = (on) => (this.material.uniforms.uShowSparse.value = on);
    }
    s.trajectories.forEach((t, i) => {
      if (t.p.length >= 6) this.addLayer(t.label, trajectoryLine(t, i), true, trajectoryColor(t, i));
    });
    if (s.fixes && s.fixes.status.length > 0) {
      this.addLayer(`GNSS fixes (${s.fixes.status.length})`, fixPoints(s.fixes), true, fixColors.used);
    }
    if (s.loops && s.loops.accepted.length > 0) {
      const n = s.loops.accepted.filter((a) => a).length;
      this.addLayer(`loops (${n} accepted, ${s.loops.accepted.length - n} rejected)`,
        loopEdges(s.loops), true, 0xe377c2);
    }
    if (s.keyframes && s.keyframes.t.length > 0) {
      const extent = this.roughExtent(s);
      this.keyframeLayer = this.addLayer(`keyframes (${s.keyframes.t.length})`,
        keyframeCameras(s.keyframes, Math.max(extent / 200, 0.5)), false, 0xffd700);
    }
    if (s.consistency && s.consistency.t.length > 0) {
      const flagged = s.consistency.flagged.filter((f) => f).length;
      this.addLayer(`image check (${flagged} of ${s.consistency.t.length} flagged)`,
        imageCheckMarkers(s.consistency), true, 0xff00ff);
    }
    if (s.voxels) {
      this.addLayer(`OctoMap voxels (${s.voxels.count})`, null, false, 0x88aacc, async (layer) => {
        layer.object = await loadVoxels();
        this.scene.add(layer.object);
      });
    }
  }

  roughExtent(s) {
    const box = new THREE.Box3();
    for (const t of s.trajectories) {
      for (let i = 0; i < t.p.length; i += 3) box.expandByPoint(new THREE.Vector3(t.p[i], t.p[i + 1], t.p[i + 2]));
    }
    return box.isEmpty() ? 100 : box.getSize(new THREE.Vector3()).length();
  }

  sceneBounds() {
    const box = new THREE.Box3();
    if (this.octree) box.union(this.octree.root.box);
    for (const l of this.layers) {
      if (l.object && l.object.isLine) {
        l.object.geometry.computeBoundingBox();
        box.union(l.object.geometry.boundingBox);
      }
    }
    if (box.isEmpty()) box.set(new THREE.Vector3(-10, -10, -1), new THREE.Vector3(10, 10, 1));
    return box;
  }

  resetView() {
    const size = this.bounds.getSize(new THREE.Vector3());
    this.rig.frame(this.bounds.getCenter(new THREE.Vector3()), Math.max(size.length() * 0.7, 5));
    this.requestRender();
  }

  async setLayerVisible(layer, on) {
    layer.visible = on;
    if (layer.input) layer.input.checked = on;
    if (layer.setVisible) layer.setVisible(on);
    if (on && !layer.object && layer.onShow) await layer.onShow(layer);
    if (layer.object) layer.object.visible = on;
    this.requestRender();
  }

  setColorMode(mode) {
    if (!colorModes.includes(mode) || (mode === 'image check' && !this.octree?.scores)) {
      throw new Error(`no colour mode '${mode}' for this map`);
    }
    this.material.uniforms.uColorMode.value = colorModes.indexOf(mode);
    const select = document.getElementById('color-mode');
    if (select) select.value = mode;
    this.requestRender();
  }

  setPointSize(px) {
    this.material.uniforms.uPointSize.value = px;
    this.requestRender();
  }

  setPointBudget(points) {
    this.octree.pointBudget = points;
    this.requestRender();
  }

  resize() {
    const w = innerWidth,
      h = innerHeight;
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  requestRender() {
    this.dirty = true;
  }

  // Draws when something changed, and keeps the octree fed while nodes are loading.
  loop() {
    requestAnimationFrame(() => this.loop());
    const now = performance.now();
    const moved = this.rig.update((now - this.last) / 1000);
    this.last = now;
    if (!this.dirty && !moved) return;
    this.dirty = false;
    this.draw();
  }

  draw() {
    if (this.octree) this.octree.update(this.camera, this.renderer.domElement.height);
    this.renderer.render(this.scene, this.camera);
    ++this.frames;
    const pictured = !this.octree || this.octree.drawnNodes > 0;
    if (pictured && this.firstPictureMs === null) this.firstPictureMs = performance.now();
    this.panel.setStats(this.statsText());
  }

  statsText() {
    const o = this.octree;
    const lines = [];
    if (o) {
      const total = this.data.points.count;
      lines.push(`points drawn ${o.drawnPoints.toLocaleString()} of ${total.toLocaleString()}`);
      lines.push(`nodes drawn ${o.drawnNodes}, loaded ${o.loadedNodes} of ${o.nodes.length}`);
      lines.push(`deepest level drawn ${o.deepestDrawn}`);
    }
    lines.push(`frames ${this.frames}`);
    return lines.join('\n');
  }

  // The 2-D map and the plots, made when first shown.
  toggle2d(side) {
    if (!this.side2d) {
      this.side2d = { map: new Map2d(side, this.data), plots: buildPlots(side, this.data) };
    }
    side.style.display = side.style.display === 'block' ? 'none' : 'block';
    return { tracks: this.side2d.map.tracks.length, plots: this.side2d.plots.length };
  }

  // The keyframe nearest the click (within 10 px) when the pointer did not drag.
  onClick(e) {
    if (!this.down || Math.hypot(e.clientX - this.down[0], e.clientY - this.down[1]) > 3) return;
    if (!this.keyframeLayer || !this.keyframeLayer.visible) return;
    let best = -1,
      bestPx = 10;
    for (let k = 0; k < this.data.keyframes.t.length; ++k) {
      const p = this.keyframeScreen(k);
      if (!p) continue;
      const d = Math.hypot(p[0] - e.clientX, p[1] - e.clientY);
      if (d < bestPx) [best, bestPx] = [k, d];
    }
    if (best >= 0) this.showKeyframe(best);
  }

  keyframeScreen(k) {
    const pose = this.data.keyframes.pose;
    const v = new THREE.Vector3(pose[7 * k], pose[7 * k + 1], pose[7 * k + 2]).project(this.camera);
    if (v.z < -1 || v.z > 1) return null;
    const r = this.renderer.domElement.getBoundingClientRect();
    return [r.left + ((v.x + 1) / 2) * r.width, r.top + ((1 - v.y) / 2) * r.height];
  }

  showKeyframe(k) {
    const kf = this.data.keyframes;
    const image = kf.images ? kf.images[k] : null;
    this.selectedKeyframe = k;
    const start = this.data.trajectories.find((t) => t.t.length > 0)?.t[0] ?? kf.t[0];
    this.panel.showKeyframe({
      title: `keyframe ${k}: ${(kf.t[k] - start).toFixed(2)} s into the drive`,
      image,
      note: image ? null : 'no image in this site',
    });
  }

  // The 3-D view's pixels, drawn now, counted by colour: grey, magenta and other colours (the
  // background left out).
  pixelColors() {
    const px = this.readPixels();
    const bg = [(kBackground >> 16) & 255, (kBackground >> 8) & 255, kBackground & 255];
    const out = { grey: 0, magenta: 0, coloured: 0 };
    for (let i = 0; i < px.length; i += 4) {
      const [r, g, b] = [px[i], px[i + 1], px[i + 2]];
      if (Math.abs(r - bg[0]) + Math.abs(g - bg[1]) + Math.abs(b - bg[2]) <= 6) continue;
      if (Math.max(r, g, b) - Math.min(r, g, b) < 24) ++out.grey;
      else if (r > 200 && b > 200 && g < 60) ++out.magenta;
      else ++out.coloured;
    }
    return out;
  }

  readPixels() {
    this.draw();
    const gl = this.renderer.getContext();
    const pixels = new Uint8Array(4 * gl.drawingBufferWidth * gl.drawingBufferHeight);
    gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA, gl.UNSIGNED_BYTE,
      pixels);
    return pixels;
  }

  // Pixels of the 3-D view that are not the background, drawn now.
  nonBackgroundPixels() {
    const c = this.pixelColors();
    return c.grey + c.magenta + c.coloured;
  }
}

function testInterface(viewer) {
  return {
    viewer,
    stats() {
      const o = viewer.octree;
      return {
        trajectories: viewer.data.trajectories.filter((t) => t.p.length >= 6).map((t) => t.name),
        fixes: viewer.data.fixes ? viewer.data.fixes.status.length : 0,
        loops: viewer.data.loops ? viewer.data.loops.accepted.length : 0,
        keyframes: viewer.data.keyframes ? viewer.data.keyframes.t.length : 0,
        pointsTotal: viewer.data.points ? viewer.data.points.count : 0,
        pointsDrawn: o ? o.drawnPoints : 0,
        pointsLoaded: o ? o.loadedPoints : 0,
        nodesTotal: o ? o.nodes.length : 0,
        nodesLoaded: o ? o.loadedNodes : 0,
        loading: o ? o.loading : 0,
        settled: o ? o.settled : true,
        deepestDrawn: o ? o.deepestDrawn : -1,
        frames: viewer.frames,
        firstPictureMs: viewer.firstPictureMs,
        failed: o ? o.failed : [],
      };
    },
    // Moves the camera to look at [x, y, z] from `distance` metres.
    lookAt(target, distance) {
      viewer.rig.frame(new THREE.Vector3(...target), distance);
      viewer.requestRender();
    },
    nonBackgroundPixels: () => viewer.nonBackgroundPixels(),
    setColorMode: (mode) => viewer.setColorMode(mode),
    colorModes: () => [...document.querySelectorAll('#color-mode option')].map((o) => o.value),
    pixelColors: () => viewer.pixelColors(),
    showKeyframes(on) {
      return viewer.setLayerVisible(viewer.keyframeLayer, on);
    },
    keyframeScreen: (k) => viewer.keyframeScreen(k),
    selectedKeyframe: () => viewer.selectedKeyframe ?? null,
    // Opens the 2-D panel; returns the tracks and plots it drew and the map's drawn pixels.
    show2d() {
      const side = document.getElementById('panel2d');
      if (side.style.display !== 'block') viewer.toggle2d(side);
      const c = document.getElementById('map2d-canvas');
      const px = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let drawn = 0;
      for (let i = 0; i < px.length; i += 4) if (px[i] + px[i + 1] + px[i + 2] > 120) ++drawn;
      return { tracks: viewer.side2d.map.tracks.length, plots: viewer.side2d.plots.length, drawn };
    },
  };
}

window.gvioScene = (scene) => {
  const style = document.createElement('style');
  style.textContent = uplotCss + css;
  document.head.append(style);
  const viewer = new Viewer(document.getElementById('app'), scene);
  window.gvioViewer = testInterface(viewer);
};
window.gvioChunk = (name, n, base64) => deliver(`chunk:${name}`, n, base64);
window.gvioVoxels = (n, base64, rgb) => deliver('voxels', n, base64, rgb);
