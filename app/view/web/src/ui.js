// The side panel: layers, colours, cameras, the point budget, live statistics and the report.
import { colorModes } from './point_material.js';
import { hex } from './colors.js';
import { reportRows } from './plots.js';

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (k === 'text') e.textContent = v;
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}

export function checkbox(label, checked, onChange, color) {
  const input = el('input', { type: 'checkbox', onchange: () => onChange(input.checked) });
  input.checked = checked;
  const swatch = color === undefined ? '' : el('span', { class: 'swatch', style: `background:${hex(color)}` });
  return el('label', {}, input, swatch, ' ' + label);
}

// Builds the panel into `root`; `viewer` is main.js's viewer (layers, rig, octree, material).
export function buildPanel(root, viewer, scene) {
  const panel = el('div', { id: 'panel' });
  panel.append(el('h1', { text: `gvio view: ${scene.title}` }));
  const frame = scene.frame;
  panel.append(
    el('div', {
      text:
        frame.type === 'enu'
          ? `ENU at ${frame.lat_deg.toFixed(6)}, ${frame.lon_deg.toFixed(6)}`
          : frame.type === 'utm'
            ? `UTM zone ${frame.utm_zone}${frame.utm_north ? 'N' : 'S'}`
            : 'VIO world frame (not georeferenced)',
    }),
  );

  panel.append(el('h2', { text: 'Camera' }));
  const buttons = {};
  for (const mode of ['orbit', 'top', 'fly']) {
    buttons[mode] = el('button', {
      text: mode,
      id: `camera-${mode}`,
      onclick: () => {
        viewer.rig.setMode(mode);
        for (const [m, b] of Object.entries(buttons)) b.classList.toggle('active', m === mode);
        viewer.requestRender();
      },
    });
    panel.append(buttons[mode]);
  }
  buttons.orbit.classList.add('active');
  panel.append(el('button', { text: 'reset', onclick: () => viewer.resetView() }));

  panel.append(el('h2', { text: 'Layers' }));
  for (const layer of viewer.layers) {
    const box = checkbox(layer.label, layer.visible, (on) => viewer.setLayerVisible(layer, on),
      layer.color);
    layer.input = box.querySelector('input');
    panel.append(box);
  }

  if (viewer.octree) {
    panel.append(el('h2', { text: 'Points' }));
    const select = el('select', {
      id: 'color-mode',
      onchange: () => viewer.setColorMode(select.value),
    });
    for (const m of colorModes) {
      if (m === 'image check' && !viewer.octree.scores) continue;
      select.append(el('option', { value: m, text: `colour by ${m}` }));
    }
    panel.append(select);
    const size = el('input', { type: 'range', min: 1, max: 8, step: 0.5, value: 2 });
    size.addEventListener('input', () => viewer.setPointSize(Number(size.value)));
    panel.append(el('label', { text: 'point size' }), size);
    const budget = el('select', { onchange: () => viewer.setPointBudget(Number(budget.value)) });
    for (const b of [1e6, 3e6, 6e6, 12e6]) {
      const o = el('option', { value: b, text: `budget ${b / 1e6} M points` });
      if (b === viewer.octree.pointBudget) o.selected = true;
      budget.append(o);
    }
    panel.append(budget);
  }

  const side = el('div', { id: 'panel2d' });
  root.append(side);
  panel.append(
    el('button', {
      id: 'toggle-2d',
      text: '2-D map and plots',
      onclick: () => viewer.toggle2d(side),
    }),
  );

  panel.append(el('h2', { text: 'Statistics' }));
  const stats = el('div', { id: 'stats' });
  panel.append(stats);

  if (scene.report) {
    panel.append(el('h2', { text: 'Report' }));
    const table = el('table', { id: 'report-figures' });
    for (const [label, value] of reportRows(scene.report)) {
      table.append(el('tr', {}, el('td', { text: label }), el('td', { text: value })));
    }
    panel.append(table);
    const details = el('details', { id: 'report' }, el('summary', { text: 'report.json' }));
    details.append(el('pre', { text: JSON.stringify(scene.report, null, 1) }));
    panel.append(details);
  }
  root.append(panel);

  const keyframe = el('div', { id: 'keyframe' });
  root.append(keyframe);
  return {
    setStats(text) {
      stats.textContent = text;
    },
    showKeyframe(info) {
      keyframe.replaceChildren(
        el('button', { text: '×', class: 'close', title: 'close', onclick: () => (keyframe.style.display = 'none') }),
        el('div', { text: info.title }),
        ...(info.image ? [el('img', { src: info.image, alt: info.title })] : []),
        ...(info.note ? [el('div', { text: info.note })] : []),
      );
      keyframe.style.display = 'block';
    },
  };
}
