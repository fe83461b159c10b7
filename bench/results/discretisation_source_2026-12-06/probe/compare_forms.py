# Element against nodal form on the phantoms of make_phantoms.sh (run in that folder, after
# register_both_forms.sh): per tumour the element form's error, the nodal form's, the shift d
# between them, and the cosine of the element error with -d. Importable (obj, vcentroid).
import json, numpy as np, glob, sys
def obj(p):
    V=[];F=[]
    for l in open(p):
        t=l.split()
        if not t: continue
        if t[0]=='v': V.append([float(x) for x in t[1:4]])
        elif t[0]=='f': F.append([int(x.split('/')[0])-1 for x in t[1:4]])
    return np.array(V),np.array(F)
def vcentroid(V,F):
    a,b,c=V[F[:,0]],V[F[:,1]],V[F[:,2]]
    vol=np.einsum('ij,ij->i',a,np.cross(b,c))/6
    return ((a+b+c)/4*vol[:,None]).sum(0)/vol.sum()
pref='out_'
for d in (sorted(glob.glob('E*_nu*/')) if __name__ == '__main__' else []):
    try:
        A=json.load(open(d+pref+'estimated/report.json')); B=json.load(open(d+pref+'estimated_nodal/report.json'))
    except Exception as e: print(d,e); continue
    for ta,tb in zip(A['tumours'],B['tumours']):
        V,F=obj(d+'tumour_%s_supine.obj'%ta['name'])
        t=vcentroid(V,F)*1e3  # file units? check
        ca=np.array(ta['centroid_supine_mm']); cb=np.array(tb['centroid_supine_mm'])
        if abs(np.linalg.norm(ca-t)-ta['centroid_distance_mm'])>0.05: t=t/1e3
        e=ca-t; dd=cb-ca
        print('%-16s %-6s |e_el| %.2f (rep %.2f) |e_nod| %.2f |d| %.2f  cos(e,-d) %+.2f  |e+d| %.2f' % (d[:-1],ta['name'],np.linalg.norm(e),ta['centroid_distance_mm'],np.linalg.norm(cb-t),np.linalg.norm(dd), np.dot(e,-dd)/np.linalg.norm(e)/max(1e-9,np.linalg.norm(dd)), np.linalg.norm(e+dd)))
    print('   E estimated: element %.0f Pa, nodal %.0f Pa'%(A['stiffness']['estimated_youngs_modulus_Pa'], B['stiffness']['estimated_youngs_modulus_Pa']))
