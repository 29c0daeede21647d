#!/usr/bin/python3
"""A merged map folder as `gvio merge` writes it (tiles.json, PCD tiles in the map frame), of any
size, for the viewer's benchmark (tests/bench/viewer_bench.sh): DRIVES drives along random smooth
roads, points in a street corridor (road surface and facades either side). Only the files gvio
view reads are written (no LAS, no OctoMap).

usage: synthetic_merged_map.py OUT --points N [--drives D] [--seed S] [--tile-size M]
"""
import argparse
import json
import os

import numpy as np

# The dtype of gvio merge's PCD tiles (app/fleet/merge_tile.cpp): 20 bytes a point.
POINT = np.dtype([('x', '<f4'), ('y', '<f4'), ('z', '<f4'), ('intensity', '<f4'),
                  ('point_source_id', '<u2'), ('source', 'u1'), ('_', 'u1')])


def road(rng, length_m, step_m=1.0):
    """A smooth random road from the origin: heading changes slowly (curvature random walk)."""
    n = int(length_m / step_m)
    curvature = np.cumsum(rng.normal(0, 0.0004, n))
    curvature = np.clip(curvature, -0.02, 0.02)
    heading = rng.uniform(0, 2 * np.pi) + np.cumsum(curvature * step_m)
    xy = np.cumsum(np.stack([np.cos(heading), np.sin(heading)], 1) * step_m, 0)
    return xy, heading


def drive_points(rng, n, drive_id, centre):
    xy, heading = road(rng, 3000.0)
    xy += centre
    k = rng.integers(0, len(xy), n)
    lateral = rng.uniform(-14, 14, n)
    facade = np.abs(lateral) > 11
    pts = np.zeros(n, POINT)
    normal = np.stack([-np.sin(heading[k]), np.cos(heading[k])], 1)
    along = rng.uniform(-0.5, 0.5, n)
    tangent = np.stack([np.cos(heading[k]), np.sin(heading[k])], 1)
    p = xy[k] + normal * lateral[:, None] + tangent * along[:, None]
    pts['x'], pts['y'] = p[:, 0], p[:, 1]
    pts['z'] = np.where(facade, rng.uniform(0, 12, n), rng.normal(0, 0.03, n))
    pts['intensity'] = np.where(facade, rng.uniform(60, 220, n), rng.uniform(20, 90, n))
    pts['point_source_id'] = drive_id
    pts['source'] = 1
    return pts


def write_pcd(path, pts):
    header = (
        '# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n'
        'FIELDS x y z intensity point_source_id source _\nSIZE 4 4 4 4 2 1 1\n'
        'TYPE F F F F U U U\nCOUNT 1 1 1 1 1 1 1\n'
        f'WIDTH {len(pts)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(pts)}\nDATA binary\n')
    with open(path, 'wb') as f:
        f.write(header.encode())
        f.write(pts.tobytes())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('out')
    ap.add_argument('--points', type=int, required=True)
    ap.add_argument('--drives', type=int, default=20)
    ap.add_argument('--seed', type=int, default=1)
    ap.add_argument('--tile-size', type=float, default=200.0)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    origin_e, origin_n, origin_h = 455393.18, 5425692.79, 116.4  # Karlsruhe, UTM 32N
    os.makedirs(os.path.join(a.out, 'tiles'), exist_ok=True)
    per_drive = a.points // a.drives
    parts = [drive_points(rng, per_drive + (a.points % a.drives if d == 0 else 0), d + 1,
                          rng.uniform(-800, 800, 2)) for d in range(a.drives)]
    pts = np.concatenate(parts)
    del parts
    # Tiles: points binned by the UTM grid of the tile size, as gvio merge does.
    ti = np.floor((pts['x'] + origin_e) / a.tile_size).astype(np.int64)
    tj = np.floor((pts['y'] + origin_n) / a.tile_size).astype(np.int64)
    key = (ti - ti.min()) * (tj.max() - tj.min() + 1) + (tj - tj.min())
    order = np.argsort(key, kind='stable')
    pts, ti, tj, key = pts[order], ti[order], tj[order], key[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    ends = np.r_[starts[1:], len(key)]
    tiles = []
    for s, e in zip(starts, ends):
        name = f'E{int(ti[s] * a.tile_size)}_N{int(tj[s] * a.tile_size)}'
        write_pcd(os.path.join(a.out, 'tiles', name + '.pcd'), pts[s:e])
        tiles.append({'name': name, 'sw_easting_m': float(ti[s] * a.tile_size),
                      'sw_northing_m': float(tj[s] * a.tile_size), 'points': int(e - s),
                      'files': {'pcd': f'tiles/{name}.pcd'}})
    index = {
        'crs': {'epsg': 32632, 'utm_zone': 32, 'north': True, 'heights': 'WGS 84 ellipsoidal'},
        'drives': [{'name': f'synthetic {d + 1}', 'point_source_id': d + 1}
                   for d in range(a.drives)],
        'map_frame': {'origin_easting_m': origin_e, 'origin_northing_m': origin_n,
                      'origin_h_ellipsoid_m': origin_h},
        'points': int(len(pts)), 'tile_size_m': a.tile_size, 'tiles': tiles,
    }
    with open(os.path.join(a.out, 'tiles.json'), 'w') as f:
        json.dump(index, f, indent=1)
    print(f'{len(pts)} points of {a.drives} drives in {len(tiles)} tiles: {a.out}')


if __name__ == '__main__':
    main()
