#!/usr/bin/env python3
"""A quad layout for a quadruped and its corners on horse, cow, pig and spot (tests/data/animals-layout.corr.json).

Plain python3, no dependencies; deterministic. Reuses make_animals_corr.py's frames and points (feet, nose, ears,
eyes, tail root, withers) and its 8 features, plus the tail root as a 9th feature.

The layout (66 corners, 64 quads, 128 edges: V - E + F = 2). The torso is a tube of four segments between five
stations S0..S4 along the body (S0: in front of the forelegs, S1: behind them, S2: halfway along the belly, S3:
in front of the hind legs, S4: behind them), each station a ring of 6 corners TL, TR, R, BR, BL, L (top left,
top right, right, bottom right, bottom left, left), closed at both ends by two quads each (upper: TL TR R L,
lower: L R BR BL). Protrusions are extruded from it, each replacing one quad Q by 4 side quads and a cap over 4
new corners:
  - each leg from the lower side quad (BL L) of its segment (forelegs: S0-S1, hind legs: S3-S4);
  - the tail from the rear end's upper quad;
  - the head four times: the neck from the front end's upper quad, the head from the neck's cap, the face
    from the head's cap, the snout from the face's front side. The face's cap is a strip along the top of the
    head between the ears and the eyes, its sides face_back, face_right, face_front, face_left; the snout's
    cap is round the nose, its sides snout_bottom (the jaw), snout_left, snout_top, snout_right.
So every leg and the tail have 5 patches of their own, the head 17; the foot lies in its leg's cap, the left
ear in face_left, the right ear in face_right, the left eye in snout_left, the right eye in snout_right, the
tail root in the tail's cap.

Why geometry and not a map through the 2-patch parameterization: corners placed on each animal by the same
rules land on the same anatomical place (the ring around each leg just below where it leaves the body, around
the neck behind the ears, around the tail root), while a stretch-minimizing map from one animal to another
moves a horse's leg root onto a pig's flank. The rules are cross-sections, so each protrusion's corners lie on
one loop around it:
  - a leg's rings are the boundaries of geodesic disks round its foot, of radius 90 % (root) and 55 % (lower
    ring) of the foot's geodesic distance to the body's midline (the belly or chest between the legs): on a long
    leg they are horizontal loops below the armpit and above the hoof, on the pig's stubs loops on the belly
    round them;
  - the neck and the head are cut by planes normal to the head's direction 35 % and 70 % of the way from the
    front station's corners to the rearmost of ears, eyes and top of the head (with a single cut at 50 % in
    the 46-quad layout the level-4 remeshes lost 1.2 dB on horse and spot, 2.2 dB on the pig; at 90 % the
    cow's left ear fell outside it);
  - the face is the part of the head (off its ring) above the eyes' level, from a quarter of the ears-to-eyes
    distance behind the ears to a tenth of the eyes-to-nose distance in front of the eyes, within half the
    ears' and eyes' least distance to the head's midplane from it: a strip on the forehead with the ears and
    eyes beside it, so that the head's surface is split four ways (the single cap over the ears and eyes held
    8 % of the horse and 24 % of spot), with each ear and the eyes in the same side on all four animals;
  - the snout ring is the boundary of the geodesic disk round the nose of radius 45 % of the nose's distance
    to the nearer eye (the face's front side alone held 15 % of spot);
  - the tail root ring is the boundary of the geodesic disk of radius 10 % of the body length around it, with
    whatever the disk cuts off (a tail hanging free from its root, less than a tenth of the vertices) added
    (without that, the cow's hanging tail lies in one side patch of the tail, L-inf stretch 40, and its level-4
    remesh loses 7 dB; a radius of 5 % puts the cow's tail root on a path, 12 % without the addition folds it);
  - a ring's 4 corners are the ring vertices seen from its centroid nearest the two diagonals of a plane
    (legs: forward and outward; head and tail: up and left; the face, seen from above: back and left), so they
    are in the same cyclic order everywhere;
  - the middle station is the torso's cross-section halfway between S1 and S3, its corners the section's
    vertices seen from its centre at the mean angle of the same corner at S1 and S3;
  - the stations' top corners TL, TR are the cross-section of the torso at the station's length (the mean of
    its leg-root corners), at its upper-left and upper-right extremes, no higher than the withers.
The script checks that the layout is a closed oriented quad surface with V - E + F = 2, that corners are
distinct and that no feature is a corner; whether the paths cut each mesh into the quads, with every feature in
its designated patch, is checked by `geomip param` and tests/tools/cli_test.cpp.
Usage: make_animals_layout.py [MESH_DIR] > animals-layout.corr.json
"""
import heapq, json, math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_animals_corr import MODELS, FEATURES, Frame, find_points, load_obj, split_pinches, dot  # noqa: E402

# Leg rings at these fractions of the foot's geodesic distance to the midline. The pig's front legs are stubs
# against its jaw: 0.7-0.9 / 0.3-0.45 leave its front feet on or outside the lower ring's paths, 0.7-0.8 / 0.55
# make two corners coincide; 0.9 / 0.55 puts every foot inside its leg's cap on all four animals.
ROOT, LOW = 0.9, 0.55
RING = ['TL', 'TR', 'R', 'BR', 'BL', 'L']  # a station's corners, going round the body
MID = 1  # stations between the forelegs' and the hind legs' (cross-sections evenly spaced along the belly)
NST = 4 + MID  # stations 0, 1 round the forelegs, H0, H1 round the hind legs (a 5th station: the torso's
# middle segment held 10-13 % of horse and cow in each of its flanks)
H0, H1 = NST - 2, NST - 1
# The head's rings, from the torso forward: (name, where the cut lies as a fraction of the way from the front
# station to the rearmost of ears, eyes and top of the head; None: the face strip).
HEAD_CUTS = [('neck', 0.35), ('head', 0.7), ('face', None)]
HEAD_RINGS = [h for h, _ in HEAD_CUTS]
# The face strip: FACE of the ears' and eyes' least distance to their midplane either side of it, from GAP of the
# ears-to-eyes distance behind the ears to FWD of the eyes-to-nose distance in front of the eyes (FWD 0.25 puts
# the pig's right eye on a path, 0.5 its left eye in face_left while the horse's is in face_front).
FACE, GAP, FWD = 0.5, 0.25, 0.1
# The snout: a geodesic disk round the nose of SNOUT of its distance to the nearer eye, extruded from face_front
# (0.4-0.5 put each eye in the snout's side on its side on all four animals, 0.6-0.7 puts spot's left eye on a
# path).
SNOUT = 0.45


def corner_names():
    names = ['%s%d' % (c, k) for k in range(NST) for c in RING]
    for leg in ('lf', 'rf', 'lb', 'rb'):
        names += ['%s_%s' % (leg, c) for c in ('fo', 'fi', 'bi', 'bo')]  # front/back, outer/inner
    for h in HEAD_RINGS:
        names += ['%s_%s' % (h, c) for c in ('tl', 'tr', 'br', 'bl')]
    names += ['tail_%s' % c for c in ('tl', 'tr', 'br', 'bl')]
    names += ['snout_%s' % c for c in ('tl', 'tr', 'br', 'bl')]
    return names


def layout_quads():
    """(name, [corner names]) for every quad, unoriented: the orientation is fixed by orient()."""
    quads = []
    for k in range(NST - 1):
        for i in range(6):
            a, b = RING[i], RING[(i + 1) % 6]
            quads.append(('torso%d_%s%s' % (k, a, b), ['%s%d' % (a, k), '%s%d' % (b, k), '%s%d' % (b, k + 1),
                                                       '%s%d' % (a, k + 1)]))
    for k, end in ((0, 'front'), (NST - 1, 'rear')):
        quads.append(('%s_upper' % end, ['TL%d' % k, 'TR%d' % k, 'R%d' % k, 'L%d' % k]))
        quads.append(('%s_lower' % end, ['L%d' % k, 'R%d' % k, 'BR%d' % k, 'BL%d' % k]))
    # protrusion: the quad it replaces (base corner -> new corner)
    extrusions = [('leg_lf', {'L0': 'lf_fo', 'BL0': 'lf_fi', 'BL1': 'lf_bi', 'L1': 'lf_bo'}, 'torso0_BLL'),
                  ('leg_rf', {'R0': 'rf_fo', 'BR0': 'rf_fi', 'BR1': 'rf_bi', 'R1': 'rf_bo'}, 'torso0_RBR'),
                  ('leg_lb', {'L%d' % H0: 'lb_fo', 'BL%d' % H0: 'lb_fi', 'BL%d' % H1: 'lb_bi', 'L%d' % H1: 'lb_bo'},
                   'torso%d_BLL' % H0),
                  ('leg_rb', {'R%d' % H0: 'rb_fo', 'BR%d' % H0: 'rb_fi', 'BR%d' % H1: 'rb_bi', 'R%d' % H1: 'rb_bo'},
                   'torso%d_RBR' % H0),
                  ('tail', {'TL%d' % H1: 'tail_tl', 'TR%d' % H1: 'tail_tr', 'R%d' % H1: 'tail_br',
                            'L%d' % H1: 'tail_bl'}, 'rear_upper')]
    prev, base = ['TL0', 'TR0', 'R0', 'L0'], 'front_upper'
    for h in HEAD_RINGS:
        cur = ['%s_%s' % (h, c) for c in ('tl', 'tr', 'br', 'bl')]
        extrusions.append((h, dict(zip(prev, cur)), base))
        prev, base = cur, '%s_cap' % h
    # the snout from face_front, seen from the front: the face's front corners up, the head ring's below
    extrusions.append(('snout', {'face_bl': 'snout_tl', 'face_br': 'snout_tr', 'head_br': 'snout_br',
                                 'head_bl': 'snout_bl'}, 'face_front'))
    for name, new, base in extrusions:
        q = dict(quads)[base]
        assert set(q) == set(new), name
        quads = [x for x in quads if x[0] != base]
        for i in range(4):
            a, b = q[i], q[(i + 1) % 4]
            side = {'face': ('face_back', 'face_right', 'face_front', 'face_left'),
                    'snout': ('snout_bottom', 'snout_left', 'snout_top', 'snout_right')}
            side = side[name][i] if name in side else '%s_side%d' % (name, i)
            quads.append((side, [a, b, new[b], new[a]]))
        quads.append(('%s_cap' % name, [new[c] for c in q]))
    return quads


def orient(quads, names):
    """Orients the quads consistently (each directed edge once) and checks the surface: closed, V - E + F = 2."""
    idx = {n: i for i, n in enumerate(names)}
    Q = [[idx[c] for c in q] for _, q in quads]
    edges = {}
    for qi, q in enumerate(Q):
        for i in range(4):
            edges.setdefault(frozenset((q[i], q[(i + 1) % 4])), []).append(qi)
    assert all(len(v) == 2 for v in edges.values()), 'every layout edge in exactly two quads'
    done = {0}
    stack = [0]
    while stack:
        qi = stack.pop()
        q = Q[qi]
        for i in range(4):
            a, b = q[i], q[(i + 1) % 4]
            for oj in edges[frozenset((a, b))]:
                if oj == qi: continue
                o = Q[oj]
                pairs = [(o[j], o[(j + 1) % 4]) for j in range(4)]
                if oj in done:
                    assert (b, a) in pairs, 'orientable'
                    continue
                if (a, b) in pairs: Q[oj] = o[::-1]
                done.add(oj); stack.append(oj)
    assert len(done) == len(Q), 'connected'
    V, E, F = len(names), len(edges), len(Q)
    assert V - E + F == 2, (V, E, F)
    return Q


def adjacency(V, F):
    adj = [set() for _ in V]
    for t in F:
        for i in range(3):
            adj[t[i]].add(t[(i + 1) % 3]); adj[t[(i + 1) % 3]].add(t[i])
    return [sorted(a) for a in adj]


def flood(adj, start, keep):
    seen = {start}
    stack = [start]
    while stack:
        x = stack.pop()
        for y in adj[x]:
            if y not in seen and keep(y): seen.add(y); stack.append(y)
    return seen


def boundary(adj, comp):
    return sorted(v for v in comp if any(w not in comp for w in adj[v]))


def geodesic(V, adj, s, limit):
    """Dijkstra's distances along edges from the vertex s (or the vertices of the list s), up to `limit`."""
    dist = {v: 0.0 for v in (s if isinstance(s, list) else [s])}
    pq = [(0.0, v) for v in dist]
    while pq:
        d, x = heapq.heappop(pq)
        if d > dist[x] or d > limit: continue
        for y in adj[x]:
            e = V[x]; f = V[y]
            nd = d + ((e[0] - f[0]) ** 2 + (e[1] - f[1]) ** 2 + (e[2] - f[2]) ** 2) ** 0.5
            if nd < dist.get(y, 1e300): dist[y] = nd; heapq.heappush(pq, (nd, y))
    return dist


def extremes(ring, coords, dirs, centre=None):
    """For each direction of `dirs` (weights on the two coordinates), the ring vertex seen from `centre` (by
    default the ring's centroid) at the angle nearest that direction's (the farther one among ties): distinct
    corners in the same cyclic order as the directions whenever the ring goes once round the centre."""
    n = len(ring)
    ca = sum(coords(v)[0] for v in ring) / n; cb = sum(coords(v)[1] for v in ring) / n
    if centre is not None: ca, cb = centre
    polar = {v: (math.atan2(coords(v)[1] - cb, coords(v)[0] - ca), math.hypot(coords(v)[0] - ca, coords(v)[1] - cb))
             for v in ring}
    out = []
    for wa, wb in dirs:
        t = math.atan2(wb, wa)
        gap = lambda v: abs(math.remainder(polar[v][0] - t, 2 * math.pi))
        out.append(min(ring, key=lambda v: (round(gap(v), 9), -polar[v][1], v)))
    return out


def disk_with_cutoffs(V, F, adj, centre, r):
    """The geodesic disk of radius r round `centre`, with whatever it cuts off from the rest of the mesh (each
    piece under a tenth of the vertices: a tail hanging free from its root, an ear flap) added."""
    dist = geodesic(V, adj, centre, 2 * r)
    disk = {v for v, d in dist.items() if d < r}
    used = sorted({v for t in F for v in t})
    rest = [v for v in used if v not in disk]
    seen = set()
    for v in rest:
        if v in seen: continue
        part = flood(adj, v, lambda w: w not in disk)
        seen |= part
        if len(part) < len(used) // 10: disk |= part
    return disk


def place(name, V, F, fr, P):
    adj = adjacency(V, F)
    L, H = fr.length, fr.height
    C = {}
    feet = {leg: P['foot_' + leg] for leg in ('lf', 'rf', 'lb', 'rb')}
    # Legs: geodesic rings round the foot, at ROOT and LOW of its distance to the body's midline (the belly
    # between the legs; a stumpy leg's rings then lie on the belly round it).
    midline = [v for v in range(len(V)) if abs(fr.Lc[v] - fr.lmid) < 0.05 * fr.halfwidth]
    for leg, foot in feet.items():
        left = leg[0] == 'l'
        dist = geodesic(V, adj, foot, 2 * L)
        reach = min(dist.get(v, 1e300) for v in midline)
        side = 1 if left else -1
        coords = lambda v: (fr.F[v], side * (fr.Lc[v] - fr.lmid))
        for frac, tag in ((ROOT, 'root'), (LOW, 'low')):
            ring = boundary(adj, {v for v, d in dist.items() if d < frac * reach})
            fo, fi, bi, bo = extremes(ring, coords, ((1, 1), (1, -1), (-1, -1), (-1, 1)))
            if tag == 'low':
                C.update({'%s_fo' % leg: fo, '%s_fi' % leg: fi, '%s_bi' % leg: bi, '%s_bo' % leg: bo})
            else:
                s0, s1 = (0, 1) if leg[1] == 'f' else (H0, H1)
                o, i = ('L', 'BL') if left else ('R', 'BR')
                C.update({'%s%d' % (o, s0): fo, '%s%d' % (i, s0): fi, '%s%d' % (i, s1): bi, '%s%d' % (o, s1): bo})
        print('%s leg %s: midline %.3f L away' % (name, leg, reach / L), file=sys.stderr)
    # Stations' top corners: the torso's cross-section at the station, upper-left / upper-right extremes.
    top = fr.U[P['withers']]
    for k in (0, 1, H0, H1):
        fs = (fr.F[C['L%d' % k]] + fr.F[C['R%d' % k]]) / 2
        low = max(fr.U[C['L%d' % k]], fr.U[C['R%d' % k]])
        w = 0.01 * L
        while True:
            sl = [v for v in range(len(V)) if abs(fr.F[v] - fs) < w and low < fr.U[v] <= top]
            if len({v for v in sl if fr.Lc[v] > fr.lmid}) >= 3 and len({v for v in sl if fr.Lc[v] < fr.lmid}) >= 3:
                break
            w *= 1.5
        C['TL%d' % k] = max((v for v in sl if fr.Lc[v] > fr.lmid), key=lambda v: (fr.U[v] + fr.Lc[v] - fr.lmid, -v))
        C['TR%d' % k] = max((v for v in sl if fr.Lc[v] < fr.lmid), key=lambda v: (fr.U[v] - fr.Lc[v] + fr.lmid, -v))
    # Middle stations: cross-sections evenly spaced between stations 1 and H0, each corner at the mean angle
    # (seen from the section's centre) of the same corner at stations 1 and H0.
    tcoords = lambda v: (fr.Lc[v] - fr.lmid, fr.U[v])
    def section(fs):
        w = 0.01 * L
        while True:
            sl = [v for v in range(len(V)) if abs(fr.F[v] - fs) < w]
            if len(sl) >= 24: break
            w *= 1.5
        return sl, (sum(tcoords(v)[0] for v in sl) / len(sl), sum(tcoords(v)[1] for v in sl) / len(sl))
    ends = {}
    for k in (1, H0):
        fs = sum(fr.F[C['%s%d' % (c, k)]] for c in RING) / 6
        _, centre = section(fs)
        ends[k] = (fs, centre)
    for m in range(1, MID + 1):
        t = m / (MID + 1)
        fs = (1 - t) * ends[1][0] + t * ends[H0][0]
        sl, centre = section(fs)
        dirs = []
        for c in RING:
            d = [0.0, 0.0]
            for k, wt in ((1, 1 - t), (H0, t)):
                a, b = tcoords(C['%s%d' % (c, k)]); n = math.hypot(a - ends[k][1][0], b - ends[k][1][1])
                d[0] += wt * (a - ends[k][1][0]) / n; d[1] += wt * (b - ends[k][1][1]) / n
            dirs.append(tuple(d))
        C.update({'%s%d' % (c, 1 + m): v for c, v in zip(RING, extremes(sl, tcoords, dirs, centre))})
    # Head: cuts normal to the head's direction behind the ears, eyes and top of the head, then the face strip.
    hf = lambda v: dot(V[v], fr.hf)
    back = min(hf(P[k]) for k in ('ear_l', 'ear_r', 'eye_l', 'eye_r', 'head_top'))
    front = max(hf(C[k]) for k in ('TL0', 'TR0', 'L0', 'R0'))
    hcoords = lambda v: (fr.U[v], dot(V[v], fr.hl))
    for h, frac in HEAD_CUTS:
        if frac is None:
            # The face: a strip along the top of the head (above the eyes' level, off the head's ring) between
            # the ears and between the eyes (see FACE). Its corners back / front, left / right: seen from above,
            # with the back up, in the same cyclic order as a ring's seen from the front.
            hl = lambda v: dot(V[v], fr.hl)
            feats = [P[k] for k in ('ear_l', 'ear_r', 'eye_l', 'eye_r')]
            m = sum(hl(v) for v in feats) / 4
            half = FACE * min(abs(hl(v) - m) for v in feats)
            ue = min(fr.U[P[k]] for k in ('eye_l', 'eye_r'))
            hb = min(hf(P[k]) for k in ('ear_l', 'ear_r')); hn = max(hf(P[k]) for k in ('eye_l', 'eye_r'))
            hb, hn = hb - GAP * (hn - hb), hn + FWD * (hf(P['nose']) - hn)
            body = flood(adj, C['TL0'], lambda v: v not in comp)  # (not a horn tip the head's cut cuts off)
            keep = lambda v: (v in comp and abs(hl(v) - m) < half and hb <= hf(v) <= hn and fr.U[v] >= ue and
                              not any(w in body for w in adj[v]))
            start = max((v for v in comp if keep(v)), key=lambda v: (fr.U[v], -v))
            disk = flood(adj, start, keep)
            assert not set(feats) & disk, (name, 'the ears and eyes beside the face')
            ring = boundary(adj, disk)
            tl, bl, br, tr = extremes(ring, lambda v: (-hf(v), dot(V[v], fr.hl)), ((1, 1), (-1, 1), (-1, -1), (1, -1)))
            C.update({h + '_tl': tl, h + '_bl': bl, h + '_br': br, h + '_tr': tr})
            continue
        cut = front + frac * (back - front) if front < back else back
        comp = flood(adj, P['nose'], lambda v: hf(v) >= cut)
        assert not comp & set(feet.values()), (name, 'head cut reaches a foot')
        ring = boundary(adj, comp)
        tl, bl, br, tr = extremes(ring, hcoords, ((1, 1), (-1, 1), (-1, -1), (1, -1)))
        C.update({h + '_tl': tl, h + '_bl': bl, h + '_br': br, h + '_tr': tr})
    # Snout: the boundary of the geodesic disk round the nose.
    eyes = geodesic(V, adj, P['nose'], 4 * L)
    disk = disk_with_cutoffs(V, F, adj, P['nose'], SNOUT * min(eyes[P[k]] for k in ('eye_l', 'eye_r')))
    tl, bl, br, tr = extremes(boundary(adj, disk), hcoords, ((1, 1), (-1, 1), (-1, -1), (1, -1)))
    C.update({'snout_tl': tl, 'snout_bl': bl, 'snout_br': br, 'snout_tr': tr})
    # Tail: the boundary of the geodesic disk around the tail root.
    disk = disk_with_cutoffs(V, F, adj, P['tail'], 0.1 * L)
    ring = boundary(adj, disk)
    tcoords = lambda v: (fr.U[v], fr.Lc[v])
    tl, bl, br, tr = extremes(ring, tcoords, ((1, 1), (-1, 1), (-1, -1), (1, -1)))
    C.update({'tail_tl': tl, 'tail_bl': bl, 'tail_br': br, 'tail_tr': tr})
    return C


def main():
    mesh_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                                    '..', '..', '..', 'shared', 'meshes')
    names = corner_names()
    quads = layout_quads()
    models = []
    oriented = None
    for name, fwd, up, yaw, head_frac in MODELS:
        V0, F0 = load_obj(os.path.join(mesh_dir, name + '.obj'))
        V, F, copies = split_pinches(V0, F0)
        fr = Frame(V0, fwd, up, yaw, head_frac)
        P = find_points(V0, F0, fr, name)
        C = place(name, V, F, Frame(V, fwd, up, yaw, head_frac), P)  # (the cow's split pinch: one more vertex)
        corners = [C[n] for n in names]
        features = [P[k] for k in FEATURES] + [P['tail']]
        dup = [n for n in names if corners.count(C[n]) > 1]
        assert not dup, (name, 'corners that coincide', dup)
        assert not set(features) & set(corners), (name, 'a feature is a corner')
        assert not any(v in copies for v in corners + features), name
        if oriented is None:
            # The quads' orientation: counter-clockwise seen from outside, i.e. the middle of the back faces up.
            oriented = orient(quads, names)
            q = oriented[[n for n, _ in quads].index('torso1_TLTR')]
            p = [V[C[names[i]]] for i in q]
            d1 = [p[2][j] - p[0][j] for j in range(3)]; d2 = [p[3][j] - p[1][j] for j in range(3)]
            n = (d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2], d1[0] * d2[1] - d1[1] * d2[0])
            if dot(n, fr.u) < 0: oriented = [qq[::-1] for qq in oriented]
        print('%s: %s' % (name, C), file=sys.stderr)
        models.append({'mesh': '../../../shared/meshes/%s.obj' % name, 'partition_points': corners,
                       'features': features})
    out = '{"layout": {"quads": %s,\n  "quad_names": %s,\n  "corner_names": %s,\n  "feature_names": %s},\n' % (
        json.dumps(oriented), json.dumps([n for n, _ in quads]), json.dumps(names), json.dumps(FEATURES + ['tail']))
    out += '"models": [\n' + ',\n'.join('  ' + json.dumps(m) for m in models) + '\n]}\n'
    sys.stdout.write(out)


if __name__ == '__main__':
    main()
