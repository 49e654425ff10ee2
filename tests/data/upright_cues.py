#!/usr/bin/env python3
"""The front-back axis, the upright test and the face cue of mesh/view_frame.h (upright_rotation), as a markdown
table.

Plain python3, no dependencies; the same rules as the C++ code (a reimplementation for the table in
docs/streaming.md, "Upright and front"). Up = ground() of front_cues.py (ground_direction()); then
  mirror   — per horizontal axis a, the mean distance (capped at 2 % of the box's diagonal, / the diagonal)
             from every k-th referenced vertex (k = ⌈#V / 4000⌉), reflected across the plane a = the surface's
             area centroid, to the nearest referenced vertex: small across the left-right axis of a
             mirror-symmetric body;
  axis     — the front-back axis: the longer horizontal axis (the length), unless its mirror value is below
             0.8 × the other's (then the length is a left-right span, a biped's arms: the other axis);
  foot     — the extent along that axis of the vertices within 5 % of the height from the ground, / the axis's
             extent; upright when below 0.45 (a neck or two feet under the body; four legs or a lying body span
             the length);
  tip      — per end of the axis, among the vertices at least 40 % of the height above the ground: the 2D
             convex hull (across the axis: the side axis and up) of those within 2 % of the axis's extent from
             the extreme one, / (side extent × height); the face is the end with the smaller hull (a nose, a
             muzzle, a snout) when the other is at least 1.5 × as large;
  votes    — the three cues of front_cues.py on the axis (reach, width, mass; two of three): lying shapes, and
             upright ones without a decisive tip.
Upright shapes turn their front to the viewer's +z (the default camera's side), lying ones to +x.
Usage: upright_cues.py MESH_DIR NAME...   (OBJ, or binary little-endian PLY with triangle faces)
"""
import math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from front_cues import hull_area, read_upright, three_votes  # noqa: E402


def area_centroid(V, F):
    area, c = 0.0, [0.0, 0.0, 0.0]
    for t in F:
        a, b, d = (V[k] for k in t)
        u = [b[i] - a[i] for i in range(3)]
        w = [d[i] - a[i] for i in range(3)]
        n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
        s = math.sqrt(sum(x * x for x in n)) / 2
        area += s
        for i in range(3):
            c[i] += s * (a[i] + b[i] + d[i]) / 3
    return [x / area for x in c] if area > 0 else None


def mirror(P, lo, hi, centre, axes):
    diag = math.sqrt(sum((hi[i] - lo[i]) ** 2 for i in range(3)))
    cap = 0.02 * diag
    if not cap > 0 or centre is None:
        return {a: 0.0 for a in axes}
    cell = lambda q: tuple(int(math.floor((q[i] - lo[i]) / cap)) for i in range(3))
    grid = {}
    for p in P:
        grid.setdefault(cell(p), []).append(p)
    step = max(1, -(-len(P) // 4000))
    out = {}
    for a in axes:
        total, n = 0.0, 0
        for p in P[::step]:
            q = list(p)
            q[a] = 2 * centre[a] - p[a]
            k = cell(q)
            best = cap * cap
            for dx in (-1, 0, 1):
                for dy in (-1, 0, 1):
                    for dz in (-1, 0, 1):
                        for r in grid.get((k[0] + dx, k[1] + dy, k[2] + dz), ()):
                            best = min(best, (r[0] - q[0]) ** 2 + (r[1] - q[1]) ** 2 + (r[2] - q[2]) ** 2)
            total += math.sqrt(best)
            n += 1
        out[a] = total / n / diag
    return out


def main():
    mesh_dir = sys.argv[1]
    print('| mesh | up | length | mirror length / other | front axis | foot | shape | tip − / + | votes | '
          'front | viewer +x / +z |')
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for name in sys.argv[2:]:
        V, F, P, lo, hi, gax, gs, L = read_upright(os.path.join(mesh_dir, name))
        ext = [hi[i] - lo[i] for i in range(3)]
        O = 3 - L - gax
        m = mirror(P, lo, hi, area_centroid(V, F), (L, O))
        A = O if m[L] < 0.8 * m[O] else L
        S = 3 - A - gax
        U = [-gs * p[gax] for p in P]
        u0, uh = min(U), max(U) - min(U)
        foot = [p[A] for k, p in enumerate(P) if U[k] <= u0 + 0.05 * uh]
        span = (max(foot) - min(foot)) / ext[A]
        upright = span < 0.45
        top = [(p, U[k]) for k, p in enumerate(P) if U[k] >= u0 + 0.4 * uh]
        tip = []
        for s in (-1, 1):
            e = max(s * p[A] for p, _ in top)
            cap = [(p[S], u) for p, u in top if s * p[A] >= e - 0.02 * ext[A]]
            tip.append(hull_area(cap) / (ext[S] * uh))
        votes = three_votes(V, F, P, lo, hi, gax, gs, A)[0]
        voted = 1 if (sum(votes) or votes[0]) >= 0 else -1
        decisive = max(tip) >= 1.5 * min(tip) and max(tip) > 0
        front = (-1 if tip[0] < tip[1] else 1) if upright and decisive else voted
        ax = lambda s, a: ('+' if s > 0 else '−') + 'xyz'[a]
        up = (gax, -gs)
        # Rows: upright: +z = front, +x = up × front; lying: +x = front, +z = front × up.
        f = [0, 0, 0]
        f[A] = front
        u = [0, 0, 0]
        u[gax] = -gs
        cross = lambda p, q: [p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]]
        x, z = (cross(u, f), f) if upright else (f, cross(f, u))
        name_of = lambda v: next(ax(v[i], i) for i in range(3) if v[i])
        votes_s = ' '.join(ax(v, A) if v else '—' for v in votes)
        print(f"| {name} | {ax(up[1], up[0])} | {'xyz'[L]} | {m[L]:.4f} / {m[O]:.4f} | {'xyz'[A]} | {span:.2f} | "
              f"{'upright' if upright else 'lying'} | {tip[0]:.4f} / {tip[1]:.4f} | {votes_s} → {ax(voted, A)} | "
              f"**{ax(front, A)}** | {name_of(x)} / {name_of(z)} |", flush=True)


if __name__ == '__main__':
    main()
