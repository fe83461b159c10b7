# Tables of the accurate preset's study from reports/ (python3 summarize.py, in this folder):
#  1. every scene with balanced, accurate until now (nodal 5 mm, linear unload), the candidates
#     (accurate tolerances with the quadratic unload stated, --cell-size 9 and 7) and accurate now;
#  2. the re-meshed scenes over three meshes each (nominal size and 1 % either side): medians.
import json, os, statistics as st
here = os.path.dirname(os.path.abspath(__file__))
SCENES = ['S1_1000', 'S1_3400', 'S2_500', 'S2_1000', 'S2_3400', 'P400', 'P1000', 'C2000_est', 'C700_est',
          'C2000_told', 'C700_told', 'P700_est', 'P2000_est', 'P700_rf', 'P2000_rf']
REMESHED = [n for n in SCENES if n[0] in 'SC']
def load(tag, n):
    f = '%s/reports/%s_%s.json' % (here, tag, n)
    if not os.path.exists(f): return None
    r = json.load(open(f))
    return (max(t['centroid_distance_mm'] for t in r['tumours']),
            sum(r['seconds'].get(k, 0) for k in ('prepare', 'registration_total')), r['converged'])
def cell(v): return '-' if not v else '%.3f mm, %.1f s%s' % (v[0], v[1], '' if v[2] else ', NOT converged')
cols = [('bal', 'balanced'), ('acc5', 'accurate until now'), ('acc9q', 'candidate 9 mm'), ('acc7q', 'candidate 7 mm'), ('accnew', 'accurate now')]
print('| scene | ' + ' | '.join(c[1] for c in cols) + ' |\n|---|' + '---|' * len(cols))
for n in SCENES: print('| %s | %s |' % (n, ' | '.join(cell(load(t, n)) for t, _ in cols)))
def tally(a, b, names):
    ps = [(load(a, n), load(b, n)) for n in names]
    ps = [(x, y) for x, y in ps if x and y]
    return (sum(x[0] < y[0] for x, y in ps), sum(x[0] > y[0] for x, y in ps), len(ps), st.median(x[1] / y[1] for x, y in ps))
for a, b in [('accnew', 'acc5'), ('accnew', 'bal'), ('acc5', 'bal')]:
    print('\n%s against %s, one mesh each: nearer on %d, farther on %d of %d; median time ratio %.2f' % ((a, b) + tally(a, b, SCENES)), end='')
print('\n')
draws = {'balanced': ['bal', 'draw_bal_8.91', 'draw_bal_9.09'], 'accurate now': ['accnew', 'draw_acc_6.93', 'draw_acc_7.07'],
         'accurate until now': ['acc5', 'draw_acc5_4.95', 'draw_acc5_5.05']}
print('| scene (three meshes each) | ' + ' | '.join(draws) + ' |\n|---|' + '---|' * len(draws))
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
for a, b in [('accurate now', 'accurate until now'), ('accurate now', 'balanced'), ('accurate until now', 'balanced')]:
    ps = [(med[(a, n)], med[(b, n)]) for n in REMESHED]
    print('\n%s against %s, medians of three meshes: nearer on %d, farther on %d of %d; median time ratio %.2f' %
          (a, b, sum(x[0] < y[0] for x, y in ps), sum(x[0] > y[0] for x, y in ps), len(ps), st.median(x[1] / y[1] for x, y in ps)), end='')
print()
