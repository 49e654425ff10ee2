# Throwaway (2026-12-08, fortieth session): the bunny's parameterized mesh as two Draco "meshes" whose
# positions are (u, v, tiny z) and (octahedral normal, tiny z), to measure what Draco would spend on a
# normal layer sent as the source (uv mesh + vertex normals) instead of texels. Input: `geomip param
# ../shared/meshes/bunny.obj -o /tmp/bp`; then `geomip rd -q --quick --no-geomip --no-lindstrom-turk
# /tmp/nm/uv.obj -o rd_uv` (and nrm.obj; create /tmp/nm first) and read the draco rows of rd.csv. See docs/codec-v3.md, "Normal maps
# from the parameterized mesh".
import math
V=[];VT=[];F=[]
for l in open('/tmp/bp/bunny.param.obj'):
    if l.startswith('v '): V.append(tuple(map(float,l.split()[1:4])))
    elif l.startswith('vt '): VT.append(tuple(map(float,l.split()[1:3])))
    elif l.startswith('f '):
        F.append([tuple(int(x)-1 for x in c.split('/')) for c in l.split()[1:]])
N=[[0.0,0.0,0.0] for _ in V]
for f in F:
    a,b,c=(V[x[0]] for x in f)
    u=[b[i]-a[i] for i in range(3)]; w=[c[i]-a[i] for i in range(3)]
    n=[u[1]*w[2]-u[2]*w[1],u[2]*w[0]-u[0]*w[2],u[0]*w[1]-u[1]*w[0]]
    for x in f:
        for i in range(3): N[x[0]][i]+=n[i]
def oct(n):
    l=math.sqrt(sum(c*c for c in n)) or 1; x,y,z=(c/l for c in n)
    s=abs(x)+abs(y)+abs(z); x/=s;y/=s
    if z<0:
        x,y=(1-abs(y))*(1 if x>=0 else -1),(1-abs(x))*(1 if y>=0 else -1)
    return x,y
vt2v={}
for f in F:
    for v,t in f: vt2v[t]=v
with open('/tmp/nm/uv.obj','w') as o:
    for t in range(len(VT)): o.write('v %.9f %.9f %.9f\n'%(VT[t][0],VT[t][1],1e-3*math.sin(VT[t][0]*37)*math.cos(VT[t][1]*23)))
    for f in F: o.write('f %d %d %d\n'%tuple(t+1 for v,t in f))
with open('/tmp/nm/nrm.obj','w') as o:
    for t in range(len(VT)):
        x,y=oct(N[vt2v[t]]); o.write('v %.9f %.9f %.9f\n'%(x,y,1e-3*math.sin(x*37)*math.cos(y*23)))
    for f in F: o.write('f %d %d %d\n'%tuple(t+1 for v,t in f))
print(len(V),len(VT),len(F))
