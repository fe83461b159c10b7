# Tables of a preset study from its folder's reports/ (each call's report.json, renamed
# VARIANT_NAME.json): the worst tumour, the seconds (preparation with meshing plus
# registration) and whether it converged, per scene and variant, and medians over mesh draws.
# Imported by bench/results/*_preset_*/summarize.py.
import json, os, statistics as st

# The 15 scenes of the presets' studies since 2026-12-07 (bench/results/
# quadratic_unload_balanced_2026-12-07/README.md): seven the balanced preset's quadratic unload
# was chosen on, eight made after; S* and C* are surfaces each call re-meshes, P* fix their mesh.
SCENES = ['S1_1000', 'S1_3400', 'S2_500', 'S2_1000', 'S2_3400', 'P400', 'P1000', 'C2000_est', 'C700_est',
          'C2000_told', 'C700_told', 'P700_est', 'P2000_est', 'P700_rf', 'P2000_rf']
REMESHED = [n for n in SCENES if n[0] in 'SC']


class Reports:
    def __init__(self, folder):
        self.folder = folder

    def load(self, tag, name):
        """(worst tumour [mm], seconds, converged), or None where the run is missing."""
        f = '%s/reports/%s_%s.json' % (self.folder, tag, name)
        if not os.path.exists(f):
            return None
        r = json.load(open(f))
        return (max(t['centroid_distance_mm'] for t in r['tumours']),
                sum(r['seconds'].get(k, 0) for k in ('prepare', 'registration_total')), r['converged'])


def cell(v):
    return '-' if not v else '%.3f mm, %.1f s%s' % (v[0], v[1], '' if v[2] else ', NOT converged')


def draws_table(reports, scenes, draws):
    """Prints a table of the medians over each point's meshes (draws: label -> its tags) and
    returns {(label, scene): (median error, median seconds)}."""
    print('| scene (three meshes each) | ' + ' | '.join(draws) + ' |\n|---|' + '---|' * len(draws))
    med = {}
    for n in scenes:
        cells = []
        for label, tags in draws.items():
            vs = [v for v in (reports.load(t, n) for t in tags) if v]
            e, s = [v[0] for v in vs], [v[1] for v in vs]
            med[(label, n)] = (st.median(e), st.median(s))
            cells.append('%.3f (%.3f to %.3f) mm, %.1f s%s' % (st.median(e), min(e), max(e), st.median(s),
                                                              '' if all(v[2] for v in vs) else ', some NOT converged'))
        print('| %s | %s |' % (n, ' | '.join(cells)))
    return med


def median_tally(med, a, b, scenes):
    """'a against b, medians of three meshes: nearer on ..., farther on ... of ...; median time ratio ...'"""
    ps = [(med[(a, n)], med[(b, n)]) for n in scenes]
    return ('%s against %s, medians of three meshes: nearer on %d, farther on %d of %d; median time ratio %.2f' %
            (a, b, sum(x[0] < y[0] for x, y in ps), sum(x[0] > y[0] for x, y in ps), len(ps),
             st.median(x[1] / y[1] for x, y in ps)))
