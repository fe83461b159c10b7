# Tables and the adoption rule of this study (README.md here): python3 summary.py > summary.md
# draws.csv: one row per btr_register call (accurate preset, five cell sizes within 1 % of its
# 7 mm, 8 mm on P400), without (tumour_cells_mm 0) and with prone.tumour_cell_size_mm: 4.
import csv, os, statistics
here = os.path.dirname(os.path.abspath(__file__))
RESOLVED = ['BR_500', 'BR_1000', 'BR_3400', 'AR_500', 'AR_1000', 'AR_3400']
STRADDLED = ['S1_1000', 'S1_3400', 'S2_500', 'S2_1000', 'S2_3400', 'P400', 'C2000', 'C700', 'C700_told']
rows = list(csv.DictReader(open(os.path.join(here, 'draws.csv'))))
med = statistics.median
def col(n, cells, key): return [float(r[key]) for r in sorted(rows, key=lambda r: r['draw']) if r['scene'] == n and r['tumour_cells_mm'] == cells]
stats = {}
for title, names in (('Resolved truths', RESOLVED), ('Straddled truths', STRADDLED)):
    print('\n## %s\n' % title)
    print('| scene | worst tumour [mm], median of 5: now / 4 mm tumour cells | axis ratio off, median: now / tumour cells | prone shape\'s axis ratio off | not converged: now / cells | tetrahedra (median) | time ratio (median of pairs) |')
    print('|---|---|---|---|---|---|---|')
    for n in names:
        w0, w4 = col(n, '0', 'worst_tumour_mm'), col(n, '4', 'worst_tumour_mm')
        a0, a4 = col(n, '0', 'axis_ratio_off_pct'), col(n, '4', 'axis_ratio_off_pct')
        s0, s4 = col(n, '0', 'seconds'), col(n, '4', 'seconds')
        nc0, nc4 = (sum(1 - c for c in col(n, k, 'converged')) for k in ('0', '4'))
        stats[n] = (med(w0), med(w4), med(a0), med(a4))
        print('| %s | %.3f / %.3f | %.1f / %.1f %% | %.1f %% | %d / %d | %d / %d | %.2f |' % (
            n, med(w0), med(w4), med(a0), med(a4), col(n, '0', 'prone_axis_ratio_off_pct')[0], nc0, nc4,
            med(col(n, '0', 'tetrahedra')), med(col(n, '4', 'tetrahedra')), med(b / a for a, b in zip(s0, s4))))
# The rule, fixed before the run (run.sh):
ok1 = all(stats[n][3] < stats[n][2] and stats[n][1] - stats[n][0] <= 0.02 for n in RESOLVED)
ratios = [stats[n][1] / stats[n][0] for n in STRADDLED]
ok2 = med(ratios) <= 1.02 and all(stats[n][1] - stats[n][0] <= 0.1 for n in STRADDLED)
print('\nRule (1), resolved truths: axis ratio nearer on every scene, worst tumour not farther by > 0.02 mm: %s' % ok1)
print('Rule (2), straddled truths: median after/before ratio %.3f <= 1.02, none farther by > 0.1 mm (largest %+.3f): %s'
      % (med(ratios), max(stats[n][1] - stats[n][0] for n in STRADDLED), ok2))
