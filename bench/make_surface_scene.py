#!/usr/bin/python3
"""Turns a btr_phantom scene folder into a scene whose prone model is a closed surface
(prone_surface.obj) instead of a tetrahedral mesh: the chest wall and the landmarks are
written as indices of the surface's vertices, so that btr_register tetrahedralizes it.

Usage: /usr/bin/python3 bench/make_surface_scene.py PHANTOM_DIR [--no-ring]
Writes PHANTOM_DIR/surface_scene.yaml, chest_wall_surface.txt, landmarks_surface.csv."""
import re
import sys


def read_vtk_points(path):
    with open(path) as f:
        tokens = f.read().split()
    i = tokens.index('POINTS')
    n = int(tokens[i + 1])
    vals = [float(t) for t in tokens[i + 3:i + 3 + 3 * n]]
    return [tuple(vals[3 * k:3 * k + 3]) for k in range(n)]


def main():
    d = sys.argv[1]
    no_ring = '--no-ring' in sys.argv
    surf = [tuple(float(t) for t in line.split()[1:4]) for line in open(d + '/prone_surface.obj') if line.startswith('v ')]
    index = {tuple(round(c, 6) for c in p): i for i, p in enumerate(surf)}
    tet = read_vtk_points(d + '/prone.vtk')
    wall_tet = [int(t) for t in open(d + '/chest_wall.txt').read().split()]
    wall = sorted(index[tuple(round(c, 6) for c in tet[v])] for v in wall_tet if tuple(round(c, 6) for c in tet[v]) in index)
    with open(d + '/chest_wall_surface.txt', 'w') as f:
        f.write('\n'.join(str(v) for v in wall) + '\n')
    rows = [line.strip().split(',') for line in open(d + '/landmarks.csv')][1:]
    with open(d + '/landmarks_surface.csv', 'w') as f:
        f.write('prone_index,x,y,z\n')
        for r in rows:
            s = index[tuple(round(c, 6) for c in tet[int(r[0])])]
            f.write('%d,%s,%s,%s\n' % (s, r[1], r[2], r[3]))
    scene = open(d + '/scene.yaml').read()
    scene = re.sub(r'(?m)^prone:\n(  .*\n)+', 'prone:\n  surface: prone_surface.obj\n', scene)
    scene = scene.replace('chest_wall: chest_wall.txt', 'chest_wall: chest_wall_surface.txt')
    scene = scene.replace('landmarks: landmarks.csv', 'landmarks: landmarks_surface.csv')
    if no_ring:
        scene = re.sub(r'(?m)^\s*chest_ring: chest_ring.obj\n', '', scene)
    open(d + '/surface_scene.yaml', 'w').write(scene)
    print('%s/surface_scene.yaml: %d surface vertices, %d chest-wall vertices, %d landmarks' % (d, len(surf), len(wall), len(rows)))


if __name__ == '__main__':
    main()
