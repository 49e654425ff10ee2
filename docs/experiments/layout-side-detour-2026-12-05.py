#!/usr/bin/env python3
# Experiment (2026-12-05, docs/measurements.md "Three quads per coarse triangle"): for each side of the layout in
# DIR/<stem>.param.json, its traced 3D length over the shortest-path distance of its endpoints on the edge graph.
# Usage: layout-side-detour-2026-12-05.py DIR/<stem>.param.json MESH.obj
import json, math, sys, heapq
d=json.load(open(sys.argv[1])); mesh=sys.argv[2]
V=[];F=[]
for l in open(mesh):
    if l.startswith('v '): V.append(list(map(float,l.split()[1:4])))
    elif l.startswith('f '): F.append([int(x.split('/')[0])-1 for x in l.split()[1:4]])
adj=[set() for _ in V]
for f in F:
    for i in range(3): adj[f[i]].add(f[(i+1)%3]); adj[f[(i+1)%3]].add(f[i])
def L(a,b): return math.dist(V[a],V[b])
def dij(s,t):
    dist={s:0.0}; h=[(0.0,s)]
    while h:
        dd,x=heapq.heappop(h)
        if x==t: return dd
        if dd>dist[x]: continue
        for y in adj[x]:
            nd=dd+L(x,y)
            if nd<dist.get(y,1e30): dist[y]=nd; heapq.heappush(h,(nd,y))
seen={}; ratios=[]
nv=len(V)
for p in d['patches']:
    for s in p['sides']:
        if any(v>=nv for v in s): continue
        key=(min(s[0],s[-1]),max(s[0],s[-1]))
        if key in seen: continue
        plen=sum(L(s[i],s[i+1]) for i in range(len(s)-1))
        g=dij(s[0],s[-1]); seen[key]=plen/g; ratios.append(plen/g)
ratios.sort()
n=len(ratios)
print("sides",n,"path/geodesic median %.3f p90 %.3f max %.3f"%(ratios[n//2],ratios[int(n*.9)],ratios[-1]), "above 1.5:",sum(r>1.5 for r in ratios))
