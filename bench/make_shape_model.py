#!/usr/bin/python3
"""A rest model of another body shape than the built-in phantom, meshed by TetGen (not CGAL),
for measuring the method on data it was not tuned on (issue 10).

The breast is a sheared, laterally asymmetric half ellipsoid: depth A along +z (chest wall in
z = 0), half widths B+ / B- along +x / -x and C along y, the apex sagging by S towards -y.
It has no chest ring (no rigid region), five landmarks (C at the apex, O1..O4 around it) and
five spherical tumours. Writes DIR/model.yaml (input of btr_experiments --model), rest.vtk,
chest_wall.txt, landmark_vertices.txt, tumour_*.obj.

Usage: /usr/bin/python3 bench/make_shape_model.py DIR [--depth 60] [--half-width 85 70]
       [--half-height 65] [--sag 15] [--max-volume 200]   (lengths in mm; needs Debian's tetgen)"""
import argparse
import math
import os
import subprocess

import numpy as np


def dome_point(theta, phi, a, bp, bm, c, s):
    u = math.sin(theta)
    z = a * math.cos(theta)
    b = bp if math.cos(phi) >= 0 else bm
    return (b * u * math.cos(phi), c * u * math.sin(phi) - s * z / a, z)


def surface(a, bp, bm, c, s, n_phi=40, n_theta=12, n_base=8):
    V, F = [], []
    V.append(dome_point(0.0, 0.0, a, bp, bm, c, s))  # apex
    rings = []
    for i in range(1, n_theta + 1):
        theta = (math.pi / 2) * i / n_theta
        rings.append([len(V) + j for j in range(n_phi)])
        V.extend(dome_point(theta, 2 * math.pi * j / n_phi, a, bp, bm, c, s) for j in range(n_phi))
    for j in range(n_phi):  # apex fan
        F.append((0, rings[0][j], rings[0][(j + 1) % n_phi]))
    for r0, r1 in zip(rings, rings[1:]):
        for j in range(n_phi):
            k = (j + 1) % n_phi
            F.append((r0[j], r1[j], r1[k]))
            F.append((r0[j], r1[k], r0[k]))
    base = [rings[-1]]  # the rim (z = 0) is the base's outer ring
    for i in range(n_base - 1, 0, -1):
        r = i / n_base
        base.append([len(V) + j for j in range(n_phi)])
        V.extend(((bp if math.cos(2 * math.pi * j / n_phi) >= 0 else bm) * r * math.cos(2 * math.pi * j / n_phi),
                  c * r * math.sin(2 * math.pi * j / n_phi), 0.0) for j in range(n_phi))
    centre = len(V)
    V.append((0.0, 0.0, 0.0))
    for r0, r1 in zip(base, base[1:]):
        for j in range(n_phi):
            k = (j + 1) % n_phi
            F.append((r0[j], r0[k], r1[k]))
            F.append((r0[j], r1[k], r1[j]))
    for j in range(n_phi):
        F.append((base[-1][j], base[-1][(j + 1) % n_phi], centre))
    V, F = np.array(V), np.array(F)
    vol = sum(np.dot(V[f[0]], np.cross(V[f[1]], V[f[2]])) for f in F) / 6
    if vol < 0:
        F = F[:, [0, 2, 1]]
    return V, F, rings


def icosphere(centre, radius, subdiv=2):
    t = (1 + 5 ** 0.5) / 2
    V = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    F = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7),
         (9, 8, 1)]
    V = [np.array(v, float) / np.linalg.norm(v) for v in V]
    for _ in range(subdiv):
        mid = {}
        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = V[a] + V[b]
                V.append(p / np.linalg.norm(p))
                mid[key] = len(V) - 1
            return mid[key]
        F = [f for (a, b, c) in F for f in ((a, m(a, b), m(c, a)), (b, m(b, c), m(a, b)), (c, m(c, a), m(b, c)),
                                             (m(a, b), m(b, c), m(c, a)))]
    return np.array(centre) + radius * np.array(V), np.array(F)


def write_obj(path, V, F):
    with open(path, 'w') as f:
        f.writelines('v %.9g %.9g %.9g\n' % tuple(v) for v in V)
        f.writelines('f %d %d %d\n' % tuple(t + 1) for t in F)


def write_vtk(path, V, T, labels=None):
    """Legacy ASCII VTK unstructured grid of linear tetrahedra [mm], with cell labels."""
    with open(path, 'w') as f:
        f.write('# vtk DataFile Version 3.0\nTetGen tetrahedra [mm] (bench/)\nASCII\nDATASET UNSTRUCTURED_GRID\n')
        f.write('POINTS %d double\n' % len(V))
        f.writelines('%.12g %.12g %.12g\n' % tuple(v) for v in V)
        f.write('CELLS %d %d\n' % (len(T), 5 * len(T)))
        f.writelines('4 %d %d %d %d\n' % tuple(t) for t in T)
        f.write('CELL_TYPES %d\n' % len(T))
        f.writelines('10\n' for _ in T)
        if labels is not None:
            f.write('CELL_DATA %d\nSCALARS label int 1\nLOOKUP_TABLE default\n' % len(T))
            f.writelines('%d\n' % k for k in labels)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('dir')
    ap.add_argument('--depth', type=float, default=60)
    ap.add_argument('--half-width', type=float, nargs=2, default=[85, 70])
    ap.add_argument('--half-height', type=float, default=65)
    ap.add_argument('--sag', type=float, default=15)
    ap.add_argument("--max-volume", type=float, default=200, help='TetGen -a bound [mm^3]')
    o = ap.parse_args()
    os.makedirs(o.dir, exist_ok=True)
    a, (bp, bm), c, s = o.depth, o.half_width, o.half_height, o.sag
    V, F, rings = surface(a, bp, bm, c, s)
    with open(os.path.join(o.dir, 'surface.off'), 'w') as f:
        f.write('OFF\n%d %d 0\n' % (len(V), len(F)))
        f.writelines('%.9g %.9g %.9g\n' % tuple(v) for v in V)
        f.writelines('3 %d %d %d\n' % tuple(t) for t in F)
    subprocess.run(['tetgen', '-pq1.4a%g' % o.max_volume, '-zQ', os.path.join(o.dir, 'surface.off')], check=True)
    node = np.loadtxt(os.path.join(o.dir, 'surface.1.node'), comments='#', skiprows=1)[:, 1:4]
    ele = np.loadtxt(os.path.join(o.dir, 'surface.1.ele'), comments='#', skiprows=1, dtype=int)[:, 1:5]
    write_vtk(os.path.join(o.dir, 'rest.vtk'), node, ele)
    wall = np.nonzero(np.abs(node[:, 2]) < 1e-9)[0]
    np.savetxt(os.path.join(o.dir, 'chest_wall.txt'), wall, fmt='%d')
    # Landmarks: input surface vertices (TetGen keeps them first): the apex and four around it.
    ring = rings[len(rings) * 5 // 9]
    n_phi = len(ring)
    landmarks = {'C': 0, 'O1': ring[0], 'O2': ring[n_phi // 4], 'O3': ring[n_phi // 2], 'O4': ring[3 * n_phi // 4]}
    with open(os.path.join(o.dir, 'landmark_vertices.txt'), 'w') as f:
        f.writelines('%s %d\n' % kv for kv in landmarks.items())
    tumours = {'central': (0, -0.15 * c, 0.45 * a), 'lateral': (0.45 * bp, 0, 0.3 * a), 'upper': (0, 0.5 * c, 0.25 * a),
               'lower': (0, -0.55 * c, 0.2 * a), 'medial': (-0.5 * bm, 0.05 * c, 0.25 * a)}
    lines = ['# Rest model of another shape (bench/make_shape_model.py; meshed by TetGen)', 'units: mm',
             'rest: rest.vtk', 'chest_wall: chest_wall.txt', 'landmarks: landmark_vertices.txt',
             'gravity: {prone: [0, 0, 9.81], supine: [0, 0, -9.81]}', 'tumours:']
    for name, p in tumours.items():
        TV, TF = icosphere(p, 8.0)
        write_obj(os.path.join(o.dir, 'tumour_%s.obj' % name), TV, TF)
        lines.append('  %s: tumour_%s.obj' % (name, name))
    open(os.path.join(o.dir, 'model.yaml'), 'w').write('\n'.join(lines) + '\n')
    print('%s: %d surface vertices, %d tet vertices, %d tetrahedra, %d chest-wall vertices' %
          (os.path.join(o.dir, 'model.yaml'), len(V), len(node), len(ele), len(wall)))


if __name__ == '__main__':
    main()
