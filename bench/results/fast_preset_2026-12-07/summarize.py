# Tables of the fast preset's study from reports/ (python3 summarize.py, in this folder): every
# scene with fast as it is (element form, 9 mm, linear unload), the candidates (the scene with
# material.volume_form: nodal stated, --preset fast at its 9 mm and at --cell-size 11) and
# balanced, one run each, the four side by side (bash run.sh OUT NAME=SCENE ...).
import json, os, statistics as st
here = os.path.dirname(os.path.abspath(__file__))
SCENES = ['S1_1000', 'S1_3400', 'S2_500', 'S2_1000', 'S2_3400', 'P400', 'P1000', 'C2000_est', 'C700_est',
          'C2000_told', 'C700_told', 'P700_est', 'P2000_est', 'P700_rf', 'P2000_rf']
COLS = [('fast', 'fast as it is'), ('fastn9', 'nodal, 9 mm'), ('fastn11', 'nodal, 11 mm'), ('bal', 'balanced')]
def load(tag, n):
    f = '%s/reports/%s_%s.json' % (here, tag, n)
    if not os.path.exists(f): return None
    r = json.load(open(f))
    return (max(t['centroid_distance_mm'] for t in r['tumours']),
            sum(r['seconds'].get(k, 0) for k in ('prepare', 'registration_total')), r['converged'])
def cell(v): return '-' if not v else '%.3f mm, %.1f s%s' % (v[0], v[1], '' if v[2] else ', NOT converged')
print('| scene | ' + ' | '.join(c[1] for c in COLS) + ' |\n|---|' + '---|' * len(COLS))
for n in SCENES: print('| %s | %s |' % (n, ' | '.join(cell(load(t, n)) for t, _ in COLS)))
def tally(a, b):
    ps = [(load(a, n), load(b, n)) for n in SCENES]
    ps = [(x, y) for x, y in ps if x and y]
    e, s = [x[0] / y[0] for x, y in ps], [x[1] / y[1] for x, y in ps]
    return (sum(x[0] < y[0] for x, y in ps), sum(x[0] > y[0] for x, y in ps), len(ps), st.median(e), st.median(s), min(s), max(s))
for a, b in [('fast', 'bal'), ('fastn9', 'fast'), ('fastn11', 'fast'), ('fastn9', 'bal'), ('fastn11', 'bal')]:
    print('\n%s against %s: nearer on %d, farther on %d of %d; error ratio median %.2f; time ratio median %.2f (%.2f to %.2f)'
          % ((a, b) + tally(a, b)), end='')
print()

# Three meshes per point on the re-meshed scenes (S*, C*): the nominal size and 1 % either side
# (bash draws.sh OUT NAME=SCENE ...): medians of the worst tumour and of the seconds.
REMESHED = [n for n in SCENES if n[0] in 'SC']
draws = {'fast until now (element 9 mm)': ['fast', 'draw_fast_8.91', 'draw_fast_9.09'],
         'fast now (nodal 11 mm)': ['fastn11', 'draw_fastn11_10.89', 'draw_fastn11_11.11']}
print('\n| scene (three meshes each) | ' + ' | '.join(draws) + ' |\n|---|' + '---|' * len(draws))
med = {}
for n in REMESHED:
    cells = []
    for label, tags in draws.items():
        vs = [v for v in (load(t, n) for t in tags) if v]
        e, s = [v[0] for v in vs], [v[1] for v in vs]
        med[(label, n)] = (st.median(e), st.median(s))
        cells.append('%.3f (%.3f to %.3f) mm, %.1f s%s' % (st.median(e), min(e), max(e), st.median(s),
                                                          '' if all(v[2] for v in vs) else ', some NOT converged'))
    print('| %s | %s |' % (n, ' | '.join(cells)))
a, b = list(draws)[1], list(draws)[0]
ps = [(med[(a, n)], med[(b, n)]) for n in REMESHED]
print('\n%s against %s, medians of three meshes: nearer on %d, farther on %d of %d; median time ratio %.2f' %
      (a, b, sum(x[0] < y[0] for x, y in ps), sum(x[0] > y[0] for x, y in ps), len(ps), st.median(x[1] / y[1] for x, y in ps)))
