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


def aggregate_inverse(Auu, plive, dpn, pcomp, nx, spec):
    """Binv: exact inverse of A_uu on each aggregate's displacement dofs (u and U), diag(A_uu)^-1 elsewhere.

    The displacement dofs are node-major with dpn - 1 of them per node (the order of the split), so node k owns the
    rows (dpn - 1) k ... (dpn - 1) k + dpn - 2 of A_uu. Returns Binv (sparse) and a one-line description."""
    nd = dpn - 1
    nn = Auu.shape[0] // nd
    I, J = np.arange(nn) % (nx + 1), np.arange(nn) // (nx + 1)
    pnode = plive // dpn
    imax, jmax = (pnode % (nx + 1)).max(), (pnode // (nx + 1)).max()
    diag = Auu.diagonal()
    off = Auu - sp.diags(diag)
    active = np.asarray(abs(off).sum(axis=1)).ravel().reshape(nn, nd).sum(axis=1) > 0
    kind, *kv = spec.split(":")
    opt = dict(x.split("=") for x in kv if "=" in x)
    bare = [x for x in kv if "=" not in x]
    groups = []
    node = lambda i, j: j * (nx + 1) + i
    # the strip runs out to the last active displacement nodes, beyond the outermost live pressure layer
    # where the material reaches nodes whose pressure is fixed (drained) or absent
    iend, jend = I[active].max(), J[active].max()
    if opt.get("base") == "u":  # count the K layers from the outermost active displacement node instead
        imax, jmax = iend, jend
    if kind == "root":
        d = diag.reshape(nn, nd)
        inner = active & (I < imax - 2) & (J < jmax - 2)
        med = np.median(d[inner], axis=0)
        if "tau" in opt:  # only the components that couple (fixed dofs keep an identity row)
            dofact = (np.asarray(abs(off).sum(axis=1)).ravel() > 0).reshape(nn, nd)
            sliver = active & (np.where(dofact, d / med, np.inf).min(axis=1) < float(opt["tau"]))
        else:
            L = int(opt.get("layers", 1))
            sliver = active & ((I >= imax + 1 - L) | (J >= jmax + 1 - L))
        # node-to-node coupling strength: Frobenius norm of the nd x nd blocks of A_uu
        C = Auu.tocoo()
        W = sp.coo_matrix((C.data ** 2, (C.row // nd, C.col // nd)), shape=(nn, nn)).tocsr()
        W.sum_duplicates()
        depth = int(opt.get("depth", 1))
        owner = {}
        for k in np.where(sliver)[0]:
            r, seen = k, set()
            # follow the strongest coupling to a non-sliver node
            while sliver[r] and r not in seen:
                seen.add(r)
                row = W.getrow(r)
                cand = [(v, c) for c, v in zip(row.indices, row.data) if c != r and active[c]
                        and (not sliver[c] or (d[c] / med).min() > (d[r] / med).min())]
                if not cand:
                    break
                r = max(cand)[1]
            chain = [r]
            for _ in range(depth - 1):  # further roots inwards
                row = W.getrow(chain[-1])
                cand = [(v, c) for c, v in zip(row.indices, row.data) if c not in chain and active[c]
                        and not sliver[c] and (I[c] + J[c] < I[chain[-1]] + J[chain[-1]])]
                if not cand:
                    break
                chain.append(max(cand)[1])
            owner.setdefault(tuple(chain), []).append(k)
        # non-overlapping: a root claimed by several chains keeps the first; merge aggregates sharing nodes
        parent = {}
        def find(x):
            while parent.get(x, x) != x:
                x = parent[x]
            return x
        members = {}
        for chain, sl in owner.items():
            nodes = list(chain) + sl
            for q in nodes[1:]:
                a_, b_ = find(nodes[0]), find(q)
                if a_ != b_:
                    parent[b_] = a_
        for chain, sl in owner.items():
            for q in list(chain) + sl:
                members.setdefault(find(q), set()).add(q)
        groups = [sorted(m) for m in members.values()]
        weights = None
    elif kind == "overlap":
        K, Wd = int(bare[0]) if bare else 2, int(opt.get("width", 3))
        groups = []
        i0, j0 = imax + 1 - K, jmax + 1 - K
        h = Wd // 2
        for j in range(0, j0):
            groups.append([node(i, jj) for jj in range(max(0, j - h), min(j0, j - h + Wd)) for i in range(i0, iend + 1)])
        for i in range(0, i0):
            groups.append([node(ii, j) for ii in range(max(0, i - h), min(i0, i - h + Wd)) for j in range(j0, jend + 1)])
        groups.append([node(i, j) for i in range(i0, iend + 1) for j in range(j0, jend + 1)])
        weights = True
    else:
        K = int(kind)
        Wd = int(opt.get("width", 1))
        corner = opt.get("corner", "block")
        Cw = int(opt.get("cornerw", K))
        i0, j0 = imax + 1 - K, jmax + 1 - K
        ci0, cj0 = imax + 1 - Cw, jmax + 1 - Cw  # corner square
        if corner == "block":
            groups.append([node(i, j) for i in range(ci0, iend + 1) for j in range(cj0, jend + 1)])
            right_top, top_right = cj0, ci0
        elif corner == "top":
            right_top, top_right = j0, iend + 1
        elif corner == "right":
            right_top, top_right = jend + 1, i0
        elif corner == "nodes":
            groups += [[node(i, j)] for i in range(i0, iend + 1) for j in range(j0, jend + 1)]
            right_top, top_right = j0, i0
        else:
            sys.exit(f"unknown corner {corner}")
        for j in range(0, right_top, Wd):  # right side: columns along i
            groups.append([node(i, jj) for jj in range(j, min(j + Wd, right_top)) for i in range(i0, iend + 1)])
        for i in range(0, top_right, Wd):  # top: columns along j
            groups.append([node(ii, j) for ii in range(i, min(i + Wd, top_right)) for j in range(j0, jend + 1)])
        weights = None
    groups = [[k for k in g if active[k]] for g in groups]
    groups = [g for g in groups if g]
    covered = np.zeros(nn, int)
    for g in groups:
        covered[g] += 1
    if weights is None and covered.max() > 1:
        sys.exit(f"aggregates {spec} overlap")
    dinv = np.where(covered.repeat(nd) > 0, 0.0, 1.0 / diag)
    rows, cols, vals = [np.arange(len(diag))], [np.arange(len(diag))], [dinv]
    A = Auu.tocsr()
    nnz_blocks = 0
    for g in groups:
        dofs = (np.asarray(g)[:, None] * nd + np.arange(nd)).ravel()
        B = la.inv(A[dofs][:, dofs].toarray())
        if weights:
            B = B * (1.0 / covered[np.asarray(g)].repeat(nd))[:, None]  # restricted-additive-Schwarz style weight
        r, c = np.meshgrid(dofs, dofs, indexing="ij")
        rows.append(r.ravel()); cols.append(c.ravel()); vals.append(B.ravel())
        nnz_blocks += B.size
    Binv = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=A.shape).tocsr()
    sizes = np.array([len(g) for g in groups])
    info = (f"{len(groups)} aggregates of {sizes.min()}-{sizes.max()} nodes (mean {sizes.mean():.2f}), "
            f"{(covered > 0).sum()} nodes covered, Binv nnz {Binv.nnz} (diag alone {len(diag)})")
    return Binv, info


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
    ap.add_argument("--aggregates", action="append", default=[], metavar="SPEC",
                    help="also try selfp with an aggregate block inverse of A_uu (exact inverse of A_uu restricted to "
                         "all displacement dofs, u and U, of each aggregate; diag(A_uu)^-1 elsewhere) and, with "
                         "--drained-bulk-modulus, minus each --fixed-stress-share; repeatable; needs --cells-x. "
                         "SPEC is K[:key=value...] with K the depth in node layers of the free-surface strip "
                         "(i >= imax+1-K or j >= jmax+1-K, imax/jmax the outermost live pressure layer, out to the "
                         "last active displacement node beyond it as --strip does; with base=u imax/jmax are the "
                         "outermost active displacement nodes, so K counts all node layers), "
                         "grouped in columns normal to the surface. Keys: width=W (W nodes along the surface per "
                         "aggregate, default 1), corner=block|top|right|nodes (the K x K corner square: one "
                         "aggregate, vertical or horizontal columns, or single nodes; default block), "
                         "cornerw=C (the corner aggregate spans C x C nodes, C >= K, default K). "
                         "SPEC root[:key=value...] is the AgFEM-like graph rule: sliver nodes (the outer "
                         "layers=L layers, default 1, or with tau=T the active nodes whose diagonal of A_uu is "
                         "below T times the interior median in any component) each join their most strongly "
                         "coupled non-sliver neighbour (the root, by the Frobenius norm of the 4 x 4 coupling "
                         "block of A_uu; depth=D follows D roots inwards, default 1); aggregate = root + its "
                         "slivers. SPEC overlap:K[:width=W] sums the local inverses of overlapping K-deep, "
                         "W-wide patches centred on each surface node, weighted by 1/multiplicity (a "
                         "partition of unity, restricted additive Schwarz; not symmetric)")
    ap.add_argument("--skip-basic", action="store_true",
                    help="only selfp and the requested --strip/--aggregates variants (skip A_pp and the fixed-stress pair)")
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
    cases = [("selfp", selfp)] + ([] if a.skip_basic else [("A_pp", App.toarray()[keep])])
    if a.drained_bulk_modulus:
        mass = -np.asarray(App.sum(axis=1)).ravel()[live] / a.storage
        if a.mass_cap:
            mass = np.minimum(mass, a.mass_cap)
        if not a.skip_basic:
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
    for spec in a.aggregates:
        if not a.cells_x:
            sys.exit("--aggregates needs --cells-x")
        Binv, info = aggregate_inverse(Auu, p[live], a.dofs_per_node, a.pressure, a.cells_x, spec)
        print(f"aggregates {spec}: {info}")
        corrected = (App - Apu @ Binv @ Aup).toarray()[keep]
        cases.append((f"agg {spec}", corrected))
        if a.drained_bulk_modulus:
            for c in a.fixed_stress_share:
                beta = c * (1.0 - a.porosity) ** 2 / a.drained_bulk_modulus
                cases.append((f"agg {spec} - {c}(1-n)^2 M/K", corrected - np.diag(mass * beta)))
    for name, Sp in cases:
        w, imag = spectrum(S, Sp)
        lo, hi = w[int(0.01 * len(w))], w[int(0.99 * len(w))]
        print(f"{name:>12}: eigenvalues of Sp^-1 S in [{w[0]:.3g}, {w[-1]:.3g}] (ratio {w[-1] / w[0]:.3g}), "
              f"1 %-99 % [{lo:.3g}, {hi:.3g}] (ratio {hi / lo:.3g}), largest imaginary part {imag:.2g}")


if __name__ == "__main__":
    main()
