"""The visible skin of a closed supine surface: its faces in the chest-wall plane removed.

The scenes our generators write (btr_phantom, bench/make_independent_truth.py) give the supine
surface as the whole closed boundary of the body, chest-wall face included, which no camera sees.
This writes the surface without the faces whose three vertices lie in the plane z = 0 (the chest
wall of those generators' frame), for measuring whether a registration leans on that face
(BENCHMARKS.md, "The quadratic unload in the balanced preset", "a closed supine surface shows the
chest wall").

Usage: /usr/bin/python3 bench/open_supine_skin.py supine.obj open.obj [--tolerance MM]
"""
import argparse


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('surface', help='closed supine surface (OBJ, triangles)')
    ap.add_argument('out', help='the surface without its faces in z = 0 (OBJ)')
    ap.add_argument('--tolerance', type=float, default=1e-6, help='|z| below which a vertex is on the chest wall')
    a = ap.parse_args()
    vertices, faces = [], []
    with open(a.surface) as f:
        for line in f:
            if line.startswith('v '):
                vertices.append([float(x) for x in line.split()[1:4]])
            elif line.startswith('f '):
                faces.append([int(x.split('/')[0]) - 1 for x in line.split()[1:]])
    kept = [t for t in faces if not all(abs(vertices[i][2]) < a.tolerance for i in t)]
    used = sorted({i for t in kept for i in t})
    index = {old: new for new, old in enumerate(used)}
    with open(a.out, 'w') as f:
        for i in used:
            f.write('v %.9g %.9g %.9g\n' % tuple(vertices[i]))
        for t in kept:
            f.write('f ' + ' '.join(str(index[i] + 1) for i in t) + '\n')
    print('%s: %d of %d faces kept (%d in z = 0 removed), %d vertices' % (a.out, len(kept), len(faces), len(faces) - len(kept), len(used)))


if __name__ == '__main__':
    main()
