#!/usr/bin/python3
"""How well a Schur-complement approximation fits porompm's own tangent: the spectrum of Sp^-1 S.

A study tool for the block preconditioners of docs/solvers.md ("Why the iterations grow"). It reads a
tangent that PETSc wrote in its binary format, splits it into the displacement dofs (u, and U in the
u-p-U system) and the pore pressures p (node-major ordering, `--dofs-per-node` dofs per node, the
pressure at component `--pressure`), forms the exact Schur complement S = A_pp - A_pu A_uu^-1 A_up
(sparse LU of A_uu, dense S: keep the grid small, up to about 64 x 48 cells) and prints the extreme and
the 1 %/99 % eigenvalues of Sp^-1 S for

* selfp: Sp = A_pp - A_pu diag(A_uu)^-1 A_up (PETSc's `-pc_fieldsplit_schur_precondition selfp`);
* A_pp alone;
* with `--strip K`: selfp with the exact inverse of A_uu over the displacement dofs of a free-surface strip
  (the nodes beyond the outermost K - 1 layers of live pressure nodes) in place of its diagonal, and with
  `--fixed-stress-share c` that minus c (1-n)^2 M_L/K_dr (the solid's share of the fixed-stress term);
* fixed stress (with `--drained-bulk-modulus`): selfp - beta M_L and A_pp - beta M_L (the one porompm builds
  for `-pc_fieldsplit_schur_precondition user`), beta = 1/K_dr, M_L the lumped
  pressure mass in PETSc's scaled units. M_L is recovered from the rows of A_pp: where the Darcy flux and
  the pressure projection rows sum to zero, a row of A_pp sums to -c M_L with c = `--storage` (n/K_w +
  (1-n)/K_s, 1/Pa); near drained boundaries the flux rows do not, so M_L is capped at `--mass-cap`
  (the full-support value (M/h)^2 h^2 = M^2 for porompm's pressure scale s = M/h).

Rows of p without any coupling to u (inactive or constrained nodes) are left out. The condition number
of Sp^-1 S (its spectrum is real and positive when the approximation is good) bounds the Krylov
iterations of a Schur field split with exact block solves.

Make a dump with, for example,
    porompm run cases/slumping_block.toml --set grid.cells=[64,48] --set stages.slump.duration=0.001 \\
        --set stabilisation.pressure_projection=1.0 --options-file petsc_options/fieldsplit-schur-amg.opts \\
        -- -ksp_view_mat binary:/tmp/A.bin
then
    /usr/bin/python3 scripts/schur_spectrum.py /tmp/A.bin --dofs-per-node 5 --pressure 2

It needs NumPy and SciPy (Debian: python3-scipy) and PETSc's PetscBinaryIO.py (petsc-dev).
"""
import argparse, glob, sys, warnings

warnings.filterwarnings("ignore", message="PETSC_DIR env not set")
for d in sorted(glob.glob("/usr/share/petsc/*/lib/petsc/bin")):
    sys.path.insert(0, d)
import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as sla
import PetscBinaryIO


def spectrum(S, Sp):
    """Sorted real parts of the eigenvalues of Sp^-1 S, and the largest imaginary part."""
    w = la.eigvals(la.solve(Sp, S))
    return np.sort(w.real), np.abs(w.imag).max()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("matrix", help="PETSc binary file (the last matrix in it is used)")
    ap.add_argument("--dofs-per-node", type=int, required=True, help="5 for u-p-U, 3 for u-p")
    ap.add_argument("--pressure", type=int, default=2, help="component of the pressure in a node's dofs")
    ap.add_argument("--drained-bulk-modulus", type=float, help="K_dr [Pa]: also try fixed stress, beta = 1/K_dr")
    ap.add_argument("--storage", type=float, default=0.3 / 2.2e9, help="n/K_w + (1-n)/K_s [1/Pa]")
    ap.add_argument("--mass-cap", type=float, help="cap of the recovered lumped pressure mass (M^2 for s = M/h)")
    ap.add_argument("--drop-layers", type=int, default=0,
                    help="leave out the pressure nodes of the outermost K layers of live nodes along the largest i and j "
                         "(the Schur complement were those pressures fixed); needs --cells-x")
    ap.add_argument("--cells-x", type=int, help="cells along x of the grid the matrix came from")
    ap.add_argument("--strip", type=int, default=0,
                    help="also try selfp with the exact inverse of A_uu over the displacement dofs of the nodes "
                         "beyond the outermost K - 1 layers of live pressure nodes (a free-surface strip along the "
                         "largest i and j; dense, small grids only) instead of its diagonal there; needs --cells-x")
    ap.add_argument("--fixed-stress-share", type=float, action="append", default=[],
                    help="with --strip and --drained-bulk-modulus: subtract this share c of (1-n)^2 M_L/K_dr "
                         "(n = --porosity) from the strip-corrected selfp (repeatable)")
    ap.add_argument("--porosity", type=float, default=0.3, help="n for --fixed-stress-share")
    a = ap.parse_args()

    A = PetscBinaryIO.PetscBinaryIO().readBinaryFile(a.matrix, mattype="scipy.sparse")[-1].tocsr()
    idx = np.arange(A.shape[0])
    p = idx[idx % a.dofs_per_node == a.pressure]
    u = idx[idx % a.dofs_per_node != a.pressure]
    Auu, Aup = A[u][:, u].tocsc(), A[u][:, p].tocsc()
    Apu, App = A[p][:, u].tocsr(), A[p][:, p]
    live = np.where(np.asarray(abs(Apu).sum(axis=1)).ravel() > 0)[0]
    if a.drop_layers:
        if not a.cells_x:
            sys.exit("--drop-layers needs --cells-x")
        node = p[live] // a.dofs_per_node
        i, j = node % (a.cells_x + 1), node // (a.cells_x + 1)
        live = live[(i <= i.max() - a.drop_layers) & (j <= j.max() - a.drop_layers)]
    keep = np.ix_(live, live)
    S = (App.toarray() - Apu @ sla.splu(Auu).solve(Aup.toarray()))[keep]
    selfp = (App - Apu @ sp.diags(1.0 / Auu.diagonal()) @ Aup).toarray()[keep]
    print(f"{A.shape[0]} unknowns, {len(u)} displacement, {len(p)} pressure ({len(live)} coupled)")
    cases = [("selfp", selfp), ("A_pp", App.toarray()[keep])]
    if a.drained_bulk_modulus:
        mass = -np.asarray(App.sum(axis=1)).ravel()[live] / a.storage
        if a.mass_cap:
            mass = np.minimum(mass, a.mass_cap)
        cases.append(("selfp - bM", selfp - np.diag(mass / a.drained_bulk_modulus)))
        cases.append(("A_pp - bM", App.toarray()[keep] - np.diag(mass / a.drained_bulk_modulus)))
    if a.strip:
        if not a.cells_x:
            sys.exit("--strip needs --cells-x")
        pnode = p[live] // a.dofs_per_node
        pi, pj = pnode % (a.cells_x + 1), pnode // (a.cells_x + 1)
        unode = u // a.dofs_per_node
        ui, uj = unode % (a.cells_x + 1), unode // (a.cells_x + 1)
        strip = np.where((ui >= pi.max() + 1 - a.strip) | (uj >= pj.max() + 1 - a.strip))[0]
        inner = np.setdiff1d(np.arange(len(u)), strip)
        d = 1.0 / Auu.diagonal()
        corrected = (App - Apu[:, inner] @ sp.diags(d[inner]) @ Aup[inner]).toarray()
        corrected -= Apu[:, strip].toarray() @ la.solve(Auu[strip][:, strip].toarray(), Aup[strip].toarray())
        corrected = corrected[keep]
        cases.append((f"strip {a.strip}", corrected))
        if a.drained_bulk_modulus:
            for c in a.fixed_stress_share:
                beta = c * (1.0 - a.porosity) ** 2 / a.drained_bulk_modulus
                cases.append((f"strip {a.strip} - {c}(1-n)^2 M/K", corrected - np.diag(mass * beta)))
    for name, Sp in cases:
        w, imag = spectrum(S, Sp)
        lo, hi = w[int(0.01 * len(w))], w[int(0.99 * len(w))]
        print(f"{name:>12}: eigenvalues of Sp^-1 S in [{w[0]:.3g}, {w[-1]:.3g}] (ratio {w[-1] / w[0]:.3g}), "
              f"1 %-99 % [{lo:.3g}, {hi:.3g}] (ratio {hi / lo:.3g}), largest imaginary part {imag:.2g}")


if __name__ == "__main__":
    main()
