#!/usr/bin/env python3
"""A TUM trajectory with a stretch of its poses moved: the fault the image check must find.

  displace_poses.py IN.tum OUT.tum FROM_S TO_S DIRECTION METRES

Poses whose time from the trajectory's start lies in [FROM_S, TO_S) are moved by METRES along
DIRECTION: `side` (the body's y axis: left of travel for a forward x, up z body) or `up` (the
frame's z axis: ENU up). Orientations are kept. Comment lines are dropped.
"""
import sys


def rotate(q, v):
    """v rotated by the unit quaternion q = (w, x, y, z)."""
    w, x, y, z = q
    # v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)
    ux = (y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0])
    uux = (y * ux[2] - z * ux[1], z * ux[0] - x * ux[2], x * ux[1] - y * ux[0])
    return tuple(v[i] + 2.0 * w * ux[i] + 2.0 * uux[i] for i in range(3))


def main():
    if len(sys.argv) != 7 or sys.argv[5] not in ("side", "up"):
        sys.exit("usage: displace_poses.py IN.tum OUT.tum FROM_S TO_S side|up METRES")
    src, dst, t0, t1, direction, metres = sys.argv[1:]
    t0, t1, metres = float(t0), float(t1), float(metres)
    out, first = [], None
    with open(src) as f:
        for n, line in enumerate(f, 1):
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            v = line.split()
            if len(v) != 8:
                sys.exit(f"{src}:{n}: expected 8 numbers (t x y z qx qy qz qw)")
            t, x, y, z, qx, qy, qz, qw = (float(a) for a in v)
            first = t if first is None else first
            if t0 <= t - first < t1:
                d = rotate((qw, qx, qy, qz), (0.0, 1.0, 0.0)) if direction == "side" else (0, 0, 1)
                if direction == "side":  # horizontal: drop the body's roll and pitch
                    norm = (d[0] ** 2 + d[1] ** 2) ** 0.5
                    d = (d[0] / norm, d[1] / norm, 0.0)
                x, y, z = x + metres * d[0], y + metres * d[1], z + metres * d[2]
            out.append(f"{v[0]} {x:.9f} {y:.9f} {z:.9f} {v[4]} {v[5]} {v[6]} {v[7]}\n")
    with open(dst, "w") as f:
        f.writelines(out)


if __name__ == "__main__":
    main()
