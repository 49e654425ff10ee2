#!/usr/bin/env python3
# Experiment (2026-12-05, docs/measurements.md "Three quads per coarse triangle"): for each corner of the layout in
# DIR/<stem>.param.json, whether the cyclic order of its layout neighbours matches the order of their directions
# projected on the tangent plane, and how many big patch corners (> 200°, scripts/linf-diagnose) sit at corners
# that do not match. Usage: layout-corner-order-2026-12-05.py DIR/<stem>.param.json MESH.obj (run from the
# repository root). Crude: far neighbours on a curved part project unreliably.
import json, math, sys
d=json.load(open(sys.argv[1])); mesh=sys.argv[2]
V=[];F=[]
for l in open(mesh):
    if l.startswith('v '): V.append(list(map(float,l.split()[1:4])))
    elif l.startswith('f '): F.append([int(x.split('/')[0])-1 for x in l.split()[1:4]])
def sub(a,b): return [a[i]-b[i] for i in range(3)]
def cross(a,b): return [a[1]*b[2]-a[2]*b[1],a[2]*b[0]-a[0]*b[2],a[0]*b[1]-a[1]*b[0]]
def dot(a,b): return sum(a[i]*b[i] for i in range(3))
def norm(a): return dot(a,a)**0.5
N=[[0,0,0] for _ in V]
for f in F:
    n=cross(sub(V[f[1]],V[f[0]]),sub(V[f[2]],V[f[0]]))
    for k in f:
        for i in range(3): N[k][i]+=n[i]
N=[[x/norm(n) for x in n] for n in N]
pp=d['partition_points']; quads=d['layout_quads']
# outgoing layout edges per corner in quad order: quad q at corner c: next corner = q[(i+1)%4]
from collections import defaultdict
out=defaultdict(dict)  # corner -> {next: prev}  (ccw fan: edge c->next, then c->prev of same quad)
for q in quads:
    for i in range(4):
        c=q[i]; out[c][q[(i+1)%4]]=q[(i+3)%4]
bad=0; total=0; badc=[]
for c,m in out.items():
    # build ccw cycle of neighbours: from quad: next then prev is cw or ccw? quad ccw: c->next is side, c->prev is the other side; going around c ccw from next... 
    start=next(iter(m)); cyc=[start]; x=start
    while True:
        x=m[x]
        if x==start: break
        cyc.append(x)
        if len(cyc)>50: break
    p=V[pp[c]]; n=N[pp[c]]
    e1=cross(n,[1,0,0])
    if norm(e1)<0.1: e1=cross(n,[0,1,0])
    e1=[x/norm(e1) for x in e1]; e2=cross(n,e1)
    ang=[math.atan2(dot(sub(V[pp[y]],p),e2),dot(sub(V[pp[y]],p),e1)) for y in cyc]
    # count descents in angular order (cyclic): monotone in one direction means consistent
    diffs=[(ang[(i+1)%len(ang)]-ang[i])%(2*math.pi) for i in range(len(ang))]
    turns=sum(diffs)/(2*math.pi)
    total+=1
    if abs(turns-1)>0.01 and abs(turns-(len(ang)-1))>0.01:
        bad+=1; badc.append((c,len(cyc),round(turns,2)))
print("corners",total,"order not monotone",bad, badc[:10])
badset={b[0] for b in badc}
import subprocess
diag=subprocess.run(['python3','scripts/linf-diagnose',sys.argv[1]],capture_output=True,text=True).stdout.splitlines()[1:]
big=0; bigbad=0; small=0; smallbad=0
for line in diag:
    f=[x.strip() for x in line.split('|')]
    q=int(f[0]); angs=list(map(float,f[4].split()))
    for i,a in enumerate(angs):
        c=quads[q][i]
        if a>200: big+=1; bigbad+= c in badset
        else: small+=1; smallbad+= c in badset
print("corner angles >200:",big,"at mismatched corners:",bigbad,"| <=200:",small,"at mismatched:",smallbad)
