# Seconds of the paired calls in run1/ and run2/ (before: 14-point rule, after: 4-point rule):
# per scene the whole call (preparation with meshing + registration) and the unload step, and
# the medians of the after/before ratios over both runs.  Usage: python3 seconds.py (in this folder)
import glob, json, os, statistics as st
here = os.path.dirname(os.path.abspath(__file__))
names = sorted({os.path.basename(f)[len('before_'):-len('.json')] for f in glob.glob(here + '/run1/before_*.json')})
calls, unloads = [], []
print('| scene | call, 14 / 4 points [s] (run 1; run 2) | unload step, 14 / 4 points [s] (run 1; run 2) |')
print('|---|---|---|')
for n in names:
    cells_c, cells_u = [], []
    for run in ('run1', 'run2'):
        r = {s: json.load(open('%s/%s/%s_%s.json' % (here, run, s, n))) for s in ('before', 'after')}
        c = {s: sum(r[s]['seconds'].get(k, 0) for k in ('prepare', 'registration_total')) for s in r}
        u = {s: r[s]['seconds'].get('unload', 0) for s in r}
        calls.append(c['after'] / c['before'])
        unloads.append(u['after'] / u['before'])
        cells_c.append('%.2f / %.2f' % (c['before'], c['after']))
        cells_u.append('%.2f / %.2f' % (u['before'], u['after']))
    print('| %s | %s | %s |' % (n, '; '.join(cells_c), '; '.join(cells_u)))
print('\ncall: median ratio %.2f (%.2f to %.2f); unload step: median ratio %.2f (%.2f to %.2f)' %
      (st.median(calls), min(calls), max(calls), st.median(unloads), min(unloads), max(unloads)))
