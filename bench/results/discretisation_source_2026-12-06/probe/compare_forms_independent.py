# The element form's and the nodal form's tumour centroids against SfePy's truth (run from the
# repository root): python3 compare_forms_independent.py PROBE_DIR REPORTS_DIR, where REPORTS_DIR
# holds E1000_el, E1000_nod, E3400_el, E3400_nod (btr_register --out of each fat modulus's
# scene_estimated_regions.yaml, as given and with `volume_form: nodal` in its material).
import json, numpy as np, sys
sys.path.insert(0, sys.argv[1])
out = sys.argv[2]
from compare_forms import obj, vcentroid
for E in (1000, 3400):
    A=json.load(open('%s/E%d_el/report.json'%(out,E))); B=json.load(open('%s/E%d_nod/report.json'%(out,E)))
    for ta,tb in zip(A['tumours'],B['tumours']):
        V,F=obj('test/data/independent_truth_E%d/tumour_%s_supine.obj'%(E,ta['name']))
        t=vcentroid(V,F)
        ca=np.array(ta['centroid_supine_mm']); cb=np.array(tb['centroid_supine_mm'])
        if abs(np.linalg.norm(ca-t)-ta['centroid_distance_mm'])>0.05: t=t*1e3
        e=ca-t; dd=cb-ca
        print('SfePy fat %d %-8s |e_el| %.2f (rep %.2f) |e_nod| %.2f |d| %.2f  cos(e,-d) %+.2f  |e+d| %.2f' % (E,ta['name'],np.linalg.norm(e),ta['centroid_distance_mm'],np.linalg.norm(cb-t),np.linalg.norm(dd), np.dot(e,-dd)/np.linalg.norm(e)/max(1e-9,np.linalg.norm(dd)), np.linalg.norm(e+dd)))
