# Tables of the fast preset's study from reports/ (python3 summarize.py, in this folder):
#  1. every scene with fast as it was (element form, 9 mm, linear unload), the candidates (the
#     scene with material.volume_form: nodal stated, --preset fast at its 9 mm and at
#     --cell-size 11) and balanced, one run each, the four side by side (run.sh candidates);
#  2. the re-meshed scenes (S*, C*) over three meshes per point, the nominal size and 1 % either
#     side (run.sh draws): medians of the worst tumour and of the seconds.
import os, statistics as st, sys
here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, '..', '..'))
from preset_tables import REMESHED, SCENES, Reports, cell, draws_table, median_tally
load = Reports(here).load
COLS = [('fast', 'fast as it is'), ('fastn9', 'nodal, 9 mm'), ('fastn11', 'nodal, 11 mm'), ('bal', 'balanced')]
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
print('\n')
draws = {'fast until now (element 9 mm)': ['fast', 'draw_fast_8.91', 'draw_fast_9.09'],
         'fast now (nodal 11 mm)': ['fastn11', 'draw_fastn11_10.89', 'draw_fastn11_11.11']}
med = draws_table(Reports(here), REMESHED, draws)
print('\n' + median_tally(med, 'fast now (nodal 11 mm)', 'fast until now (element 9 mm)', REMESHED))
