#!/usr/bin/env python3
"""The accuracy floor of GNSS fusion under the simulator's SPP model, for one run.

With a drift-free VIO only the trajectory's offset is unknown; its best (generalised least
squares) estimate from the used fixes has this error, whatever the fusion does. Per axis a
two-state Kalman filter (constant offset c, diffuse prior; first-order Gauss-Markov receiver bias
b, sigma 1 m, tau 60 s; white noise 1.5 m horizontal, 3 m vertical: `gvio simulate --gnss-noise
spp`) runs over the fixes minus the true antenna position; its final c is the realised error of
that estimate, its sigma the expected one.

  tests/bench/gnss_offset_floor.py RUN_DIR [LEVER_ARM_UP_M]   # RUN_DIR of gvio run --gnss graph
"""
import math, bisect, sys
run = sys.argv[1]
lever_up = float(sys.argv[2]) if len(sys.argv) > 2 else 0.8
gt = []
for line in open(run + '/groundtruth.tum'):
    v = [float(x) for x in line.split()]
    gt.append(v)
ts = [g[0] for g in gt]
def rot(qx, qy, qz, qw, v):
    # v rotated by the unit quaternion (x, y, z, w): v + 2w (u x v) + 2 u x (u x v)
    x, y, z = v
    ux, uy, uz = qx, qy, qz
    cx, cy, cz = uy*z - uz*y, uz*x - ux*z, ux*y - uy*x
    ccx, ccy, ccz = uy*cz - uz*cy, uz*cx - ux*cz, ux*cy - uy*cx
    return (x + 2*qw*cx + 2*ccx, y + 2*qw*cy + 2*ccy, z + 2*qw*cz + 2*ccz)
res = []
for line in list(open(run + '/gnss_fixes.csv'))[1:]:
    t, e, n, u, st = line.strip().split(',')
    if st != 'used': continue
    t = float(t)
    i = bisect.bisect_left(ts, t)
    if i == 0 or i >= len(ts): continue
    a, b = gt[i-1], gt[i]
    w = (t - a[0]) / (b[0] - a[0])
    p = [a[k] + w*(b[k]-a[k]) for k in (1,2,3)]
    l = rot(a[4], a[5], a[6], a[7], (0, 0, lever_up))
    ant = [p[k] + l[k] for k in range(3)]
    res.append((t, float(e) - ant[0], float(n) - ant[1], float(u) - ant[2]))
print(len(res), 'fixes')
tau, sb = 60.0, 1.0
out = []
for ax, sw in ((1, 1.5), (2, 1.5), (3, 3.0)):
    # x = [c, b]: c constant (diffuse prior), b Gauss-Markov(sb, tau); measurement c + b + w
    c, b = 0.0, 0.0
    P = [[1e6, 0.0], [0.0, sb*sb]]
    tprev = None
    for r in res:
        t = r[0]
        if tprev is not None:
            phi = math.exp(-(t - tprev)/tau)
            b *= phi
            P = [[P[0][0], P[0][1]*phi], [P[1][0]*phi, P[1][1]*phi*phi + sb*sb*(1 - phi*phi)]]
        tprev = t
        y = r[ax] - (c + b)
        S = P[0][0] + P[0][1] + P[1][0] + P[1][1] + sw*sw
        K = [(P[0][0] + P[0][1]) / S, (P[1][0] + P[1][1]) / S]
        c += K[0]*y; b += K[1]*y
        P = [[P[i][j] - K[i]*(P[0][j] + P[1][j]) for j in range(2)] for i in range(2)]
    out.append((c, math.sqrt(P[0][0])))
print('realised offset estimate (E,N,U):', ['%.3f' % o[0] for o in out], 'sigma', ['%.3f' % o[1] for o in out])
print('norm %.3f m, expected %.3f m' % (math.sqrt(sum(o[0]**2 for o in out)), math.sqrt(sum(o[1]**2 for o in out))))
