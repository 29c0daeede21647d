// The points' shader: an octree node's positions arrive as uint16 in its cube (the object's
// position and scale turn them into the scene frame), colour is chosen by a uniform.
import * as THREE from 'three';
import { drivePalette } from './colors.js';

// 'image check' needs the image check's scores (octree.scores): the page offers it only then.
export const colorModes = ['intensity', 'height', 'drive', 'kind', 'image check'];

const vertexShader = /* glsl */ `
in float drive;
in float intensity;
in float kind;
in float score;  // check_scores.js: 0 none, 1..254 ZNCC 0..1, 255 flagged
uniform float uPointSize;
uniform int uColorMode;
uniform vec2 uHeightRange;
uniform bool uShowSparse;
uniform bool uShowDense;
uniform vec3 uPalette[${drivePalette.length}];
out vec3 vColor;

// Turbo colour map, polynomial approximation (Mikhailov 2019, Google AI blog).
vec3 turbo(float x) {
  const vec4 kR4 = vec4(0.13572138, 4.61539260, -42.66032258, 132.13108234);
  const vec4 kG4 = vec4(0.09140261, 2.19418839, 4.84296658, -14.18503333);
  const vec4 kB4 = vec4(0.10667330, 12.64194608, -60.58204836, 110.36276771);
  const vec2 kR2 = vec2(-152.94239396, 59.28637943);
  const vec2 kG2 = vec2(4.27729857, 2.82956604);
  const vec2 kB2 = vec2(-89.90310912, 27.34824973);
  x = clamp(x, 0.0, 1.0);
  vec4 v4 = vec4(1.0, x, x * x, x * x * x);
  vec2 v2 = v4.zw * v4.z;
  return vec3(dot(v4, kR4) + dot(v2, kR2), dot(v4, kG4) + dot(v2, kG2), dot(v4, kB4) + dot(v2, kB2));
}

void main() {
  bool sparse = kind < 0.5;
  if ((sparse && !uShowSparse) || (!sparse && !uShowDense)) {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume: not drawn
    gl_PointSize = 0.0;
    return;
  }
  vec4 world = modelMatrix * vec4(position, 1.0);
  gl_Position = projectionMatrix * viewMatrix * world;
  gl_PointSize = sparse ? uPointSize + 1.0 : uPointSize;
  if (uColorMode == 0) {
    float g = 0.15 + 0.85 * intensity;
    vColor = vec3(g);
  } else if (uColorMode == 1) {
    vColor = turbo((world.z - uHeightRange.x) / max(uHeightRange.y - uHeightRange.x, 1e-3));
  } else if (uColorMode == 2) {
    vColor = uPalette[int(mod(drive, ${drivePalette.length}.0))];
  } else if (uColorMode == 3) {
    vColor = sparse ? vec3(0.9, 0.2, 0.2) : vec3(0.6, 0.6, 0.65) * (0.4 + 0.6 * intensity);
  } else if (score < 0.5) {
    vColor = vec3(0.12 + 0.3 * intensity);  // no checked keyframe near: dim grey
  } else if (score > 254.5) {
    vColor = vec3(1.0, 0.0, 1.0);  // flagged: magenta, as the keyframe markers
  } else {
    // ZNCC from red (0) through yellow to green (1), as the keyframe markers.
    float x = (score - 1.0) / 253.0;
    vColor = vec3(min(1.0, 2.0 - 2.0 * x), min(1.0, 2.0 * x), 0.05);
  }
}
`;

const fragmentShader = /* glsl */ `
in vec3 vColor;
out vec4 outColor;
void main() { outColor = vec4(vColor, 1.0); }
`;

export function makePointMaterial() {
  return new THREE.ShaderMaterial({
    glslVersion: THREE.GLSL3,
    vertexShader,
    fragmentShader,
    uniforms: {
      uPointSize: { value: 2.0 },
      uColorMode: { value: 0 },
      uHeightRange: { value: new THREE.Vector2(0, 10) },
      uShowSparse: { value: true },
      uShowDense: { value: true },
      // sRGB components as they are: the shader writes its colours without conversion.
      uPalette: {
        value: drivePalette.map(
          (c) => new THREE.Vector3(((c >> 16) & 255) / 255, ((c >> 8) & 255) / 255, (c & 255) / 255),
        ),
      },
    },
  });
}
