# Tables of the accurate preset's study from reports/ (python3 summarize.py, in this folder):
#  1. every scene with balanced, accurate until now (nodal 5 mm, linear unload), the candidates
#     (accurate tolerances with the quadratic unload stated, --cell-size 9 and 7) and accurate now;
#  2. the re-meshed scenes over three meshes each (nominal size and 1 % either side): medians.
import os, statistics as st, sys
here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, '..', '..'))
from preset_tables import REMESHED, SCENES, Reports, cell, draws_table, median_tally
load = Reports(here).load
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
med = draws_table(Reports(here), REMESHED, draws)
for a, b in [('accurate now', 'accurate until now'), ('accurate now', 'balanced'), ('accurate until now', 'balanced')]:
    print('\n' + median_tally(med, a, b, REMESHED), end='')
print()
