// The image check's score carried onto the map's points: each point takes the ZNCC of the checked
// keyframe (gvio consistency --images) nearest to it, within kRadiusM; a flagged keyframe marks
// its points as flagged. The check scores a keyframe's view of the map, not single points, so
// this shows which part of the map a finding concerns (a flagged stretch's surroundings), not a
// per-point verdict. One byte per point: 0 no checked keyframe near (or no score), 1..254 ZNCC
// 0..1, 255 flagged.
export const kRadiusM = 30;
export const kNoScore = 0;
export const kFlagged = 255;

export class CheckScores {
  // c: scene.consistency ({t, p: [x y z]..., ncc, flagged}), positions in the scene frame.
  constructor(c) {
    this.cell = kRadiusM;
    this.grid = new Map(); // cell key (key(i, j)) -> keyframe indices
    this.p = [];
    this.code = [];
    for (let k = 0; k < c.t.length; ++k) {
      const p = c.p.slice(3 * k, 3 * k + 3);
      if (p.some((v) => v === null)) continue;
      const code = c.flagged[k] ? kFlagged : c.ncc[k] === null ? kNoScore : encodeNcc(c.ncc[k]);
      const id = this.p.length;
      this.p.push(p);
      this.code.push(code);
      const key = this.key(Math.floor(p[0] / this.cell), Math.floor(p[1] / this.cell));
      if (!this.grid.has(key)) this.grid.set(key, []);
      this.grid.get(key).push(id);
    }
  }

  get size() {
    return this.p.length;
  }

  // One number per cell (exact for |i|, |j| < 2^20 cells: 31,000 km at 30 m): a string key
  // would cost an allocation per cell looked at, nine per point.
  key(i, j) {
    return (i + 1048576) * 2097152 + (j + 1048576);
  }

  // The code of the keyframe nearest (x, y, z) within kRadiusM (ties: the first one met).
  codeAt(x, y, z) {
    const i0 = Math.floor(x / this.cell),
      j0 = Math.floor(y / this.cell);
    let best = kRadiusM * kRadiusM,
      code = kNoScore;
    for (let i = i0 - 1; i <= i0 + 1; ++i) {
      for (let j = j0 - 1; j <= j0 + 1; ++j) {
        const ids = this.grid.get(this.key(i, j));
        if (!ids) continue;
        for (const id of ids) {
          const p = this.p[id];
          const d = (p[0] - x) ** 2 + (p[1] - y) ** 2 + (p[2] - z) ** 2;
          if (d < best) {
            best = d;
            code = this.code[id];
          }
        }
      }
    }
    return code;
  }

  // Codes of a node's n points, quantised in its cube [min x y z, size] (view_points.hpp).
  codesOf(quantised, n, cube) {
    const out = new Uint8Array(n);
    const step = cube[3] / 65535;
    for (let k = 0; k < n; ++k) {
      out[k] = this.codeAt(
        cube[0] + quantised[3 * k] * step,
        cube[1] + quantised[3 * k + 1] * step,
        cube[2] + quantised[3 * k + 2] * step,
      );
    }
    return out;
  }
}

// ZNCC in [0, 1] (clamped) to 1..254.
export function encodeNcc(ncc) {
  return 1 + Math.round(Math.min(Math.max(ncc, 0), 1) * 253);
}
