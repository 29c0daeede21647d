// Colours shared by the 3-D view, its legend and the 2-D panel.

export const trajectoryColors = {
  fused: 0x1f77b4,
  online: 0x17becf,
  vio: 0xff7f0e,
  truth: 0x2ca02c,
};

export const fixColors = {
  used: 0x2ca02c,
  rejected: 0xd62728,
  skipped: 0x7f7f7f,
  unmatched: 0xbcbd22,
  unaligned: 0x9467bd,
};

// Drives of a merged map (point source ids), repeated past 10.
export const drivePalette = [
  0x1f77b4, 0xff7f0e, 0x2ca02c, 0xd62728, 0x9467bd, 0x8c564b, 0xe377c2, 0x7f7f7f, 0xbcbd22,
  0x17becf,
];

export function trajectoryColor(t, index) {
  if (t.drive !== undefined) return drivePalette[t.drive % drivePalette.length];
  return trajectoryColors[t.name] ?? drivePalette[index % drivePalette.length];
}

export function hex(color) {
  return '#' + color.toString(16).padStart(6, '0');
}
