// The point octree of data/points (app/view/view_points.hpp): nodes are loaded as the camera
// comes near them and shown while their points are sparser on screen than minSpacingPx, nearest
// and largest first, within a point budget (Schuetz 2016, "Potree", sec. 4: nodes by projected
// size in a priority queue). Loaded nodes that are not drawn are dropped, oldest first, once the
// page holds twice the budget. Loading is fed from the last frame's wish list as each load
// ends, not only when a frame is drawn: with software GL a frame of millions of points takes
// half a second, and tying loads to frames held the view in close to a fifth of its points.
import * as THREE from 'three';
import { decodeBase64, loadDataScript } from './data.js';

const kMaxLoads = 4; // scripts in flight

export class PointOctree {
  constructor(index, material, parent) {
    this.material = material;
    this.group = new THREE.Group();
    parent.add(this.group);
    this.nodes = index.nodes.map((n) => ({
      ...n,
      box: new THREE.Box3(
        new THREE.Vector3(n.bounds[0], n.bounds[1], n.bounds[2]),
        new THREE.Vector3(n.bounds[3], n.bounds[4], n.bounds[5]),
      ),
      state: n.points > 0 ? 'none' : 'empty',
      object: null,
      lastDrawn: 0,
    }));
    this.pointBudget = 3_000_000;
    this.minSpacingPx = 3;
    this.loading = 0;
    this.queue = []; // nodes wanted by the last update, most wanted first
    this.stale = false; // a node loaded since the last update
    this.frame = 0;
    this.loadedPoints = 0;
    this.drawnPoints = 0;
    this.drawnNodes = 0;
    this.deepestDrawn = -1;
    this.onLoad = () => {};
    this.failed = [];
    this.scores = null; // a CheckScores: each loaded point gets its image-check code
  }

  get root() {
    return this.nodes[0];
  }

  // Chooses the nodes to draw from `camera` (a perspective camera) for a view `heightPx` tall,
  // and starts loading the nodes wanted next.
  update(camera, heightPx) {
    ++this.frame;
    this.stale = false;
    const frustum = new THREE.Frustum().setFromProjectionMatrix(
      new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse),
    );
    const pxPerMetre = heightPx / (2 * Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2));
    const eye = camera.position;
    const priority = (node) =>
      (node.box.getSize(tmpSize).length() * pxPerMetre) /
      Math.max(node.box.distanceToPoint(eye), 1e-3);
    const heap = [[priority(this.root), 0]];
    const wanted = [];
    let budget = this.pointBudget;
    let drawnPoints = 0,
      drawnNodes = 0,
      deepest = -1;
    while (heap.length > 0) {
      heap.sort((a, b) => a[0] - b[0]); // few hundred entries at most: sorting is cheap
      const [p, i] = heap.pop();
      const node = this.nodes[i];
      if (!frustum.intersectsBox(node.box)) continue;
      if (node.state !== 'empty') {
        if (node.state !== 'loaded') {
          if (node.state === 'none') wanted.push([p, node]);
          continue; // its children wait for it: coarse levels first
        }
        if (budget < node.points) break;
        budget -= node.points;
        node.lastDrawn = this.frame;
        drawnPoints += node.points;
        ++drawnNodes;
        deepest = Math.max(deepest, node.depth);
      }
      const spacingPx =
        (node.spacing * pxPerMetre) / Math.max(node.box.distanceToPoint(eye), 1e-3);
      if (node.spacing > 0 && spacingPx > this.minSpacingPx) {
        for (const c of node.children) heap.push([priority(this.nodes[c]), c]);
      }
    }
    for (const node of this.nodes) {
      if (node.object) node.object.visible = node.lastDrawn === this.frame;
    }
    this.drawnPoints = drawnPoints;
    this.drawnNodes = drawnNodes;
    this.deepestDrawn = deepest;
    wanted.sort((a, b) => b[0] - a[0]);
    this.queue = wanted.map(([, node]) => node);
    this.startLoads();
    this.evict();
  }

  startLoads() {
    while (this.loading < kMaxLoads && this.queue.length > 0) {
      const node = this.queue.shift();
      if (node.state === 'none') this.load(node);
    }
  }

  // Nothing loading, nothing more wanted, and the last update saw every load: the view shows
  // what it will show until the camera moves.
  get settled() {
    return this.loading === 0 && this.queue.length === 0 && !this.stale;
  }

  load(node) {
    node.state = 'loading';
    ++this.loading;
    loadDataScript(`data/points/${node.name}.js`, `chunk:${node.name}`)
      .then(([count, base64]) => {
        node.object = this.makeObject(node, count, decodeBase64(base64));
        node.state = 'loaded';
        this.loadedPoints += count;
        this.group.add(node.object);
      })
      .catch((error) => {
        node.state = 'failed';
        this.failed.push(String(error));
        console.error(error);
      })
      .finally(() => {
        --this.loading;
        this.stale = true;
        this.startLoads();
        this.onLoad(node);
      });
  }

  makeObject(node, n, bytes) {
    const buffer = bytes.buffer; // a fresh buffer of its own (decodeBase64)
    const geometry = new THREE.BufferGeometry();
    const quantised = new Uint16Array(buffer, 0, 3 * n);
    geometry.setAttribute('position', new THREE.BufferAttribute(quantised, 3, true));
    if (this.scores) {
      const codes = this.scores.codesOf(quantised, n, node.cube);
      geometry.setAttribute('score', new THREE.BufferAttribute(codes, 1));
    }
    geometry.setAttribute('drive', new THREE.BufferAttribute(new Uint16Array(buffer, 6 * n, n), 1));
    geometry.setAttribute(
      'intensity',
      new THREE.BufferAttribute(new Uint8Array(buffer, 8 * n, n), 1, true),
    );
    geometry.setAttribute('kind', new THREE.BufferAttribute(new Uint8Array(buffer, 9 * n, n), 1));
    // In the object's frame the points lie in the unit cube: bounds given, never computed (the
    // arrays are gone once uploaded).
    geometry.boundingBox = new THREE.Box3(new THREE.Vector3(0, 0, 0), new THREE.Vector3(1, 1, 1));
    geometry.boundingSphere = new THREE.Sphere(new THREE.Vector3(0.5, 0.5, 0.5), Math.sqrt(3) / 2);
    // Once on the GPU, the arrays are not needed again (the node is dropped, not edited): freed,
    // they would double what a loaded point costs the page.
    for (const attribute of Object.values(geometry.attributes)) {
      attribute.onUpload(function release() {
        this.array = null;
      });
    }
    const points = new THREE.Points(geometry, this.material);
    points.frustumCulled = false; // the octree culls by node
    points.position.set(node.cube[0], node.cube[1], node.cube[2]);
    points.scale.setScalar(node.cube[3]);
    points.visible = false;
    return points;
  }

  evict() {
    if (this.loadedPoints <= 2 * this.pointBudget) return;
    const idle = this.nodes
      .filter((n) => n.state === 'loaded' && n.lastDrawn !== this.frame && n !== this.root)
      .sort((a, b) => a.lastDrawn - b.lastDrawn);
    for (const node of idle) {
      if (this.loadedPoints <= this.pointBudget) break;
      this.group.remove(node.object);
      node.object.geometry.dispose();
      node.object = null;
      node.state = 'none';
      this.loadedPoints -= node.points;
    }
  }

  get loadedNodes() {
    return this.nodes.filter((n) => n.state === 'loaded').length;
  }
}

const tmpSize = new THREE.Vector3();
