#!/usr/bin/python3
"""Compare btr_experiments results.csv files of the same plan; a run's error is its worst tumour
centroid error [mm].

  compare_suites.py A.csv B.csv
      run by run: the error and seconds in A and in B, with the status where either did not converge
  compare_suites.py --changed A.csv B.csv [--by MM]
      only the runs whose error moved by more than MM (default 0.03) or whose convergence changed
  compare_suites.py --summary NAME=A.csv NAME=B.csv ...
      a line per file: runs not converged, median and mean error (also without the thesis's
      misalignment runs without the rigid step), runs better / worse by more than 0.1 mm than the
      first file, and the full method's error per generating E
  compare_suites.py --fallback A.csv B.csv
      what "B, else A where B did not converge" would give (e.g. the nodal volume term falling back
      to the element form): per generating E the runs not converged in A, B and the fallback, and
      the full method's error; the summed seconds (the fallback pays A only where B failed)
  compare_suites.py --fallback A.csv B.csv C.csv
      C is a suite run with the fallback built in (`--volume-form nodal`, `--nodal-fallback on`; A the
      element form, B the nodal form without the fallback, same plan): the same table from C's own
      rows, which runs fell back, and every row of C checked against the run of the form it took
      (B where it did not fall back, A where it did: the same worst error within 0.002 mm and the
      same convergence); exits 1 on a mismatch
"""
import collections, csv, statistics, sys


def load(p):
    d = collections.OrderedDict()
    for r in csv.DictReader(open(p)):
        k = (r['experiment'], r['setting'], r['variable'], r['value'], r['generating_youngs_modulus_Pa'])
        e = d.setdefault(k, [0, '', 0])
        e[0] = max(e[0], float(r['centroid_distance_mm'])); e[1] = r['status']; e[2] = float(r['seconds'])
    return d


def converged(status):
    return status.startswith('converged')


def run_by_run(a, b):
    for k in a:
        print(k, "%.3f %.1fs | %.3f %.1fs" % (a[k][0], a[k][2], b[k][0], b[k][2]))
        if a[k][1] != 'converged' or b[k][1] != 'converged':
            print("    A:", a[k][1][:110]); print("    B:", b[k][1][:110])


def changed(a, b, by):
    for k in a:
        (wa, sa, _), (wb, sb, _) = a[k], b[k]
        if abs(wa - wb) > by or converged(sa) != converged(sb):
            tag = lambda s: 'C' if converged(s) else 'NC'
            print(f"{k[4]:>5} {k[0]}/{k[1]} {k[2]}={k[3]}: {wa:.3f} -> {wb:.3f} mm, {tag(sa)} -> {tag(sb)}"
                  + ("" if converged(sb) else "   | " + sb[:150]))


def fallback(a, b):
    per = collections.defaultdict(collections.Counter)
    full, secs = {}, collections.Counter()
    for k in b:
        if k not in a:
            continue
        ok_a, ok_b = converged(a[k][1]), converged(b[k][1])
        pick = b[k] if ok_b else a[k]
        c = per[k[4]]
        c['runs'] += 1; c['a'] += not ok_a; c['b'] += not ok_b; c['fallback'] += not (ok_a or ok_b)
        secs['a'] += a[k][2]; secs['b'] += b[k][2]; secs['fallback'] += b[k][2] + (0 if ok_b else a[k][2])
        if k[0] == 'practical' and k[1] == 'full':
            full[k[4]] = (a[k][0], b[k][0], pick[0])
    print('| generating E [Pa] | not converged A / B / fallback | full method A / B / fallback [mm] |')
    print('|---|---|---|')
    for e in sorted(per, key=float):
        c, f = per[e], full.get(e, (float('nan'),) * 3)
        print(f"| {e} | {c['a']} / {c['b']} / {c['fallback']} of {c['runs']} | {f[0]:.2f} / {f[1]:.2f} / {f[2]:.2f} |")
    print(f"seconds, summed: A {secs['a']:.0f}, B {secs['b']:.0f}, fallback {secs['fallback']:.0f}")


def fallback_run(a, b, c):
    per = collections.defaultdict(collections.Counter)
    full, secs, mismatches = {}, collections.Counter(), []
    for k in c:
        fell = 'element form: the nodal did not converge' in c[k][1]
        ref = a[k] if fell else b[k]
        if abs(ref[0] - c[k][0]) > 2e-3 or converged(ref[1]) != converged(c[k][1]) or fell == converged(b[k][1]):
            mismatches.append(k)
        n = per[k[4]]
        n['runs'] += 1; n['a'] += not converged(a[k][1]); n['b'] += not converged(b[k][1])
        n['c'] += not converged(c[k][1]); n['fell'] += fell
        secs['a'] += a[k][2]; secs['b'] += b[k][2]; secs['c'] += c[k][2]
        if k[0] == 'practical' and k[1] == 'full':
            full[k[4]] = (a[k][0], b[k][0], c[k][0])
    print('| generating E [Pa] | not converged: element / nodal / with the fallback | fell back | full method: element / nodal / with the fallback [mm] |')
    print('|---|---|---|---|')
    for e in sorted(per, key=float):
        n, f = per[e], full.get(e, (float('nan'),) * 3)
        print(f"| {e} | {n['a']} / {n['b']} / {n['c']} of {n['runs']} | {n['fell']} | {f[0]:.3f} / {f[1]:.3f} / {f[2]:.3f} |")
    ws = {name: [d[k][0] for k in c] for name, d in (('element', a), ('nodal', b), ('fallback', c))}
    print('median / mean worst error [mm]: ' + ', '.join(f"{n} {statistics.median(v):.3f} / {statistics.mean(v):.3f}" for n, v in ws.items()))
    print(f"against the element form: {sum(1 for k in c if c[k][0] < a[k][0] - 0.1)} runs nearer by more than 0.1 mm, "
          f"{sum(1 for k in c if c[k][0] > a[k][0] + 0.1)} farther")
    print(f"seconds, summed: element {secs['a']:.0f}, nodal {secs['b']:.0f}, with the fallback {secs['c']:.0f}")
    print(f"{len(mismatches)} rows differ from the run of the form they took" + (': ' + str(mismatches[:5]) if mismatches else ''))
    return not mismatches


def summary(named):
    base = None
    for name, path in named:
        d = load(path)
        base = base or d
        nc = sum(1 for v in d.values() if not converged(v[1]))
        ws = [v[0] for v in d.values()]
        core = [v[0] for k, v in d.items() if k[1] != 'without_rigid']
        better = sum(1 for k in d if d[k][0] < base[k][0] - 0.1)
        worse = sum(1 for k in d if d[k][0] > base[k][0] + 0.1)
        full = [d[k][0] for k in d if k[0] == 'practical' and k[1] == 'full']
        print(f"| {name} | {nc} of {len(d)} | {statistics.median(ws):.3f} | {statistics.mean(ws):.3f} | "
              f"{statistics.mean(core):.3f} | {better} / {worse} | {' / '.join(f'{x:.3f}' for x in full)} |")


if __name__ == '__main__':
    args = sys.argv[1:]
    if args and args[0] == '--summary':
        print("| file | not converged | median [mm] | mean [mm] | mean without `without_rigid` [mm] | better / worse than the first | full method per E [mm] |")
        print("|---|---|---|---|---|---|---|")
        summary([a.split('=', 1) for a in args[1:]])
    elif args and args[0] == '--changed':
        by = float(args[args.index('--by') + 1]) if '--by' in args else 0.03
        changed(load(args[1]), load(args[2]), by)
    elif args and args[0] == '--fallback' and len(args) == 3:
        fallback(load(args[1]), load(args[2]))
    elif args and args[0] == '--fallback' and len(args) == 4:
        sys.exit(0 if fallback_run(load(args[1]), load(args[2]), load(args[3])) else 1)
    elif len(args) == 2:
        run_by_run(load(args[0]), load(args[1]))
    else:
        sys.exit(__doc__)
