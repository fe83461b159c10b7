# Is a registered tumour's shape error its interpolation? Each tumour carried instead by the
# affine map fitted (least squares) to its embedded vertices, prone -> registered, against the
# registration itself and the prone shape: the worst tumour's axis ratio error and centroid
# distance per scene. The registrations are btr_register's output folders REG/NAME.
#   /usr/bin/python3 bench/axis_ratio_affine_fit.py REG NAME=SCENE.yaml ...
import os, sys
import numpy as np, yaml


def read_obj(path):
    V, F = [], []
    for line in open(path):
        s = line.split()
        if s and s[0] == 'v':
            V.append([float(x) for x in s[1:4]])
        elif s and s[0] == 'f':
            F.append([int(x.split('/')[0]) - 1 for x in s[1:4]])
    return np.array(V), np.array(F)


def axis_ratio_and_centroid(V, F):
    """As principal_axis_ratio (metrics.h): the volume's second moments from signed tetrahedra."""
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    v = np.einsum('ij,ij->i', a, np.cross(b, c)) / 6
    S = a + b + c
    M = np.einsum('i,ijk->jk', v / 20, np.einsum('ij,ik->ijk', a, a) + np.einsum('ij,ik->ijk', b, b) +
                  np.einsum('ij,ik->ijk', c, c) + np.einsum('ij,ik->ijk', S, S))
    vol = v.sum()
    centre = (v[:, None] * S / 4).sum(0) / vol
    ev = np.linalg.eigvalsh(M / vol - np.outer(centre, centre))
    return np.sqrt(max(ev[0], 0) / ev[2]), centre


reg = sys.argv[1]
print('| scene | axis ratio: registered / affine / prone | centroid: registered / affine [scene units] |\n|---|---|---|')
for spec in sys.argv[2:]:
    name, scene = spec.split('=', 1)
    d, s = os.path.dirname(scene), yaml.safe_load(open(scene))
    rows = []
    for t in s['tumours']:
        P, F = read_obj(os.path.join(d, t['prone']))
        T, FT = read_obj(os.path.join(d, t['supine_ground_truth']))
        R, FR = read_obj(os.path.join(reg, name, 'tumour_%s_registered.obj' % t['name']))
        X = np.hstack([P, np.ones((len(P), 1))])
        A = X @ np.linalg.lstsq(X, R, rcond=None)[0]
        (rt, ct), (rr, cr), (ra, ca), (rp, _) = (axis_ratio_and_centroid(*m) for m in ((T, FT), (R, FR), (A, F), (P, F)))
        rows.append([abs(rr / rt - 1), abs(ra / rt - 1), abs(rp / rt - 1), np.linalg.norm(cr - ct), np.linalg.norm(ca - ct)])
    w = np.array(rows).max(0)
    print('| %s | %.1f / %.1f / %.1f %% | %.3f / %.3f |' % (name, 100 * w[0], 100 * w[1], 100 * w[2], w[3], w[4]))
