// Issue 62: the map's points coloured by the image check (app/view/web/src/check_scores.js): each
// point takes the code of the checked keyframe nearest to it within 30 m. Plain node, no browser.
//   node tests/viewer/check_scores_test.mjs
import assert from 'node:assert/strict';
import { CheckScores, encodeNcc, kFlagged, kNoScore, kRadiusM } from '../../app/view/web/src/check_scores.js';

// Keyframes along x every 10 m: ZNCC 0.5, no score, 0.9 flagged, one without a position.
const c = {
  t: [0, 1, 2, 3],
  p: [0, 0, 0, 10, 0, 0, 20, 0, 0, null, null, null],
  ncc: [0.5, null, 0.9, 0.7],
  flagged: [false, false, true, false],
};
const s = new CheckScores(c);
assert.equal(s.size, 3, 'the keyframe without a position is left out');
assert.equal(s.codeAt(1, 2, 0), encodeNcc(0.5));
assert.equal(s.codeAt(9, -1, 0), kNoScore, 'nearest is the unscored keyframe');
assert.equal(s.codeAt(21, 0, 5), kFlagged);
assert.equal(s.codeAt(20 + kRadiusM - 0.5, 0, 0), kFlagged, 'within the radius');
assert.equal(s.codeAt(20 + kRadiusM + 0.5, 0, 0), kNoScore, 'beyond the radius');
assert.equal(s.codeAt(-kRadiusM - 0.5, 0, 0), kNoScore);
// Grid cells do not hide a nearer keyframe across a cell border (negative coordinates too).
assert.equal(s.codeAt(-0.1, -29.9, 0), encodeNcc(0.5));
// ZNCC clamped to [0, 1] and coded 1..254, never the codes of "none" and "flagged".
assert.equal(encodeNcc(-0.3), 1);
assert.equal(encodeNcc(1.4), 254);
assert.equal(encodeNcc(0.5), 128);
// A node's quantised points: p = cube_min + q / 65535 * size.
const q = new Uint16Array([0, 0, 0, 65535, 0, 0, 32768, 65535, 0]);
assert.deepEqual([...s.codesOf(q, 3, [0, 0, 0, 20])], [encodeNcc(0.5), kFlagged, kNoScore]);
// No scores at all: every point none.
assert.deepEqual([...new CheckScores({ t: [], p: [], ncc: [], flagged: [] }).codesOf(q, 3, [0, 0, 0, 20])],
  [kNoScore, kNoScore, kNoScore]);
console.log('check_scores: ok');
