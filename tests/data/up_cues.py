#!/usr/bin/env python3
"""The up cues of mesh/view_frame.h (ground_direction) on meshes, as a markdown table.

Plain python3, no dependencies (a reimplementation for the table in docs/streaming.md, "Upright and front").
Per face of the bounding box, as fractions of the box face's area:
  support — the 2D convex hull of the vertices within 5 % of the box's extent from the face (the support
            polygon); support20 the same within 20 %; growth = support20 / support;
  flat    — the area of the triangles whose three vertices lie within 1 % of the box's extent from the face and
            whose normal is within 10° of the face's axis (either sign): a planar cut or a flat sole (tried, not
            used).
Up before (2026-12-02): the opposite of the face with the largest support polygon. Up after: on that face's
axis, the opposite of the end whose support polygon grows less (growths within 5 %: the larger support).
Usage: up_cues.py MESH_DIR NAME...   (OBJ, or binary little-endian PLY with triangle faces)
"""
import math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from front_cues import load, hull_area  # noqa: E402

COS10 = math.cos(math.radians(10))


def cues(V, F):
    P = [V[v] for v in sorted({v for t in F for v in t})]
    lo = [min(p[i] for p in P) for i in range(3)]
    hi = [max(p[i] for p in P) for i in range(3)]
    ext = [hi[i] - lo[i] for i in range(3)]
    out = {}
    for ax in (1, 0, 2):
        a, b = (ax + 1) % 3, (ax + 2) % 3
        face = ext[a] * ext[b]
        for s in (-1, 1):
            plane = lo[ax] if s < 0 else hi[ax]
            near = lambda p, d: abs(p[ax] - plane) <= d * ext[ax]
            sup = lambda d: hull_area([(p[a], p[b]) for p in P if near(p, d)]) / face if face > 0 else 0
            flat = 0.0
            for t in F:
                x, y, z = (V[k] for k in t)
                if near(x, 0.01) and near(y, 0.01) and near(z, 0.01):
                    u = [y[i] - x[i] for i in range(3)]
                    w = [z[i] - x[i] for i in range(3)]
                    n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
                    ln = math.sqrt(sum(c * c for c in n))
                    if ln > 0 and abs(n[ax]) >= COS10 * ln:
                        flat += ln / 2
            out[(ax, s)] = (sup(0.05), sup(0.20), flat / face if face > 0 else 0)
    return out


def main():
    name = lambda ax, s: ('−' if s < 0 else '+') + 'xyz'[ax]
    print('| mesh | up before | support − / + | growth − / + | flat − / + | up after |')
    print('|---|---|---|---|---|---|')
    for mesh in sys.argv[2:]:
        V, F = load(os.path.join(sys.argv[1], mesh))
        c = cues(V, F)
        best = max(c, key=lambda k: (c[k][0], -list(c).index(k)))
        ax = best[0]
        (s_lo, t_lo, f_lo), (s_hi, t_hi, f_hi) = c[(ax, -1)], c[(ax, 1)]
        g_lo = t_lo / s_lo if s_lo > 0 else math.inf
        g_hi = t_hi / s_hi if s_hi > 0 else math.inf
        ground = best[1]
        if math.isfinite(g_lo) and math.isfinite(g_hi) and abs(g_lo - g_hi) > 0.05 * max(g_lo, g_hi):
            ground = -1 if g_lo < g_hi else 1
        elif math.isfinite(g_lo) != math.isfinite(g_hi):
            ground = -1 if math.isfinite(g_lo) else 1
        print(f'| {mesh} | {name(ax, -best[1])} | {s_lo:.3f} / {s_hi:.3f} | {g_lo:.2f} / {g_hi:.2f} | '
              f'{f_lo:.3f} / {f_hi:.3f} | {name(ax, -ground)} |', flush=True)


if __name__ == '__main__':
    main()
