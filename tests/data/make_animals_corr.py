#!/usr/bin/env python3
"""Finds corresponding partition points and features on horse, cow, pig and spot (tests/data/animals.corr.json).

Plain python3, no dependencies. Each animal's frame (forward, up; left = up x forward) and the yaw of its head
were read off orthographic renders of the meshes; every point is then an extreme of the geometry in that frame.
The partition loop is traced as geomip does (Dijkstra on the edge graph, paths in order, each avoiding the other
points and the earlier paths) to check that the features and the legs/ears fall in the expected halves.
Usage: make_animals_corr.py [MESH_DIR] > animals.corr.json
"""
import heapq, json, math, os, sys

# forward, up (unit axes of the file), head yaw toward the animal's left in degrees, head depth (fraction of length)
MODELS = [
    ('horse', (0, 1, 0), (0, 0, 1), 60.0, 0.35),
    ('cow',   (1, 0, 0), (0, 1, 0), 0.0, 0.25),
    ('pig',   (0, 0, -1), (0, -1, 0), 0.0, 0.30),
    ('spot',  (0, 0, -1), (0, 1, 0), 0.0, 0.35),
]
# Eyes: a ray aimed at the point `a` of the way from the top of the head to the nose, shot from the side (the
# horse's and the cow's eyes are on the sides of the head) or, offset sideways by `w` times the ear-tip distance,
# from the front (the pig's eyes are the two ovals on its face; Spot has no modelled eyes, so the rays hit the
# upper face where its texture has them). Read off close-up renders of the heads.
EYES = {'horse': (0.30, None), 'cow': (0.30, None), 'pig': (0.78, 0.155), 'spot': (0.35, 0.12)}

def dot(a, b): return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def sub(a, b): return (a[0] - b[0], a[1] - b[1], a[2] - b[2])
def norm(a): return math.sqrt(dot(a, a))

def load_obj(path):
    V, F = [], []
    with open(path) as fh:
        for line in fh:
            s = line.split()
            if not s: continue
            if s[0] == 'v': V.append(tuple(float(x) for x in s[1:4]))
            elif s[0] == 'f': F.append(tuple(int(x.split('/')[0]) - 1 for x in s[1:4]))
    return V, F

def split_pinches(V, F):
    """Splits non-manifold vertices (more than one edge-connected fan) into one copy per fan, as geomip's repair."""
    V = list(V); F = [list(t) for t in F]
    inc = {}
    for fi, t in enumerate(F):
        for v in t: inc.setdefault(v, []).append(fi)
    copies = {}
    for v, fs in list(inc.items()):
        comp = {}
        for fi in fs:
            comp[fi] = fi
        def find(x):
            while comp[x] != x: comp[x] = comp[comp[x]]; x = comp[x]
            return x
        edge_face = {}
        for fi in fs:
            for w in F[fi]:
                if w == v: continue
                if w in edge_face: comp[find(fi)] = find(edge_face[w])
                else: edge_face[w] = fi
        roots = sorted({find(fi) for fi in fs})
        for r in roots[1:]:
            nv = len(V); V.append(V[v]); copies.setdefault(v, []).append(nv)
            for fi in fs:
                if find(fi) == r: F[fi] = [nv if w == v else w for w in F[fi]]
    return V, [tuple(t) for t in F], copies

class Frame:
    def __init__(self, V, fwd, up, yaw, head_frac):
        self.V, self.f, self.u = V, fwd, up
        self.l = cross(up, fwd)
        a = math.radians(yaw)
        self.hf = tuple(math.cos(a) * fwd[i] + math.sin(a) * self.l[i] for i in range(3))  # head direction
        self.hl = cross(up, self.hf)                                                         # head left
        F_ = [dot(v, fwd) for v in V]; U_ = [dot(v, up) for v in V]; L_ = [dot(v, self.l) for v in V]
        self.F, self.U, self.Lc = F_, U_, L_
        self.length = max(F_) - min(F_); self.height = max(U_) - min(U_)
        # lateral centre from the torso (the middle of the body's length): the horse's turned head skews the bbox
        fmin = min(F_)
        torso = [L_[k] for k in range(len(V)) if fmin + 0.3 * self.length < F_[k] < fmin + 0.6 * self.length]
        self.lmid = (max(torso) + min(torso)) / 2
        self.halfwidth = (max(torso) - min(torso)) / 2
        fmax, umin = max(F_), min(U_)
        self.head = [k for k in range(len(V)) if F_[k] > fmax - head_frac * self.length and U_[k] > umin + 0.5 * self.height]

def find_points(V, F, fr, name):
    L, H, hd = fr.length, fr.height, fr.head
    P = {}
    # Nose: the most forward head vertex along the head direction, nearest the head's midline among near-ties.
    # (searched over the front 15% at any height: the pig's snout is low)
    fmax, umin = max(fr.F), min(fr.U)
    front = [k for k in range(len(V)) if fr.F[k] > fmax - 0.15 * L]
    HF = {k: dot(V[k], fr.hf) for k in set(hd) | set(front)}; HL = {k: dot(V[k], fr.hl) for k in HF}
    top = max(HF[k] for k in front)
    near = [k for k in front if HF[k] > top - 0.02 * L]
    c = sum(HL[k] for k in near) / len(near)
    P['nose'] = min(near, key=lambda k: (HL[k] - c) ** 2 - 0.01 * (HF[k] - top))
    c_head = HL[P['nose']]
    # Ear tips.
    if name == 'horse':  # ears point up: highest head vertex on each side of the head's midline
        utop = max(fr.U[k] for k in hd)
        ear = [k for k in hd if fr.U[k] > utop - 0.1 * H]
        ce = sum(HL[k] for k in ear) / len(ear)
        P['ear_l'] = max((k for k in hd if HL[k] > ce and fr.U[k] > utop - 0.1 * H), key=lambda k: fr.U[k])
        P['ear_r'] = max((k for k in hd if HL[k] < ce and fr.U[k] > utop - 0.1 * H), key=lambda k: fr.U[k])
    else:  # ears stick out sideways: the most lateral head vertex on each side
        P['ear_l'] = max(hd, key=lambda k: HL[k])
        P['ear_r'] = min(hd, key=lambda k: HL[k])
    # Top of the head between the ears: the highest vertex horizontally near the ears' midpoint.
    el, er = V[P['ear_l']], V[P['ear_r']]
    m = tuple((el[i] + er[i]) / 2 for i in range(3))
    sep = norm(sub(el, er))
    def hdist(k):
        d = sub(V[k], m); d = sub(d, tuple(dot(d, fr.u) * x for x in fr.u)); return norm(d)
    P['head_top'] = max((k for k in hd if hdist(k) < 0.05 * sep), key=lambda k: fr.U[k])
    # Feet: lowest vertex in each leg quadrant (centre of the near-ties, for flat-soled legs).
    # (the muzzle and the midline strip are left out: the pig's jaw is lower than its leg stumps)
    muzzle = dot(V[P['nose']], fr.hf) - (0.25 if name == 'pig' else 0.12) * L
    low = [k for k in range(len(V)) if fr.U[k] < umin + 0.15 * H and dot(V[k], fr.hf) < muzzle
           and abs(fr.Lc[k] - fr.lmid) > 0.3 * fr.halfwidth]
    fm = (max(fr.F[k] for k in low) + min(fr.F[k] for k in low)) / 2
    for key, front, left in (('foot_lf', 1, 1), ('foot_rf', 1, 0), ('foot_lb', 0, 1), ('foot_rb', 0, 0)):
        q = [k for k in low if (fr.F[k] > fm) == bool(front) and (fr.Lc[k] > fr.lmid) == bool(left)]
        uq = min(fr.U[k] for k in q)
        ties = [k for k in q if fr.U[k] < uq + 0.02 * H]
        cf = sum(fr.F[k] for k in ties) / len(ties); cl = sum(fr.Lc[k] for k in ties) / len(ties)
        P[key] = min(ties, key=lambda k: (fr.F[k] - cf) ** 2 + (fr.Lc[k] - cl) ** 2)
    # Rear: the most backward vertex near the body midline, in the upper half (rump / tail root).
    mid = [k for k in range(len(V)) if abs(fr.Lc[k] - fr.lmid) < 0.03 * L]
    P['tail'] = min((k for k in mid if fr.U[k] > umin + 0.5 * H), key=lambda k: fr.F[k])
    # Chest between the front legs / crotch between the hind legs: first surface hit by a vertical ray going up
    # from the ground midway between the two feet; withers: first hit going down from above the front feet.
    ff = (fr.F[P['foot_lf']] + fr.F[P['foot_rf']]) / 2
    fb = (fr.F[P['foot_lb']] + fr.F[P['foot_rb']]) / 2
    P['chest'] = vertical_hit(V, F, fr, ff, fr.lmid, True)
    # (the horse's hind legs are staggered, the ray between them can pass behind the rump: step forward)
    for step in range(20):
        P['crotch'] = vertical_hit(V, F, fr, fb + 0.01 * step * L, fr.lmid, True)
        if P['crotch'] is not None: break
    P['withers'] = vertical_hit(V, F, fr, ff, fr.lmid, False)
    a, w = EYES[name]
    N, T = V[P['nose']], V[P['head_top']]
    X = tuple(T[i] + a * (N[i] - T[i]) for i in range(3))
    for key, sg in (('eye_l', 1), ('eye_r', -1)):
        if w is None:
            O = tuple(X[i] + 2 * sg * sep * fr.hl[i] for i in range(3)); D = tuple(-sg * fr.hl[i] for i in range(3))
        else:
            O = tuple(X[i] + sg * w * sep * fr.hl[i] + 2 * sep * fr.hf[i] for i in range(3)); D = tuple(-x for x in fr.hf)
        P[key] = ray_hit(V, F, O, D)
    # Brow: the head vertex as near as possible to both eyes.
    el, er = V[P['eye_l']], V[P['eye_r']]
    P['brow'] = min(hd, key=lambda k: max(norm(sub(V[k], el)), norm(sub(V[k], er))))
    return P

def ray_hit(V, F, O, D):
    """The vertex nearest the first intersection of the ray O + tD (t > 0) with the mesh (Moller-Trumbore)."""
    best = None
    for t in F:
        a, b, c = V[t[0]], V[t[1]], V[t[2]]
        e1 = sub(b, a); e2 = sub(c, a); p = cross(D, e2); det = dot(e1, p)
        if abs(det) < 1e-18: continue
        s = sub(O, a); u = dot(s, p) / det
        if u < 0 or u > 1: continue
        q = cross(s, e1); v = dot(D, q) / det
        if v < 0 or u + v > 1: continue
        d = dot(e2, q) / det
        if d > 0 and (best is None or d < best[0]): best = (d, t, (1 - u - v, u, v))
    return best[1][max(range(3), key=lambda i: best[2][i])]

def vertical_hit(V, F, fr, f0, l0, from_below):
    best = None
    for t in F:
        a = [(fr.F[k], fr.Lc[k], fr.U[k]) for k in t]
        d = (a[1][0] - a[0][0]) * (a[2][1] - a[0][1]) - (a[2][0] - a[0][0]) * (a[1][1] - a[0][1])
        if d == 0: continue
        w1 = ((f0 - a[0][0]) * (a[2][1] - a[0][1]) - (a[2][0] - a[0][0]) * (l0 - a[0][1])) / d
        w2 = ((a[1][0] - a[0][0]) * (l0 - a[0][1]) - (f0 - a[0][0]) * (a[1][1] - a[0][1])) / d
        w0 = 1 - w1 - w2
        if min(w0, w1, w2) < 0: continue
        u = w0 * a[0][2] + w1 * a[1][2] + w2 * a[2][2]
        key = u if from_below else -u
        if best is None or key < best[0]:
            best = (key, t, (w0, w1, w2))
    if best is None: return None
    _, t, w = best
    return t[max(range(3), key=lambda i: w[i])]

def trace_loop(V, F, corners, aux=()):
    adj = [[] for _ in V]
    for t in F:
        for i in range(3):
            a, b = t[i], t[(i + 1) % 3]
            adj[a].append(b)
    blocked = [0] * len(V)
    special = list(corners) + list(aux)
    for v in special: blocked[v] = 1
    def dijkstra(s, g):
        dist = {s: 0.0}; prev = {}; pq = [(0.0, s)]
        while pq:
            d, x = heapq.heappop(pq)
            if x == g: break
            if d > dist[x]: continue
            for y in adj[x]:
                if blocked[y] and y != g: continue
                nd = d + norm(sub(V[x], V[y]))
                if nd < dist.get(y, 1e300): dist[y] = nd; prev[y] = x; heapq.heappush(pq, (nd, y))
        if g not in dist: return None
        p = [g]
        while p[-1] != s: p.append(prev[p[-1]])
        return p[::-1]
    paths = []
    for k in range(4):
        a, b = corners[k], corners[(k + 1) % 4]
        if aux:
            p1 = dijkstra(a, aux[k]); p2 = dijkstra(aux[k], b) if p1 else None
            p = p1 + p2[1:] if p2 else None
        else:
            p = dijkstra(a, b)
        if p is None: return None, None
        for v in p[1:-1]: blocked[v] = 1
        paths.append(p)
    cut = set()
    for p in paths:
        for a, b in zip(p, p[1:]): cut.add((a, b)); cut.add((b, a))
    # flood fill faces; region of the face holding half-edge P0 -> next is patch 0 (left of the loop)
    he = {}
    for fi, t in enumerate(F):
        for i in range(3): he[(t[i], t[(i + 1) % 3])] = fi
    label = [-1] * len(F); nreg = 0
    for f0 in range(len(F)):
        if label[f0] >= 0: continue
        label[f0] = nreg; st = [f0]
        while st:
            g = st.pop(); t = F[g]
            for i in range(3):
                a, b = t[i], t[(i + 1) % 3]
                if (a, b) in cut: continue
                o = he[(b, a)]
                if label[o] < 0: label[o] = nreg; st.append(o)
        nreg += 1
    left = label[he[(paths[0][0], paths[0][1])]]
    face_patch = [0 if x == left else 1 for x in label]
    return paths, (face_patch, nreg)

FEATURES = ['foot_lf', 'foot_rf', 'foot_lb', 'foot_rb', 'ear_l', 'ear_r', 'eye_l', 'eye_r']

def main():
    mesh_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                                    '..', '..', '..', 'shared', 'meshes')
    models = []
    for name, fwd, up, yaw, head_frac in MODELS:
        V0, F0 = load_obj(os.path.join(mesh_dir, name + '.obj'))
        V, F, copies = split_pinches(V0, F0)
        fr = Frame(V0, fwd, up, yaw, head_frac)
        P = find_points(V0, F0, fr, name)
        corners = [P['nose'], P['head_top'], P['tail'], P['chest']]
        # Auxiliary points pin the loop to the midline: path 0 through the brow between the eyes (the horse's
        # turned head otherwise lets it run past the left eye), path 1 through the withers, path 2 through the
        # crotch (without it the rump-to-chest path cuts across a flank), path 3 through its own middle vertex.
        free, _ = trace_loop(V, F, corners)
        aux = [P['brow'], P['withers'], P['crotch'], free[3][len(free[3]) // 2]]
        points = corners + aux + [P[k] for k in FEATURES]
        assert len(set(points)) == len(points) and not any(v in copies for v in points), name
        paths, (face_patch, regions) = trace_loop(V, F, corners, aux)
        assert regions == 2, name
        on_cut = {v for p in paths for v in p}
        side = {}
        for fi, t in enumerate(F):
            for v in t: side.setdefault(v, set()).add(face_patch[fi])
        for k in FEATURES:  # left features in one patch, right ones in the other, none on the cut
            assert P[k] not in on_cut and len(side[P[k]]) == 1, (name, k)
            assert side[P[k]] == side[P['foot_lf' if k.endswith(('l', 'lf', 'lb')) else 'foot_rf']], (name, k)
        assert side[P['foot_lf']] != side[P['foot_rf']], name
        print('%s: %s aux %s' % (name, {k: P[k] for k in P}, aux), file=sys.stderr)
        models.append({'mesh': '../../../shared/meshes/%s.obj' % name, 'partition_points': corners,
                       'auxiliary_points': aux, 'features': [P[k] for k in FEATURES]})
    out = '{"models": [\n' + ',\n'.join('  ' + json.dumps(m) for m in models) + '\n]}\n'
    sys.stdout.write(out)

if __name__ == '__main__':
    main()
