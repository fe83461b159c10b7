#!/usr/bin/python3
"""Tables of bench/run_independent_suite.sh: the quick suite on SfePy's independent truth beside
our phantom, per generating (fat) E. Worst tumour centroid error [mm] of a run; * marks a run that
did not converge; "failed": the run could not start (e.g. the truth's own mesh inverted).
Usage: /usr/bin/python3 bench/summarize_independent_suite.py OUT"""
import collections, csv, os, statistics, sys

out = sys.argv[1]
VARIANTS = [('truth_mesh', "truth's mesh, prone as rest"), ('truth_mesh_estimated', "truth's mesh, unloaded at estimated E"),
            ('prone', '7 mm, prone as rest'), ('estimated', '7 mm, unloaded at estimated E'),
            ('nodal', '7 mm, estimated E, nodal volume term')]


def load(name):
    path = os.path.join(out, name, 'results.csv')
    if not os.path.isfile(path):
        return None
    runs = {}
    for r in csv.DictReader(open(path)):
        k = (r['experiment'], r['setting'], r['value'], float(r['generating_youngs_modulus_Pa']), r['variable'])
        d = float(r['centroid_distance_mm']) if r['centroid_distance_mm'] not in ('', 'nan') else float('inf')
        w, st, s, est = runs.get(k, (0.0, r['status'], float(r['seconds'] or 'nan'), r['estimated_youngs_modulus_Pa']))
        runs[k] = (max(w, d), st, s, est)
    return runs


def cell(runs, exp, value, e):
    for (x, setting, v, ee, var), (w, st, s, est) in runs.items():
        if x == exp and v == value and ee == e:
            if st.startswith('failed'):
                return 'failed'
            return '%.2f%s' % (w, '' if st.startswith('converged') else '*')
    return '-'


data = {(body, v): load('%s_%s' % (body, v)) for body in ('sfepy', 'phantom') for v, _ in VARIANTS}
moduli = sorted({k[3] for runs in data.values() if runs for k in runs})
print('Full method (practical / full), worst tumour [mm]; rigid only for scale; not converged of the quick suite\'s runs')
print()
print('| body | fat E [Pa] | rigid only | ' + ' | '.join(t for _, t in VARIANTS) + ' | not converged (' +
      ' / '.join(v for v, _ in VARIANTS) + ') |')
print('|---|---|---|' + '---|' * len(VARIANTS) + '---|')
for body in ('sfepy', 'phantom'):
    for e in moduli:
        row, nc, rigid = [], [], '-'
        for v, _ in VARIANTS:
            runs = data[(body, v)]
            if not runs or not any(k[3] == e for k in runs):
                row.append('-'), nc.append('-')
                continue
            row.append(cell(runs, 'practical', 'full', e))
            if rigid in ('-', 'failed'):
                rigid = cell(runs, 'practical', 'rigid', e)
            here = [st for k, (w, st, s, est) in runs.items() if k[3] == e]
            nc.append('%d/%d' % (sum(not st.startswith('converged') for st in here), len(here)))
        print('| %s | %g | %s | %s | %s |' % (body, e, rigid, ' | '.join(row), ' / '.join(nc)))
print()
print('Rest-shape experiment of the 7 mm estimated runs (method E 3400 Pa but for "estimated"), worst tumour [mm]')
print()
print('| body | fat E [Pa] | prone shape | true rest shape | unloaded at 3400 Pa | unloaded at estimated E | estimated E | seconds (estimated) |')
print('|---|---|---|---|---|---|---|---|')
for body in ('sfepy', 'phantom'):
    runs = data[(body, 'estimated')]
    if not runs:
        continue
    for e in moduli:
        if not any(k[3] == e for k in runs):
            continue
        est = [(x[3], x[2]) for k, x in runs.items() if k[0] == 'rest_shape' and k[2] == 'estimated' and k[3] == e]
        print('| %s | %g | %s | %s | %s | %s | %s | %s |' % (
            body, e, cell(runs, 'rest_shape', 'prone', e), cell(runs, 'rest_shape', 'rest', e),
            cell(runs, 'rest_shape', 'unloaded', e), cell(runs, 'rest_shape', 'estimated', e),
            '%.0f' % float(est[0][0]) if est else '-', '%.1f' % est[0][1] if est else '-'))
