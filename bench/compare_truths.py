#!/usr/bin/python3
"""How far two truths of the same body disagree: bench/make_independent_truth.py run twice on one
body shape with another discretization (--order 3 against 2 on the same mesh, or --refine 2),
compared where both describe the same material points: each tumour's centroid (the tumours are
the same analytic spheres carried by each displacement field), prone and supine, and the five
supine landmarks (the same surface points at every --refine). The reference is the finer truth,
so the difference is the coarser truth's own discretization error, the floor under any figure
measured against it.

Usage: /usr/bin/python3 bench/compare_truths.py COARSE FINE --fat-youngs-modulus 500
       (COARSE, FINE: output folders of bench/make_independent_truth.py)"""
import argparse
import os
import sys

import numpy as np


def read_obj(path):
    V, F = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == 'v':
                V.append([float(x) for x in p[1:4]])
            elif p[0] == 'f':
                F.append([int(x.split('/')[0]) - 1 for x in p[1:4]])
    return np.array(V), np.array(F)


def volume_centroid(V, F):
    """The centroid of the solid a closed, consistently oriented triangle mesh bounds."""
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    vol = np.einsum('ij,ij->i', a, np.cross(b, c)) / 6.0
    return ((a + b + c) / 4.0 * vol[:, None]).sum(axis=0) / vol.sum()


def landmarks(path):
    rows = np.loadtxt(path, delimiter=',', ndmin=2)
    return rows[:, 1:4]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('coarse')
    ap.add_argument('fine')
    ap.add_argument('--fat-youngs-modulus', type=float, required=True)
    o = ap.parse_args()
    sub = 'E%g' % o.fat_youngs_modulus
    dc, df = os.path.join(o.coarse, sub), os.path.join(o.fine, sub)
    names = sorted(n[len('tumour_'):-len('_supine.obj')] for n in os.listdir(dc)
                   if n.startswith('tumour_') and n.endswith('_supine.obj'))
    if not names:
        sys.exit('no tumour_*_supine.obj in %s' % dc)
    print('fat E %g Pa: %s against %s' % (o.fat_youngs_modulus, o.coarse, o.fine))
    worst = {}
    for pose in ('prone', 'supine'):
        d = []
        for n in names:
            cc = volume_centroid(*read_obj(os.path.join(dc, 'tumour_%s_%s.obj' % (n, pose))))
            cf = volume_centroid(*read_obj(os.path.join(df, 'tumour_%s_%s.obj' % (n, pose))))
            r = volume_centroid(*read_obj(os.path.join(o.fine, 'tumour_%s_rest.obj' % n)))
            d.append(np.linalg.norm(cc - cf))
            print('  %-6s %-8s centroid differs by %.3f mm (moved %.2f mm from rest in the finer truth)' %
                  (pose, n, d[-1], np.linalg.norm(cf - r)))
        worst[pose] = max(d)
    lc, lf = landmarks(os.path.join(dc, 'landmarks.csv')), landmarks(os.path.join(df, 'landmarks.csv'))
    dl = np.linalg.norm(lc - lf, axis=1)
    print('  supine landmarks differ by %s mm' % ' '.join('%.3f' % x for x in dl))
    print('worst: prone tumour %.3f mm, supine tumour %.3f mm, supine landmark %.3f mm' %
          (worst['prone'], worst['supine'], dl.max()))


if __name__ == '__main__':
    main()
