// Plots along the drive (uPlot): the horizontal error of each trajectory against the truth, and
// the image check's scores per keyframe (ZNCC, depth agreement, flags).
import uPlot from 'uplot';
import { trajectoryColors, hex } from './colors.js';

function plot(container, title, t, series, width) {
  const data = [t, ...series.map((s) => s.values)];
  return new uPlot(
    {
      title,
      width,
      height: 170,
      scales: { x: { time: false } },
      axes: [
        { stroke: '#9ab', grid: { stroke: '#223' }, label: 's' },
        { stroke: '#9ab', grid: { stroke: '#223' } },
      ],
      series: [
        { label: 't (s)' },
        ...series.map((s) => ({ label: s.label, stroke: s.color, width: 1.5, spanGaps: false,
          points: { show: s.points ?? false } })),
      ],
    },
    data,
    container,
  );
}

export function buildPlots(container, scene) {
  const width = 440;
  const made = [];
  if (scene.errors) {
    made.push(
      plot(container, 'horizontal error against the truth (m)', scene.errors.t,
        scene.errors.series.map((s) => ({
          label: s.name,
          values: s.horizontal_m,
          color: hex(trajectoryColors[s.name] ?? 0xffffff),
        })), width),
    );
  }
  if (scene.consistency && scene.consistency.t.length > 1) {
    const c = scene.consistency;
    made.push(
      plot(container, 'map against the recorded images (gvio consistency --images)', c.t, [
        { label: 'ZNCC', values: c.ncc, color: '#4ea3ff' },
        { label: 'depth agreement', values: c.depth_agreement, color: '#ffb04e' },
        { label: 'flagged', values: c.flagged.map((f) => (f ? 0 : null)), color: '#ff4040',
          points: true },
      ], width),
    );
  }
  return made;
}

// The report's headline figures and stage timings, as label/value rows.
export function reportRows(report) {
  const rows = [];
  const add = (label, v, unit = '') => {
    if (v !== undefined && v !== null) rows.push([label, typeof v === 'number' ? `${+v.toFixed(3)}${unit}` : String(v)]);
  };
  add('status', report.status);
  add('mode', report.mode);
  add('frames', report.counts?.frames);
  add('keyframes', report.counts?.keyframes);
  add('path length', report.evaluation?.path_length_m, ' m');
  add('APE fused (no alignment)', report.evaluation_fused?.ape_none?.rmse, ' m');
  add('APE VIO (SE3-aligned)', report.evaluation?.ape_se3?.rmse, ' m');
  add('GNSS fixes', report.gnss?.fixes);
  add('GNSS fixes rejected', report.gnss?.rejected);
  add('loops accepted', report.loops?.accepted);
  add('time per frame', report.timing_ms?.total?.mean, ' ms');
  add('run wall time', report.run_wall_s, ' s');
  add('peak memory', report.peak_rss_mb, ' MB');
  for (const [stage, s] of Object.entries(report.stage_wall_s ?? {})) add(`stage ${stage}`, s, ' s');
  return rows;
}
