# Runs of a btr_experiments results.csv: status counts (a run is one experiment x setting x value x
# generating E; its rows are its tumours), the runs not converged, and the full method's worst tumour.
# Usage: /usr/bin/python3 summarize.py results.csv
import csv, collections, sys
rows=list(csv.DictReader(open(sys.argv[1])))
runs=collections.OrderedDict()
for r in rows:
    k=(r['experiment'],r['setting'],r['variable'],r['value'],r['generating_youngs_modulus_Pa'])
    runs.setdefault(k,[]).append(r)
st=collections.Counter(v[0]['status'].split(' (')[0] for v in runs.values())
print(len(runs),'runs', dict(st), 'fell back', sum('element form' in v[0]['status'] for v in runs.values()))
for k,v in runs.items():
    if not v[0]['status'].startswith('converged'): print('  NOT:', k, v[0]['status'][:150])
for k,v in runs.items():
    if k[0]=='practical' and k[1]=='full': print('  full', k[4], 'worst %.3f'%max(float(x['centroid_distance_mm']) for x in v), v[0]['estimated_youngs_modulus_Pa'])
