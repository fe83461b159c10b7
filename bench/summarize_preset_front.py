#!/usr/bin/env python3
"""The presets' front with the volume form as a knob (bench/run_preset_front.sh): one markdown
table per body (time and worst tumour per setting), then each setting against each preset as it
stands, over every body: the median time ratio and the worst-tumour ratio per body.
Usage: summarize_preset_front.py DIR [--presets fast=element:9 balanced=element:7 accurate=element:4]"""
import argparse, csv, glob, os, statistics

ap = argparse.ArgumentParser()
ap.add_argument('dir')
ap.add_argument('--presets', nargs='*', default=['fast=element:9', 'balanced=element:7', 'accurate=element:4'],
                help='the presets as they stand: name=form:cell_mm')
a = ap.parse_args()

rows = {}  # body -> {(form, tolerances, cell): (seconds, worst, converged, form used)}
for f in sorted(glob.glob(os.path.join(a.dir, '*_element.csv')) + glob.glob(os.path.join(a.dir, '*_nodal.csv'))):
    body, form = os.path.basename(f)[:-4].rsplit('_', 1)
    for r in csv.DictReader(open(f)):
        if not r.get('converged'):
            continue  # a row still being written
        key = (form, r['base_preset'], float(r['cell_size_mm']))
        rows.setdefault(body, {})[key] = (float(r['seconds_median']), float(r['worst_error_mm']),
                                          r['converged'] == '1', r.get('volume_form', form))

bodies = sorted(rows)
settings = sorted({k for b in bodies for k in rows[b]}, key=lambda k: (k[1], k[0], -k[2]))
print('| setting | ' + ' | '.join(bodies) + ' |')
print('|---|' + '---|' * len(bodies))
for k in settings:
    cells = []
    for b in bodies:
        v = rows[b].get(k)
        if v is None:
            cells.append('-')
            continue
        flag = '' if v[2] else ' (not converged)'
        if v[3] == 'element_fallback':
            flag += ' (fell back)'
        cells.append('%.2f s, %.3f mm%s' % (v[0], v[1], flag))
    print('| %s, %s, %g mm | %s |' % (k[1], k[0], k[2], ' | '.join(cells)))

for spec in a.presets:
    name, rest = spec.split('=')
    form, cell = rest.split(':')
    ref = (form, name, float(cell))
    print('\n**Against %s as it stands (%s form, %s mm)**: median time ratio over the bodies; worst-tumour ratio per body\n' % (name, form, cell))
    print('| setting | time ratio (median) | ' + ' | '.join(bodies) + ' | better on |')
    print('|---|---|' + '---|' * len(bodies) + '---|')
    for k in settings:
        if not all(k in rows[b] and ref in rows[b] for b in bodies):
            continue
        t = statistics.median(rows[b][k][0] / rows[b][ref][0] for b in bodies)
        e = [rows[b][k][1] / rows[b][ref][1] for b in bodies]
        better = sum(1 for x in e if x < 1)
        print('| %s, %s, %g mm | %.2f | %s | %d of %d |' % (k[1], k[0], k[2], t, ' | '.join('%.2f' % x for x in e), better, len(bodies)))
