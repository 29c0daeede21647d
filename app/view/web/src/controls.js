// The three ways to move: orbit around a point, top-down (pan and zoom a map), and fly (WASD to
// move along the view, Q/E down and up, drag to look around).
import * as THREE from 'three';
import { MapControls } from 'three/addons/controls/MapControls.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

class FlyControls {
  constructor(camera, element) {
    this.camera = camera;
    this.element = element;
    this.enabled = false;
    this.speed = 10; // m/s, set from the scene's size
    this.keys = new Set();
    this.euler = new THREE.Euler(0, 0, 0, 'ZXY');
    element.addEventListener('keydown', (e) => this.enabled && this.keys.add(e.key.toLowerCase()));
    element.addEventListener('keyup', (e) => this.keys.delete(e.key.toLowerCase()));
    element.addEventListener('pointermove', (e) => {
      if (!this.enabled || e.buttons !== 1) return;
      this.euler.setFromQuaternion(this.camera.quaternion, 'ZXY');
      this.euler.z -= e.movementX * 0.004;
      this.euler.x = THREE.MathUtils.clamp(this.euler.x - e.movementY * 0.004, 0.01, Math.PI - 0.01);
      this.camera.quaternion.setFromEuler(this.euler);
    });
  }

  update(dt) {
    if (!this.enabled || this.keys.size === 0) return false;
    const forward = new THREE.Vector3(0, 0, -1).applyQuaternion(this.camera.quaternion);
    const right = new THREE.Vector3(1, 0, 0).applyQuaternion(this.camera.quaternion);
    const step = this.speed * dt * (this.keys.has('shift') ? 4 : 1);
    const move = new THREE.Vector3();
    if (this.keys.has('w')) move.add(forward);
    if (this.keys.has('s')) move.sub(forward);
    if (this.keys.has('d')) move.add(right);
    if (this.keys.has('a')) move.sub(right);
    if (this.keys.has('e')) move.z += 1;
    if (this.keys.has('q')) move.z -= 1;
    this.camera.position.addScaledVector(move, step);
    return move.lengthSq() > 0;
  }
}

export class CameraRig {
  constructor(camera, element) {
    this.camera = camera;
    camera.up.set(0, 0, 1);
    this.orbit = new OrbitControls(camera, element);
    this.map = new MapControls(camera, element);
    this.fly = new FlyControls(camera, element);
    this.orbit.enableDamping = false;
    this.map.enableDamping = false;
    this.mode = 'orbit';
    this.setMode('orbit');
  }

  setMode(mode) {
    this.mode = mode;
    this.orbit.enabled = mode === 'orbit';
    this.map.enabled = mode === 'top';
    this.fly.enabled = mode === 'fly';
    if (mode === 'top') {
      const target = this.orbit.target.clone();
      const height = Math.max(this.camera.position.distanceTo(target), 10);
      this.camera.position.set(target.x, target.y + 1e-3, target.z + height);
      this.map.target.copy(target);
      this.map.update();
    } else if (mode === 'orbit') {
      this.orbit.target.copy(this.map.target);
      this.orbit.update();
    }
  }

  // Looks at `target` from `distance` metres, south of it and above.
  frame(target, distance) {
    this.camera.position.set(target.x, target.y - 0.8 * distance, target.z + 0.6 * distance);
    this.camera.near = Math.max(distance / 1e4, 0.01);
    this.camera.far = distance * 100;
    this.camera.updateProjectionMatrix();
    this.orbit.target.copy(target);
    this.map.target.copy(target);
    this.fly.speed = Math.max(distance / 10, 1);
    this.orbit.update();
  }

  // Returns true when the camera moved (a frame must be drawn).
  update(dt) {
    return this.fly.update(dt);
  }

  addEventListener(type, f) {
    this.orbit.addEventListener(type, f);
    this.map.addEventListener(type, f);
  }
}
