#!/usr/bin/python3
"""Run by run comparison of two btr_experiments results.csv files of the same plan: the worst
tumour centroid error [mm] and seconds of each run in A and in B, with the status where either
did not converge. Usage: /usr/bin/python3 bench/compare_suites.py A.csv B.csv"""
import csv,sys,collections
def load(p):
    d=collections.OrderedDict()
    for r in csv.DictReader(open(p)):
        k=(r['experiment'],r['setting'],r['variable'],r['value'],r['generating_youngs_modulus_Pa'])
        e=d.setdefault(k,[0,'',0])
        e[0]=max(e[0],float(r['centroid_distance_mm'])); e[1]=r['status'][:110]; e[2]=float(r['seconds'])
    return d
a=load(sys.argv[1]); b=load(sys.argv[2])
for k in a:
    print(k, "%.3f %.1fs | %.3f %.1fs"%(a[k][0],a[k][2],b[k][0],b[k][2]))
    if a[k][1]!='converged' or b[k][1]!='converged': print("    A:",a[k][1]); print("    B:",b[k][1])
