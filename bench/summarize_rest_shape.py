#!/usr/bin/python3
"""The rest_shape experiment's CSVs (btr_experiments -e rest_shape) as one markdown table: per body,
rest shape and generating E the worst tumour centroid error [mm] ('*': a step not converged,
'failed': the run could not start), and for the estimated stiffness the estimate and the seconds.

Usage: /usr/bin/python3 bench/summarize_rest_shape.py NAME=results.csv [NAME=results.csv ...]"""
import collections
import csv
import math
import sys

SHAPES = [('prone', 'prone shape (thesis)'), ('rest', 'true rest shape'), ('unloaded', 'unloaded at 3400 Pa'),
          ('estimated', 'unloaded at estimated E')]


def main():
    bodies = [a.split('=', 1) for a in sys.argv[1:]]
    if not bodies:
        sys.exit(__doc__)
    moduli = None
    lines = []
    for name, path in bodies:
        rows = list(csv.DictReader(open(path)))
        es = sorted({float(r['generating_youngs_modulus_Pa']) for r in rows})
        if moduli is None:
            moduli = es
            lines.append('| body | rest shape | ' + ' | '.join('%g Pa' % e for e in es) + ' |')
            lines.append('|---|---|' + '---|' * len(es))
        worst, bad, failed = collections.defaultdict(float), set(), set()
        est, secs = collections.defaultdict(set), collections.defaultdict(float)
        for r in rows:
            if r['experiment'] != 'rest_shape':
                continue
            k = (r['value'], float(r['generating_youngs_modulus_Pa']))
            d = float(r['centroid_distance_mm'])
            if r['status'].startswith('failed'):
                failed.add(k)
                continue
            worst[k] = max(worst[k], d)
            secs[k] = max(secs[k], float(r['seconds']))
            if not r['status'].startswith('converged'):
                bad.add(k)
            e = float(r.get('estimated_youngs_modulus_Pa') or 0)
            if e > 0:
                est[k].add(round(e))
        for shape, label in SHAPES:
            cells = []
            for e in moduli:
                k = (shape, e)
                if k in failed:
                    cells.append('failed')
                elif k in worst:
                    c = '%.3f%s' % (worst[k], '*' if k in bad else '')
                    if shape == 'estimated':
                        c += ' (E %s, %.0f s)' % ('/'.join(str(x) for x in sorted(est[k])), secs[k])
                    cells.append(c)
                else:
                    cells.append('-')
            lines.append('| %s | %s | %s |' % (name, label, ' | '.join(cells)))
    print('\n'.join(lines))


if __name__ == '__main__':
    main()
