# Throwaway (2026-12-08, fortieth session): a normal layer sent as the source (the parameterized mesh: uv and
# vertex normals) instead of texels. docs/codec-v3.md, "Normal maps from the parameterized mesh".
#   python3 this.py PARAM.obj meshes DIR        writes DIR/uv.obj (positions (u, v, tiny z)) and DIR/nrm.obj
#       (positions (octahedral normal, tiny z)), whose Draco bytes `geomip rd -q --no-geomip
#       --no-lindstrom-turk --samples 20000 DIR/uv.obj -o OUT` gives in the draco rows of OUT/rd.csv
#   python3 this.py PARAM.obj raster Q_uv Q_n [L=9]   rasterizes the normal maps at level L with the uv quantized
#       to Q_uv bits and the octahedral normals to Q_n bits as Draco quantizes them; prints the mean / max angle
#       to the maps of the exact mesh (about 10 s at level 9)
# PARAM.obj: `geomip param MESH -o DIR` (DIR/<stem>.param.obj; the horse with --patches 2).
import math, sys
V=[];VT=[];F=[];G=[]
g=-1
for l in open(sys.argv[1]):
    if l.startswith('v '): V.append(tuple(map(float,l.split()[1:4])))
    elif l.startswith('vt '): VT.append(tuple(map(float,l.split()[1:3])))
    elif l.startswith('g '): g+=1
    elif l.startswith('f '):
        F.append([tuple(int(x)-1 for x in c.split('/')) for c in l.split()[1:]]); G.append(g)
def unit(n):
    l=math.sqrt(sum(c*c for c in n)) or 1; return [c/l for c in n]
N=[[0.0,0.0,0.0] for _ in V]  # area-weighted vertex normals, as resample_geometry takes them
for f in F:
    a,b,c=(V[x[0]] for x in f)
    u=[b[i]-a[i] for i in range(3)]; w=[c[i]-a[i] for i in range(3)]
    n=[u[1]*w[2]-u[2]*w[1],u[2]*w[0]-u[0]*w[2],u[0]*w[1]-u[1]*w[0]]
    for x in f:
        for i in range(3): N[x[0]][i]+=n[i]
N=[unit(n) for n in N]
def oct_enc(n):
    x,y,z=n; s=abs(x)+abs(y)+abs(z); x/=s;y/=s
    if z<0: x,y=(1-abs(y))*(1 if x>=0 else -1),(1-abs(x))*(1 if y>=0 else -1)
    return x,y
def oct_dec(x,y):
    z=1-abs(x)-abs(y)
    if z<0: x,y=(1-abs(y))*(1 if x>=0 else -1),(1-abs(x))*(1 if y>=0 else -1)
    return unit([x,y,z])

def write_meshes(d):
    vt2v={}
    for f in F:
        for v,t in f: vt2v[t]=v
    ripple=lambda x,y: 1e-3*math.sin(x*37)*math.cos(y*23)  # not flat, so that rd can measure it
    for name,pos in (('uv',lambda t: VT[t]),('nrm',lambda t: oct_enc(N[vt2v[t]]))):
        with open(d+'/'+name+'.obj','w') as o:
            for t in range(len(VT)):
                x,y=pos(t); o.write('v %.9f %.9f %.9f\n'%(x,y,ripple(x,y)))
            for f in F: o.write('f %d %d %d\n'%tuple(t+1 for v,t in f))
    print(len(V),'vertices',len(VT),'uv pairs',len(F),'triangles')

def quant(v,lo,ext,q):
    if q<=0: return v
    s=ext/((1<<q)-1); return lo+round((v-lo)/s)*s
def raster(uvq,nq,R):
    out={}
    UV=[(quant(u,0,1,uvq),quant(v,0,1,uvq)) for u,v in VT]
    NN=[oct_dec(*(quant(c,-1,2,nq) for c in oct_enc(n))) if nq>0 else n for n in N]
    for f,p in zip(F,G):
        (va,ta),(vb,tb),(vc,tc)=f
        A,B,C=UV[ta],UV[tb],UV[tc]
        det=(B[0]-A[0])*(C[1]-A[1])-(C[0]-A[0])*(B[1]-A[1])
        if det==0: continue
        i0=max(0,math.ceil(min(A[0],B[0],C[0])*R)); i1=min(R,math.floor(max(A[0],B[0],C[0])*R))
        j0=max(0,math.ceil(min(A[1],B[1],C[1])*R)); j1=min(R,math.floor(max(A[1],B[1],C[1])*R))
        for i in range(i0,i1+1):
            x=i/R
            for j in range(j0,j1+1):
                y=j/R
                l1=((B[0]-x)*(C[1]-y)-(C[0]-x)*(B[1]-y))/det
                l2=((C[0]-x)*(A[1]-y)-(A[0]-x)*(C[1]-y))/det
                l3=1-l1-l2
                if min(l1,l2,l3)<-1e-12 or (p,i,j) in out: continue
                na,nb,nc=NN[va],NN[vb],NN[vc]
                out[(p,i,j)]=unit([l1*na[k]+l2*nb[k]+l3*nc[k] for k in range(3)])
    return out

if sys.argv[2]=='meshes':
    write_meshes(sys.argv[3])
else:
    uvq,nq=int(sys.argv[3]),int(sys.argv[4]); R=1<<(int(sys.argv[5]) if len(sys.argv)>5 else 9)
    ref,t=raster(0,0,R),raster(uvq,nq,R)
    s=0;c=0;mx=0
    for k,n in ref.items():
        m=t.get(k)
        if m is None: continue
        d=sum(a*b for a,b in zip(n,m)); cr=[n[1]*m[2]-n[2]*m[1],n[2]*m[0]-n[0]*m[2],n[0]*m[1]-n[1]*m[0]]
        a=math.degrees(math.atan2(math.sqrt(sum(x*x for x in cr)),d)); s+=a;c+=1;mx=max(mx,a)
    print("uv Q",uvq,"normal Q",nq,"texels",len(ref),"compared",c,"mean %.4f deg max %.3f"%(s/c,mx))
