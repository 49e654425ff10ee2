#!/usr/bin/env python3
"""The three front cues of mesh/view_frame.h (upright_rotation) on meshes, as a markdown table.

Plain python3, no dependencies; the same rules as the C++ code (a reimplementation for the table in
docs/streaming.md, "Upright and front"): up = ground() (ground_direction(): the axis of the largest support
polygon, contact band 5 %, at the end that widens less from 5 % to 20 %), length = the longer horizontal axis,
then per end: reach (largest up coordinate in the end quarter, / height
above the lowest vertex), width (side extent of the end tenth, / the box's side extent), mass (volume
centroid's offset from the middle of the length, / length; the vote goes to the other end); front = 2 of 3.
Usage: front_cues.py MESH_DIR NAME...   (OBJ, or binary little-endian PLY with triangle faces)
"""
import math, os, struct, sys


def load(path):
    V, F = [], []
    if path.endswith('.ply'):
        data = open(path, 'rb').read()
        i = data.index(b'end_header\n') + 11
        hdr = data[:i].decode().split('\n')
        nv = int([l for l in hdr if l.startswith('element vertex')][0].split()[2])
        nf = int([l for l in hdr if l.startswith('element face')][0].split()[2])
        V = [struct.unpack_from('<3f', data, i + 12 * k) for k in range(nv)]
        p = i + 12 * nv
        for _ in range(nf):
            n = data[p]
            F.append(struct.unpack_from('<3i', data, p + 1))
            p += 1 + 4 * n
        return V, F
    for line in open(path):
        s = line.split()
        if s and s[0] == 'v':
            V.append(tuple(map(float, s[1:4])))
        elif s and s[0] == 'f':
            F.append(tuple(int(x.split('/')[0]) - 1 for x in s[1:4]))
    return V, F


def hull_area(p):
    p = sorted(set(p))
    if len(p) < 3:
        return 0
    cr = lambda o, a, b: (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    lo, up = [], []
    for q in p:
        while len(lo) >= 2 and cr(lo[-2], lo[-1], q) <= 0:
            lo.pop()
        lo.append(q)
    for q in reversed(p):
        while len(up) >= 2 and cr(up[-2], up[-1], q) <= 0:
            up.pop()
        up.append(q)
    h = lo[:-1] + up[:-1]
    return abs(sum(h[i][0] * h[(i + 1) % len(h)][1] - h[(i + 1) % len(h)][0] * h[i][1] for i in range(len(h)))) / 2


def ground(P, lo, hi, band=0.05):
    """ground_direction(): the axis of the face with the largest support polygon, then the end whose support
    polygon grows less from band to 4 × band (growths within 5 %: the larger support polygon)."""
    ext = [hi[i] - lo[i] for i in range(3)]

    def support(ax, s, d):
        a, b = (ax + 1) % 3, (ax + 2) % 3
        face = ext[a] * ext[b]
        plane = lo[ax] if s < 0 else hi[ax]
        return hull_area([(p[a], p[b]) for p in P if abs(p[ax] - plane) <= d * ext[ax]]) / face if face > 0 else 0

    best, ratio = (1, -1), -1
    for ax in (1, 0, 2):
        for s in (-1, 1):
            r = support(ax, s, band)
            if r > ratio:
                best, ratio = (ax, s), r
    ax = best[0]
    g = [support(ax, s, 4 * band) / n if n > 0 else math.inf for s in (-1, 1) for n in [support(ax, s, band)]]
    if math.isfinite(g[0]) and math.isfinite(g[1]) and abs(g[0] - g[1]) > 0.05 * max(g):
        return ax, -1 if g[0] < g[1] else 1
    if math.isfinite(g[0]) != math.isfinite(g[1]):
        return ax, -1 if math.isfinite(g[0]) else 1
    return best


def three_votes(V, F, P, lo, hi, gax, gs, L):
    """The reach, width and mass votes (+1: the + end of axis L, −1, 0) of upright_rotation() for up = −gs·axis
    gax, with the values behind them: reach per end (up coordinates; u0, uh the lowest up coordinate and the
    height), width per end (/ the side extent), mass (the volume centroid's offset / the length)."""
    S = 3 - L - gax
    ln = hi[L] - lo[L]
    U = [-gs * p[gax] for p in P]
    u0, uh = min(U), max(U) - min(U)
    reach = [max(U[k] for k, p in enumerate(P) if p[L] <= lo[L] + 0.25 * ln),
             max(U[k] for k, p in enumerate(P) if p[L] >= hi[L] - 0.25 * ln)]
    a = [p[S] for p in P if p[L] <= lo[L] + 0.1 * ln]
    b = [p[S] for p in P if p[L] >= hi[L] - 0.1 * ln]
    width = [(max(a) - min(a)) / (hi[S] - lo[S]), (max(b) - min(b)) / (hi[S] - lo[S])]
    c = [(lo[i] + hi[i]) / 2 for i in range(3)]
    vol = mom = 0
    for t in F:
        x, y, z = ([V[k][i] - c[i] for i in range(3)] for k in t)
        v6 = x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0]) + x[2] * (y[0] * z[1] - y[1] * z[0])
        vol += v6
        mom += v6 * (x[L] + y[L] + z[L]) / 4
    box = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2])
    mass = mom / vol / ln if abs(vol) / 6 > 1e-9 * box else 0.0
    sign = lambda v: (v > 0) - (v < 0)
    return [sign(reach[1] - reach[0]), sign(width[1] - width[0]), -sign(mass)], reach, width, mass, u0, uh


def read_upright(path):
    """The mesh (V, F), its referenced vertices P, their box lo–hi, the ground (axis gax, end gs) and the longer
    horizontal axis L."""
    V, F = load(path)
    P = [V[v] for v in sorted({v for t in F for v in t})]
    lo = [min(p[i] for p in P) for i in range(3)]
    hi = [max(p[i] for p in P) for i in range(3)]
    gax, gs = ground(P, lo, hi)
    L = max((c for c in range(3) if c != gax), key=lambda c: (hi[c] - lo[c], -c))
    return V, F, P, lo, hi, gax, gs, L


def main():
    mesh_dir = sys.argv[1]
    print('| mesh | up | reach | width | mass | front |')
    print('|---|---|---|---|---|---|')
    for name in sys.argv[2:]:
        V, F, P, lo, hi, gax, gs, L = read_upright(os.path.join(mesh_dir, name))
        votes, reach, width, mass, u0, uh = three_votes(V, F, P, lo, hi, gax, gs, L)
        total = sum(votes) or votes[0]
        end = lambda v: ('+' if v >= 0 else '−') + 'xyz'[L] if v else '—'
        print(f"| {name} | {'+' if gs < 0 else '−'}{'xyz'[gax]} | {end(votes[0])} ({(reach[0] - u0) / uh:.2f} / "
              f"{(reach[1] - u0) / uh:.2f}) | {end(votes[1])} ({width[0]:.2f} / {width[1]:.2f}) | {end(votes[2])} "
              f"({mass:+.3f}) | {end(1 if total >= 0 else -1)} |", flush=True)


if __name__ == '__main__':
    main()
