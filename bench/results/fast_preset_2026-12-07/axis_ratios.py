# The worst tumour's axis ratio error, |registered / truth - 1|, per scene and preset, from the
# reports of this study and of the accurate preset's (python3 axis_ratios.py, in this folder);
# "prone shape" is the prone tumour's own axis ratio against the truth (doing nothing to it).
import json, os, sys
here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, '..', '..'))
from preset_tables import SCENES
SOURCES = [('fast until now', here, 'fast'), ('fast now', here, 'fastn11'), ('balanced', here, 'bal'),
           ('accurate', os.path.join(here, '..', 'accurate_preset_2026-12-07'), 'accnew')]
def worst(tumours, key):
    return max(abs(t[key] / t['truth_axis_ratio'] - 1) * 100 for t in tumours)
print('| scene | prone shape | ' + ' | '.join(s[0] for s in SOURCES) + ' |\n|---|' + '---|' * (len(SOURCES) + 1))
within = {s[0]: 0 for s in SOURCES}
prone_nearer = 0
for n in SCENES:
    cells = []
    for label, folder, tag in SOURCES:
        r = json.load(open('%s/reports/%s_%s.json' % (folder, tag, n)))
        e = worst(r['tumours'], 'axis_ratio')
        within[label] += e <= 5
        cells.append('%.1f %%' % e)
        if tag == 'bal':
            p = worst(r['tumours'], 'prone_axis_ratio')
            prone_nearer += p < e
    print('| %s | %.1f %% | %s |' % (n, p, ' | '.join(cells)))
print('\nwithin 5 %: ' + ', '.join('%s %d of %d' % (k, v, len(SCENES)) for k, v in within.items()) +
      '; the prone shape nearer than balanced on %d' % prone_nearer)
