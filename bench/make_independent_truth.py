#!/usr/bin/python3
"""Prone and supine truth made by a finite-element code we did not write (SfePy), for measuring
the method on data its own solver did not generate (issue 13).

The body is bench/make_shape_model.py's sheared, asymmetric half ellipsoid (no chest ring),
meshed by TetGen and solved with quadratic tetrahedra (P2) in SfePy's total Lagrangian
formulation: the decoupled neo-Hookean term (mu J^-2/3 (I1 - 3)) plus a bulk penalty
K/2 (J - 1)^2, another hyperelastic law than the package's stable neo-Hookean with the same
small-strain limit. The tissue is heterogeneous: fat, a fibroglandular core (an ellipsoid,
2x the fat's E) and five spherical tumours (6x). Gravity is ramped up (adaptive load steps,
Newton without line search) from the rest shape to the prone (+z) and the supine (-z)
equilibrium with the chest wall (z = 0) fixed.

Is that truth converged? --order 3 solves the same mesh with cubic tetrahedra (P3), --refine K
meshes a K times finer skin surface (the same landmarks); bench/compare_truths.py measures how
far two truths of one body disagree (BENCHMARKS.md, "Is the independent truth converged?").

For every fat modulus it writes OUT/E<fat E>/ with what a user of the package would have:
the prone skin surface (prone.obj: the method meshes it itself, with CGAL), the chest-wall
and landmark indices of that surface, the supine landmark positions, the supine skin surface,
the prone tumours and their supine ground truth (tumour points carried by the P2 displacement
field), and three scenes:
  scene_prone.yaml      the thesis's method: the prone shape as rest shape, E = 3400 Pa assumed
  scene_unloaded.yaml   prone_gravity given: unloaded at the assumed 3400 Pa
  scene_estimated.yaml  prone_gravity and youngs_modulus: estimate
and, with the tissue layout given as regions (the prone gland surface gland_prone.obj, 2x, and
the prone tumour surfaces, 6x: the ratios, not the moduli), the method told the heterogeneity:
  scene_unloaded_regions.yaml, scene_estimated_regions.yaml, and the last with the nodal volume
  term (scene_estimated_regions_nodal.yaml)
and truth.json (moduli, sags, load steps, seconds).

For the experiment suite (btr_experiments --model OUT/model.yaml --truth OUT/truth.yaml) it also
writes the rest model once (OUT/model.yaml: the TetGen mesh with its tissue labels, chest wall,
landmark vertices, rest tumours, both gravities; OUT/model_regions.yaml also gives the method
the tissue layout, the labels at the truth's ratios) and, per fat modulus, the prone and supine
volumes (prone_volume.vtk, supine_volume.vtk: the rest mesh's vertices moved by the P2 solution,
the same tetrahedra); OUT/truth.yaml lists every configuration written so far.

A second body shape (a figure that holds on one body may not hold on another): the same
generator with other dimensions and tissue ratios, e.g. the deeper, narrower breast of
BENCHMARKS.md ("The nodal volume term as the default"):
  --depth 75 --half-width 65 60 --half-height 60 --sag -10 --gland-ratio 3 --tumour-ratio 8

Tumours the truth resolves: by default a tumour's stiff tissue is the few tetrahedra whose
centroid lies within 8 mm of its centre (5 to 12 cells of the 5000 mm^3 meshes), which the
7.2 mm sphere the method tracks straddles; --tumour-max-volume V meshes those spheres as internal
surfaces with tetrahedra of at most V mm^3 inside (about 500 per tumour at V = 40), so that the
stiff tissue is the tracked tumour and its shape is resolved (BENCHMARKS.md, "Tumours the truth
resolves").

Usage: /usr/bin/python3 bench/make_independent_truth.py OUT [--fat-youngs-moduli 300 1000 3400]
       [--max-volume 1500] [--tumour-max-volume 0] [--order 2|3] [--refine 1] [--poisson-ratio 0.49]
       [--linear-solver auto|mumps|scipy]
       [--depth 60] [--half-width 85 70] [--half-height 65] [--sag 15] (lengths in mm, as
       bench/make_shape_model.py) [--gland-ratio 2] [--tumour-ratio 6]
       (needs Debian's python3-sfepy and tetgen; python3-petsc4py for MUMPS)"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

# Debian's python3-petsc4py lives under PETSC_DIR, which only petsc-dev's alternative links to.
for _d in ('/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real', '/usr/lib/petsc'):
    _p = os.path.join(os.environ.get('PETSC_DIR', _d), 'lib/python3/dist-packages')
    if os.path.isdir(_p) and _p not in sys.path:
        sys.path.append(_p)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_shape_model import icosphere, surface, write_obj, write_vtk  # noqa: E402

G = 9.81
RHO = 1000.0


def mesh_body(out, max_volume, a=60.0, bp=85.0, bm=70.0, c=65.0, s=15.0, refine=1, tumour_surfaces=None,
              tumour_max_volume=0.0):
    """TetGen mesh of the body [mm]. With tumour_surfaces ({name: (V, F)} closed surfaces inside
    the body) and tumour_max_volume > 0 the surfaces are meshed as internal boundaries (a
    tetrahedron is inside one or not, none straddles) with that volume bound inside them; the
    last return value then marks each tetrahedron inside a tumour (else None)."""
    # refine K: K times the rings and points per ring, the same landmarks (one ring of K stays).
    V, F, rings = surface(a, bp, bm, c, s, n_phi=40 * refine, n_theta=12 * refine, n_base=8 * refine)
    tumours = {'central': (0, -0.15 * c, 0.45 * a), 'lateral': (0.45 * bp, 0, 0.3 * a), 'upper': (0, 0.5 * c, 0.25 * a),
               'lower': (0, -0.55 * c, 0.2 * a), 'medial': (-0.5 * bm, 0.05 * c, 0.25 * a)}
    resolved = tumour_max_volume > 0
    if resolved:
        # A piecewise linear complex: the skin and every tumour surface as facets, each tumour a
        # region (attribute 3) with its own volume bound (TetGen -A, and -a twice: regional, global).
        smesh = os.path.join(out, 'body.smesh')
        pts, facets = [np.asarray(V, float)], [np.asarray(F)]
        offset = len(V)
        for TV, TF in tumour_surfaces(tumours).values():
            pts.append(np.asarray(TV, float))
            facets.append(np.asarray(TF) + offset)
            offset += len(TV)
        P, T = np.concatenate(pts), np.concatenate(facets)
        with open(smesh, 'w') as f:
            f.write('%d 3 0 0\n' % len(P))
            f.writelines('%d %.9g %.9g %.9g\n' % (i, *p) for i, p in enumerate(P))
            f.write('%d 0\n' % len(T))
            f.writelines('3 %d %d %d\n' % tuple(t) for t in T)
            f.write('0\n%d\n' % len(tumours))
            f.writelines('%d %.9g %.9g %.9g 3 %g\n' % (i, *p, tumour_max_volume) for i, p in enumerate(tumours.values()))
        subprocess.run(['tetgen', '-pq1.4Aaa%g' % max_volume, '-zQ', smesh], check=True)
    else:
        off = os.path.join(out, 'body.off')
        with open(off, 'w') as f:
            f.write('OFF\n%d %d 0\n' % (len(V), len(F)))
            f.writelines('%.9g %.9g %.9g\n' % tuple(v) for v in V)
            f.writelines('3 %d %d %d\n' % tuple(t) for t in F)
        subprocess.run(['tetgen', '-pq1.4a%g' % max_volume, '-zQ', off], check=True)
    node = np.loadtxt(os.path.join(out, 'body.1.node'), comments='#', skiprows=1)[:, 1:4]
    ele_rows = np.loadtxt(os.path.join(out, 'body.1.ele'), comments='#', skiprows=1)
    ele = ele_rows[:, 1:5].astype(int)
    in_tumour = np.rint(ele_rows[:, 5]).astype(int) == 3 if resolved else None
    d = np.einsum('ij,ij->i', np.cross(node[ele[:, 1]] - node[ele[:, 0]], node[ele[:, 2]] - node[ele[:, 0]]),
                  node[ele[:, 3]] - node[ele[:, 0]])
    ele[d < 0] = ele[d < 0][:, [0, 2, 1, 3]]
    ring = rings[(len(rings) // refine * 5 // 9 + 1) * refine - 1]  # 52.5 deg from the apex
    n_phi = len(ring)
    landmarks = {'C': 0, 'O1': ring[0], 'O2': ring[n_phi // 4], 'O3': ring[n_phi // 2], 'O4': ring[3 * n_phi // 4]}
    gland = {'centre': np.array([0.0, -0.1 * c, 0.3 * a]), 'axes': np.array([0.55 * bp, 0.55 * c, 0.4 * a])}
    return node, ele, landmarks, tumours, gland, (a, bp, bm, c, s), in_tumour


def labels(node, ele, tumours, gland, radius, in_tumour=None):
    """1 fat, 2 gland (centroid in the ellipsoid), 3 tumour: the tetrahedra inside the tumour
    surfaces where the mesh follows them (in_tumour), else those whose centroid lies within
    `radius` of a tumour's centre."""
    cen = node[ele].mean(axis=1)
    lab = np.ones(len(ele), dtype=np.int32)  # 1 fat
    lab[(((cen - gland['centre']) / gland['axes']) ** 2).sum(axis=1) < 1] = 2  # 2 gland
    if in_tumour is not None:
        lab[in_tumour] = 3
        return lab
    for p in tumours.values():
        lab[np.linalg.norm(cen - np.array(p), axis=1) < radius] = 3  # 3 tumour
    return lab


def boundary(ele):
    faces = np.concatenate([ele[:, [1, 2, 3]], ele[:, [0, 3, 2]], ele[:, [0, 1, 3]], ele[:, [0, 2, 1]]])
    key = np.sort(faces, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return faces[cnt[inv.ravel()] == 1]


def linear_solver_of(name):
    """SfePy's direct solver for the Newton steps: MUMPS through petsc4py when it is there (about
    10x faster than SuperLU per solve on the 7k-tet P2 body, the same truth to 9 digits), else
    SciPy's SuperLU."""
    from sfepy.solvers.ls import ScipyDirect
    if name in ('auto', 'mumps'):
        try:
            from petsc4py import PETSc
        except ImportError:
            if name == 'mumps':
                raise
            return ScipyDirect({})

        class MumpsDirect(ScipyDirect):
            """A fresh MUMPS LU of every Newton tangent (PETSc KSP preonly + PC lu). One KSP for
            all solves: a KSP destroyed per solve leaked its factor (300 MB a solve here)."""
            name = 'ls.btr_mumps'
            ksp = None

            def __call__(self, rhs, x0=None, conf=None, eps_a=None, eps_r=None, i_max=None, mtx=None, status=None,
                         **kwargs):
                import scipy.sparse as sps
                a = sps.csr_matrix(mtx)
                m = PETSc.Mat().createAIJ(a.shape, csr=(a.indptr.astype(PETSc.IntType), a.indices.astype(PETSc.IntType),
                                                        a.data))
                if self.ksp is None:
                    self.ksp = PETSc.KSP().create()
                    self.ksp.setType('preonly')
                    pc = self.ksp.getPC()
                    pc.setType('lu')
                    pc.setFactorSolverType('mumps')
                self.ksp.setOperators(m)
                b, x = m.createVecLeft(), m.createVecRight()
                b.setArray(np.asarray(rhs, float))
                self.ksp.solve(b, x)
                out = x.getArray().copy()
                if status is not None:
                    status['n_iter'] = 1
                m.destroy(), b.destroy(), x.destroy()
                return out

        return MumpsDirect({})
    return ScipyDirect({})


def write_rest_model(out, node, ele, lab, chest_vertices, landmarks, tum_surf, gland_ratio, tumour_ratio):
    """OUT/model.yaml for btr_experiments --model: the rest shape the configurations came from;
    OUT/model_regions.yaml the same with the tissue layout (cell labels 2 gland, 3 tumour) given to
    the method's model at the truth's stiffness ratios."""
    write_vtk(os.path.join(out, 'rest.vtk'), node, ele, lab)
    np.savetxt(os.path.join(out, 'chest_wall_rest.txt'), chest_vertices, fmt='%d')
    with open(os.path.join(out, 'landmark_vertices.txt'), 'w') as f:
        f.writelines('%s %d\n' % (name, v) for name, v in landmarks.items())
    for n, (TV, TF) in tum_surf.items():
        write_obj(os.path.join(out, 'tumour_%s_rest.obj' % n), TV, TF)
    with open(os.path.join(out, 'model.yaml'), 'w') as f:
        f.write('# Rest model of the independent truth (bench/make_independent_truth.py): btr_experiments --model\n')
        f.write('units: mm\nrest: rest.vtk\nchest_wall: chest_wall_rest.txt\nlandmarks: landmark_vertices.txt\n')
        f.write('tumours:\n' + ''.join('  %s: tumour_%s_rest.obj\n' % (n, n) for n in sorted(tum_surf)))
        f.write('gravity:\n  prone: [0, 0, %g]\n  supine: [0, 0, %g]\n' % (G, -G))
    with open(os.path.join(out, 'model.yaml')) as f:
        plain = f.read()
    with open(os.path.join(out, 'model_regions.yaml'), 'w') as f:
        f.write(plain + 'regions:\n  - {name: gland, label: 2, relative_stiffness: %g}\n'
                '  - {name: tumour, label: 3, relative_stiffness: %g}\n' % (gland_ratio, tumour_ratio))


def write_truth_list(out, names):
    """OUT/truth.yaml: every configuration written so far, for btr_experiments --truth."""
    done = sorted((json.load(open(os.path.join(out, d, 'truth.json')))['fat_youngs_modulus_Pa'], d)
                  for d in os.listdir(out) if os.path.isfile(os.path.join(out, d, 'prone_volume.vtk'))
                  and os.path.isfile(os.path.join(out, d, 'truth.json')))
    with open(os.path.join(out, 'truth.yaml'), 'w') as f:
        f.write('# Prone and supine truth made by SfePy (bench/make_independent_truth.py): btr_experiments --truth\n')
        f.write('units: mm\nconfigurations:\n')
        for e, d in done:
            f.write('  - youngs_modulus: %g\n    prone: %s/prone_volume.vtk\n    supine: %s/supine_volume.vtk\n' % (e, d, d))
            f.write('    tumours:\n')
            f.writelines('      %s: {prone: %s/tumour_%s_prone.obj, supine: %s/tumour_%s_supine.obj}\n' % (n, d, n, d, n)
                         for n in sorted(names))


class Body:
    """The SfePy problem on the rest mesh [m]: P2 displacement, per-region materials."""

    def __init__(self, node_m, ele, lab, moduli, nu, linear_solver='auto', order=2):
        from sfepy.base.base import IndexedStruct, output
        from sfepy.discrete import Equation, Equations, FieldVariable, Function, Integral, Material, Problem
        from sfepy.discrete.conditions import Conditions, EssentialBC
        from sfepy.discrete.fem import FEDomain, Field, Mesh
        from sfepy.solvers.nls import Newton
        from sfepy.terms import Term
        output.set_output(quiet=True)
        mesh = Mesh.from_data('body', node_m, None, [ele.astype(np.int32)], [lab.astype(np.int32)], ['3_4'])
        domain = FEDomain('domain', mesh)
        omega = domain.create_region('Omega', 'all')
        chest = domain.create_region('Chest', 'vertices in (z < 1e-9)', 'facet')
        field = Field.from_args('displacement', np.float64, 'vector', omega, approx_order=order)
        self.u = FieldVariable('u', 'unknown', field)
        v = FieldVariable('v', 'test', field, primary_var_name='u')
        integral = Integral('i', order=2 * order)
        self.g = np.zeros(3)

        def force(ts, coors, mode=None, **kwargs):
            if mode != 'qp':
                return None
            val = np.tile((RHO * self.g).reshape(1, 3, 1), (coors.shape[0], 1, 1))
            return {'val': val}

        f = Material('f', function=Function('force', force))
        # Per-cell moduli as quadrature-point values (cell-major order, the region is every cell).
        # (Terms on one region per material would be simpler; SfePy 2021.4 crashes on them.)
        e_cell = np.array([moduli[int(k)] for k in lab], float)
        mu_cell, k_cell = e_cell / (2 * (1 + nu)), e_cell / (3 * (1 - 2 * nu))

        def material(ts, coors, mode=None, **kwargs):
            if mode != 'qp':
                return None
            n_qp = coors.shape[0] // len(e_cell)
            return {'mu': np.repeat(mu_cell, n_qp).reshape(-1, 1, 1), 'K': np.repeat(k_cell, n_qp).reshape(-1, 1, 1)}

        m = Material('m', function=Function('material', material))
        terms = (Term.new('dw_tl_he_neohook(m.mu, v, u)', integral, omega, m=m, v=v, u=self.u) +
                 Term.new('dw_tl_bulk_penalty(m.K, v, u)', integral, omega, m=m, v=v, u=self.u) -
                 Term.new('dw_volume_lvf(f.val, v)', integral, omega, f=f, v=v))
        self.pb = Problem('body', equations=Equations([Equation('balance', terms)]))
        self.pb.set_bcs(ebcs=Conditions([EssentialBC('chest', chest, {'u.all': 0.0})]))
        self.status = IndexedStruct()
        # No line search: the residual norm is not a merit function here (a full Newton step
        # may raise it before the quadratic convergence sets in).
        nls = Newton({'i_max': 25, 'eps_a': 1e-9, 'eps_r': 1e-9, 'ls_on': 1e10}, lin_solver=linear_solver_of(linear_solver),
                     status=self.status)
        self.pb.set_solver(nls)
        self.n_vertices = len(node_m)

    def solve(self, gravity, first_step=0.25):
        """Equilibrium under `gravity` [m/s^2] by adaptive load steps; returns (solves, steps)."""
        s, ds, prev, solves, steps = 0.0, first_step, None, 0, 0
        while s < 1 - 1e-12:
            nxt = min(1.0, s + ds)
            self.g = nxt * np.asarray(gravity, float)
            st = self.pb.solve(state0=prev, save_results=False)
            solves += 1
            if self.status.condition == 0:
                s, prev, steps = nxt, st.copy(deep=True), steps + 1
                ds = min(1.0 - s if s < 1 else 1.0, ds * 1.5) or ds
            else:
                ds /= 2
                if ds < 1.0 / 256:
                    raise RuntimeError('the load ramp failed at %.1f %% of gravity' % (100 * nxt))
        self.pb.solve(state0=prev, save_results=False)  # sets u to the converged state
        return solves, steps

    def displacement_at_vertices(self):
        return self.u().reshape(-1, 3)[:self.n_vertices].copy()

    def displacement_at(self, points_m):
        return np.asarray(self.u.evaluate_at(points_m)).reshape(-1, 3)


def write_scenes(d, fat_e, gland_ratio, tumour_ratio):
    common = ['units: mm', 'prone: {surface: prone.obj}', 'chest_wall: chest_wall.txt', 'landmarks: landmarks.csv',
              'supine: {surface: supine.obj}', 'tumours:']
    names = sorted(n[len('tumour_'):-len('_prone.obj')] for n in os.listdir(d)
                   if n.startswith('tumour_') and n.endswith('_prone.obj'))
    common += ['  - {name: %s, prone: tumour_%s_prone.obj, supine_ground_truth: tumour_%s_supine.obj}' % (n, n, n)
               for n in names]
    common += ['gravity: [0, 0, -9.81]', 'preset: balanced']
    variants = {
        'prone': ['material: {youngs_modulus: 3400, poisson_ratio: 0.49, density: 1000}'],
        'unloaded': ['material: {youngs_modulus: 3400, poisson_ratio: 0.49, density: 1000}', 'prone_gravity: [0, 0, 9.81]'],
        'estimated': ['material: {youngs_modulus: estimate, poisson_ratio: 0.49, density: 1000}',
                      'prone_gravity: [0, 0, 9.81]'],
    }
    regions = ['regions:', '  - {name: gland, surface: gland_prone.obj, relative_stiffness: %g}' % gland_ratio]
    regions += ['  - {name: tumour_%s, surface: tumour_%s_prone.obj, relative_stiffness: %g}' % (n, n, tumour_ratio)
                for n in names]
    variants['unloaded_regions'] = variants['unloaded'] + regions
    variants['estimated_regions'] = variants['estimated'] + regions
    # The volume term on nodal averages: linear tetrahedra lock at nu = 0.49 (the truth's P2 do not).
    variants['estimated_regions_nodal'] = [
        'material: {youngs_modulus: estimate, poisson_ratio: 0.49, density: 1000, volume_form: nodal}',
        'prone_gravity: [0, 0, 9.81]'] + regions
    for name, extra in variants.items():
        with open(os.path.join(d, 'scene_%s.yaml' % name), 'w') as f:
            f.write('# Independent truth (SfePy, P2, heterogeneous, fat E = %g Pa): bench/make_independent_truth.py\n' % fat_e)
            f.write('\n'.join(common + extra) + '\n')


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('out')
    ap.add_argument('--fat-youngs-moduli', type=float, nargs='+', default=[300, 1000, 3400])
    ap.add_argument('--max-volume', type=float, default=1500, help='TetGen -a bound [mm^3]')
    ap.add_argument('--order', type=int, choices=(2, 3), default=2,
                    help='the displacement field: quadratic (P2) or cubic (P3) tetrahedra')
    ap.add_argument('--refine', type=int, default=1,
                    help='K times the skin surface\'s rings and points per ring (pass --max-volume / K^3 with it)')
    ap.add_argument('--tumour-max-volume', type=float, default=0.0,
                    help='mesh the tumour spheres as internal surfaces with this TetGen volume bound inside them [mm^3] '
                         '(their stiff tissue is then exactly the tumour the method tracks); 0: tumour tissue is the '
                         'tetrahedra whose centroid lies within 8 mm of a centre (the 7.2 mm tracked spheres straddle them)')
    ap.add_argument('--poisson-ratio', type=float, default=0.49)
    ap.add_argument('--gland-ratio', type=float, default=2.0)
    ap.add_argument('--tumour-ratio', type=float, default=6.0)
    ap.add_argument('--depth', type=float, default=60.0, help='A: the apex height above the chest wall [mm]')
    ap.add_argument('--half-width', type=float, nargs=2, default=[85.0, 70.0], help='B+ B-: along +x and -x [mm]')
    ap.add_argument('--half-height', type=float, default=65.0, help='C: along y [mm]')
    ap.add_argument('--sag', type=float, default=15.0, help='S: the apex shifted by -S along y [mm]')
    ap.add_argument('--linear-solver', choices=('auto', 'mumps', 'scipy'), default='auto',
                    help='MUMPS (through petsc4py) when available, else SciPy')
    o = ap.parse_args()
    os.makedirs(o.out, exist_ok=True)
    radius = 8.0
    spheres = lambda centres: {n: icosphere(p, radius * 0.9) for n, p in centres.items()}
    node, ele, landmarks, tumours, gland, dims, in_tumour = mesh_body(
        o.out, o.max_volume, o.depth, o.half_width[0], o.half_width[1], o.half_height, o.sag, o.refine, spheres,
        o.tumour_max_volume)
    lab = labels(node, ele, tumours, gland, radius, in_tumour)
    bface = boundary(ele)
    used = np.unique(bface)
    renum = -np.ones(len(node), dtype=int)
    renum[used] = np.arange(len(used))
    sface = renum[bface]
    chest = np.nonzero(np.abs(node[used, 2]) < 1e-9)[0]
    tum_surf = spheres(tumours)
    gland_surf = icosphere((0.0, 0.0, 0.0), 1.0)
    gland_surf = (np.asarray(gland_surf[0]) * gland['axes'] + gland['centre'], gland_surf[1])
    gland_surf[0][:, 2] = np.maximum(gland_surf[0][:, 2], 0.5)  # the ellipsoid's part behind the chest wall is cut off
    node_m = node * 1e-3
    write_rest_model(o.out, node, ele, lab, np.nonzero(np.abs(node[:, 2]) < 1e-9)[0], landmarks, tum_surf,
                     o.gland_ratio, o.tumour_ratio)
    print('%d vertices, %d tetrahedra (fat %d, gland %d, tumour %d), %d skin vertices' %
          (len(node), len(ele), (lab == 1).sum(), (lab == 2).sum(), (lab == 3).sum(), len(used)))
    for fat in o.fat_youngs_moduli:
        t0 = time.time()
        moduli = {1: fat, 2: o.gland_ratio * fat, 3: o.tumour_ratio * fat}
        body = Body(node_m, ele, lab, moduli, o.poisson_ratio, o.linear_solver, o.order)
        d = os.path.join(o.out, 'E%g' % fat)
        os.makedirs(d, exist_ok=True)
        info = {'generator': 'SfePy (P%d tetrahedra, TL neo-Hookean + bulk penalty), TetGen mesh' % o.order,
                'order': o.order, 'refine': o.refine,
                'fat_youngs_modulus_Pa': fat, 'gland_youngs_modulus_Pa': moduli[2], 'tumour_youngs_modulus_Pa': moduli[3],
                'poisson_ratio': o.poisson_ratio, 'vertices': int(len(node)), 'tetrahedra': int(len(ele)),
                'shape_mm': dict(zip(('depth', 'half_width_plus_x', 'half_width_minus_x', 'half_height', 'sag'), dims))}
        pos = {}
        for which, g in (('prone', (0, 0, G)), ('supine', (0, 0, -G))):
            # Newton without line search: on soft fat a quarter of gravity folds elements in the
            # first iterate, so the first load step shrinks with the modulus (0.075 at 300 Pa).
            solves, steps = body.solve(g, first_step=0.25 * min(1.0, fat / 1000.0))
            du = body.displacement_at_vertices() * 1e3
            pos[which] = node + du
            info[which] = {'load_steps': steps, 'solves': solves, 'max_displacement_mm': float(np.abs(du).max())}
            for n, (TV, TF) in tum_surf.items():
                write_obj(os.path.join(d, 'tumour_%s_%s.obj' % (n, which)),
                          TV + body.displacement_at(TV * 1e-3) * 1e3, TF)
            if which == 'prone':
                GV, GF = gland_surf
                write_obj(os.path.join(d, 'gland_prone.obj'), GV + body.displacement_at(GV * 1e-3) * 1e3, GF)
        write_vtk(os.path.join(d, 'prone_volume.vtk'), pos['prone'], ele)
        write_vtk(os.path.join(d, 'supine_volume.vtk'), pos['supine'], ele)
        write_obj(os.path.join(d, 'prone.obj'), pos['prone'][used], sface)
        write_obj(os.path.join(d, 'supine.obj'), pos['supine'][used], sface)
        np.savetxt(os.path.join(d, 'chest_wall.txt'), chest, fmt='%d')
        with open(os.path.join(d, 'landmarks.csv'), 'w') as f:
            for name, v in landmarks.items():
                f.write('%d,%.6f,%.6f,%.6f\n' % ((renum[v],) + tuple(pos['supine'][v])))
        write_scenes(d, fat, o.gland_ratio, o.tumour_ratio)
        info['seconds'] = time.time() - t0
        json.dump(info, open(os.path.join(d, 'truth.json'), 'w'), indent=1)
        write_truth_list(o.out, tum_surf)
        print('fat E %g Pa: prone sag %.1f mm (%d load steps), supine %.1f mm (%d), %.0f s' %
              (fat, info['prone']['max_displacement_mm'], info['prone']['load_steps'],
               info['supine']['max_displacement_mm'], info['supine']['load_steps'], info['seconds']))
        sys.stdout.flush()


if __name__ == '__main__':
    main()
