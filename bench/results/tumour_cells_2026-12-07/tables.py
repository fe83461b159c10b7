# Tables of this study (README.md here): python3 tables.py > tables.md
# reports/{before,after}_PRESET_NAME.json: btr_register's report.json without / with
# prone.tumour_cell_size_mm: 4 (bench/compare_builds.sh, AFTER_SETTING); draws/refine_NAME.txt:
# the probe's five meshes within 1 % of 9 mm, each without and with the tumour cells (balanced).
import json, os, re, statistics
here = os.path.dirname(os.path.abspath(__file__))
RESOLVED = ['BR_500', 'BR_1000', 'BR_3400', 'AR_1000', 'AR_3400']
UNRESOLVED = ['S1_1000', 'S1_3400', 'S2_500', 'S2_1000', 'S2_3400', 'P400', 'P1000', 'C2000', 'C700', 'C700_told',
              'P700_est', 'P700_rf', 'P2000_est', 'P2000_rf']
def load(side, preset, n):
    f = os.path.join(here, 'reports', '%s_%s_%s.json' % (side, preset, n))
    return json.load(open(f)) if os.path.exists(f) else None
def worst(r): return max(t['centroid_distance_mm'] for t in r['tumours'])
def axis(r, key='axis_ratio'): return max(abs(t[key] / t['truth_axis_ratio'] - 1) * 100 for t in r['tumours'])
def secs(r): return sum(r['seconds'].get(k, 0) for k in ('prepare', 'registration_total'))
def pair_table(names, presets):
    print('| scene | preset | worst tumour [mm]: now / 4 mm tumour cells | axis ratio off: now / tumour cells | prone shape\'s axis ratio off | tetrahedra | time ratio |')
    print('|---|---|---|---|---|---|---|')
    for n in names:
        for p in presets:
            b, a = load('before', p, n), load('after', p, n)
            if not b or not a: continue
            print('| %s | %s | %.3f / %.3f | %.1f / %.1f %% | %.1f %% | %d / %d | %.2f |' % (
                n, p, worst(b), worst(a), axis(b), axis(a), axis(b, 'prone_axis_ratio'), b['mesh']['tetrahedra'],
                a['mesh']['tetrahedra'], secs(a) / secs(b)))
print('## Truth that resolves its tumours (SfePy, --tumour-max-volume 40)\n')
pair_table(RESOLVED, ['balanced', 'fast', 'accurate'])
print('\n## Over five meshes within 1 % of 9 mm (balanced; medians)\n')
print('| scene | worst tumour [mm]: now / tumour cells | axis ratio off: now / tumour cells | seconds: now / tumour cells |')
print('|---|---|---|---|')
pat = re.compile(r'tumour cell ([\d.]+) mm:.*worst ([\d.]+) mm, axis ratio off by ([\d.]+) %, ([\d.]+) s')
for f in sorted(os.listdir(os.path.join(here, 'draws'))):
    rows = {'0.0': [], '4.0': []}
    for line in open(os.path.join(here, 'draws', f)):
        m = pat.search(line)
        if m: rows[m.group(1)].append(tuple(float(x) for x in m.groups()[1:]))
    med = {k: [statistics.median(c) for c in zip(*v)] for k, v in rows.items() if v}
    print('| %s | %.3f / %.3f | %.1f / %.1f %% | %.2f / %.2f |' % (f[7:-4], med['0.0'][0], med['4.0'][0], med['0.0'][1],
                                                               med['4.0'][1], med['0.0'][2], med['4.0'][2]))
print('\n## Truth whose tumours are a few straddled cells (the 14 scenes of the presets\' studies)\n')
pair_table(UNRESOLVED, ['balanced'])
