// The 2-D map: the tracks (scene.tracks2d) over web map tiles from a URL the user sets (the
// page remembers it; ?tiles=URL also sets it), or, offline, over a grid of UTM coordinates.
import { trajectoryColor } from './colors.js';

const kTileSize = 256;

// Web Mercator (EPSG:3857) in world pixels at zoom z.
function mercator(lat, lon, z) {
  const s = kTileSize * 2 ** z;
  const sin = Math.sin((lat * Math.PI) / 180);
  return [((lon + 180) / 360) * s, (0.5 - Math.log((1 + sin) / (1 - sin)) / (4 * Math.PI)) * s];
}

function niceStep(span, lines) {
  const raw = span / lines;
  const p = 10 ** Math.floor(Math.log10(raw));
  return [1, 2, 5, 10].map((m) => m * p).find((s) => s >= raw) ?? 10 * p;
}

export class Map2d {
  constructor(container, scene) {
    this.scene = scene;
    this.tracks = scene.tracks2d ?? [];
    this.canvas = document.createElement('canvas');
    this.canvas.id = 'map2d-canvas';
    this.canvas.width = 440;
    this.canvas.height = 300;
    this.input = document.createElement('input');
    this.input.placeholder = 'tile URL, e.g. https://tile.openstreetmap.org/{z}/{x}/{y}.png';
    this.input.value =
      new URLSearchParams(location.search).get('tiles') ?? localStorage.getItem('gvio.tiles') ?? '';
    this.input.addEventListener('change', () => {
      localStorage.setItem('gvio.tiles', this.input.value);
      this.draw();
    });
    container.append(this.canvas, this.input);
    this.draw();
  }

  draw() {
    const ctx = this.canvas.getContext('2d');
    ctx.fillStyle = '#0c1014';
    ctx.fillRect(0, 0, this.canvas.width, this.canvas.height);
    if (this.tracks.length === 0) {
      ctx.fillStyle = '#9ab';
      ctx.fillText('not georeferenced: no 2-D map', 10, 20);
      return;
    }
    if (this.input.value.includes('{z}')) this.drawTiles(ctx);
    else this.drawGrid(ctx);
  }

  // Offline: UTM easting/northing with a labelled grid.
  drawGrid(ctx) {
    const all = this.tracks.flatMap((t) => t.utm);
    const xs = all.filter((_, i) => i % 2 === 0),
      ys = all.filter((_, i) => i % 2 === 1);
    const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
    const { width: w, height: h } = this.canvas;
    const scale = Math.min((w - 60) / Math.max(x1 - x0, 1), (h - 40) / Math.max(y1 - y0, 1));
    const cx = (x0 + x1) / 2,
      cy = (y0 + y1) / 2;
    const px = (e, n) => [w / 2 + (e - cx) * scale, h / 2 - (n - cy) * scale];
    const step = niceStep(Math.max(w, h) / scale, 5);
    ctx.strokeStyle = '#2a3440';
    ctx.fillStyle = '#789';
    ctx.font = '10px sans-serif';
    const e0 = cx - w / 2 / scale,
      e1 = cx + w / 2 / scale,
      n0 = cy - h / 2 / scale,
      n1 = cy + h / 2 / scale;
    for (let e = Math.ceil(e0 / step) * step; e <= e1; e += step) {
      const [x] = px(e, 0);
      ctx.beginPath();
      ctx.moveTo(x, 0);
      ctx.lineTo(x, h);
      ctx.stroke();
      ctx.fillText(`E ${e.toFixed(0)}`, x + 2, h - 4);
    }
    for (let n = Math.ceil(n0 / step) * step; n <= n1; n += step) {
      const [, y] = px(0, n);
      ctx.beginPath();
      ctx.moveTo(0, y);
      ctx.lineTo(w, y);
      ctx.stroke();
      ctx.fillText(`N ${n.toFixed(0)}`, 2, y - 2);
    }
    const zone = this.scene.frame.utm_zone;
    ctx.fillText(`UTM zone ${zone}${this.scene.frame.utm_north ? 'N' : 'S'}, grid ${step} m`, 2, 12);
    this.drawTracks(ctx, (t, i) => px(t.utm[2 * i], t.utm[2 * i + 1]));
  }

  // Online: web map tiles at the zoom that fits the tracks.
  drawTiles(ctx) {
    const all = this.tracks.flatMap((t) => t.lat_lon);
    const lats = all.filter((_, i) => i % 2 === 0),
      lons = all.filter((_, i) => i % 2 === 1);
    const { width: w, height: h } = this.canvas;
    let z = 19;
    for (; z > 0; --z) {
      const [ax, ay] = mercator(Math.max(...lats), Math.min(...lons), z);
      const [bx, by] = mercator(Math.min(...lats), Math.max(...lons), z);
      if (bx - ax < w - 40 && by - ay < h - 40) break;
    }
    const [cx, cy] = mercator(
      (Math.min(...lats) + Math.max(...lats)) / 2,
      (Math.min(...lons) + Math.max(...lons)) / 2,
      z,
    );
    const left = cx - w / 2,
      top = cy - h / 2;
    const px = (t, i) => {
      const [x, y] = mercator(t.lat_lon[2 * i], t.lat_lon[2 * i + 1], z);
      return [x - left, y - top];
    };
    const pending = [];
    for (let tx = Math.floor(left / kTileSize); tx * kTileSize < left + w; ++tx) {
      for (let ty = Math.floor(top / kTileSize); ty * kTileSize < top + h; ++ty) {
        const image = new Image();
        image.crossOrigin = 'anonymous';
        const url = this.input.value.replace('{z}', z).replace('{x}', tx).replace('{y}', ty);
        pending.push(
          new Promise((resolve) => {
            image.onload = () => {
              ctx.drawImage(image, tx * kTileSize - left, ty * kTileSize - top);
              resolve();
            };
            image.onerror = resolve; // a missing tile leaves the background
          }),
        );
        image.src = url;
      }
    }
    Promise.all(pending).then(() => {
      this.drawTracks(ctx, px);
      ctx.fillStyle = '#000';
      ctx.fillText(`tiles: ${new URL(this.input.value.replace(/[{}]/g, ''), location.href).host}`, 4, h - 4);
    });
  }

  drawTracks(ctx, px) {
    ctx.lineWidth = 2;
    this.tracks.forEach((t, k) => {
      const traj = this.scene.trajectories[k];
      ctx.strokeStyle = '#' + trajectoryColor(traj, k).toString(16).padStart(6, '0');
      ctx.beginPath();
      for (let i = 0; i < t.utm.length / 2; ++i) {
        const [x, y] = px(t, i);
        if (i === 0) ctx.moveTo(x, y);
        else ctx.lineTo(x, y);
      }
      ctx.stroke();
    });
    ctx.lineWidth = 1;
  }
}
