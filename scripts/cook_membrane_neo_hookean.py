# Finite-element reference for Cook's membrane with a compressible neo-Hookean material.
#
# What it computes
#   The static vertical displacement of the tip (48, 60) of Cook's membrane, the quadrilateral
#   (0,0)-(48,44)-(48,60)-(0,44) m, plane strain, unit thickness, clamped on x = 0 and loaded on
#   x = 48 by a uniform dead shear traction t_y = 1/16 N/m (1 N in total), for
#     - the compressible neo-Hookean solid  W = mu/2 (tr C - 3) - mu ln J + lam/2 (ln J)^2
#       (Kirchhoff stress tau = mu (b - I) + lam ln J I, F_zz = 1), and
#     - the small-strain linear-elastic solid with the same E = 70 Pa, nu = 0.499,
#   on n x n meshes (n = 4 ... 64), their ratio mesh by mesh, and a Richardson extrapolation.
#
# Element
#   Q9 (biquadratic Lagrange, isoparametric, nodes placed by the bilinear map x = 48 s,
#   y = 44 s + t (44 - 28 s) of scripts/cook_membrane_fe.py), total Lagrangian, with
#   selective-reduced integration: the energy is split W = W_full + kappa/2 (ln J)^2, W_full is
#   integrated with 3x3 Gauss and the volumetric kappa/2 (ln J)^2 with 2x2 Gauss.  Default
#   kappa = lam (the "lambda split": at small strain W_full -> mu eps:eps); as a sensitivity check
#   the script also runs kappa = lam + 2 mu/3 (the "bulk-modulus split": W_full -> mu dev eps:dev eps).
#   The linear-elastic solve uses the same element and the same split (it is the exact
#   linearisation at u = 0 of the nonlinear one).  Newton with the consistent tangent
#   dP/dF, scipy.sparse + SuperLU, the load in a few equal steps.
#
# Verification printed by the script
#   (a) linear plane stress, E = 1, nu = 1/3, total shear 1: u_y -> ~23.96, the classical value,
#       which is u_y at the mid-point (48, 52) of the loaded edge (the corner (48, 60) -> ~25.2);
#   (b) Newton residual history (quadratic convergence), a finite-difference check of the
#       tangent on a small mesh, and neo-Hookean vs linear at load x 1e-3, 1e-4 (u / load must
#       agree, the difference falling in proportion to the load).
#
# Run:  python3 scripts/cook_membrane_neo_hookean.py   (needs numpy + scipy, e.g. /usr/bin/python3;
#       ~2 min on a busy 2-core machine; --quick skips n = 64)
import sys, time
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

E, NU = 70.0, 0.499
TRACTION = 1.0 / 16.0


def lame(E, nu):
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


# ---------------------------------------------------------------- Q9 shape functions
def q1d(x):
    N = np.array([0.5 * x * (x - 1), 1 - x * x, 0.5 * x * (x + 1)])
    dN = np.array([x - 0.5, -2 * x, x + 0.5])
    return N, dN


def q9(xi, eta):
    """Shape-function derivatives (9, 2) at (xi, eta); local node (i, j) -> 3 j + i."""
    Nx, dNx = q1d(xi)
    Ny, dNy = q1d(eta)
    d = np.zeros((9, 2))
    for j in range(3):
        for i in range(3):
            d[3 * j + i] = [dNx[i] * Ny[j], Nx[i] * dNy[j]]
    return d


def gauss(m):
    x, w = np.polynomial.legendre.leggauss(m)
    return [(a, b, wa * wb) for a, wa in zip(x, w) for b, wb in zip(x, w)]


# ---------------------------------------------------------------- mesh
class Mesh:
    def __init__(self, n):
        self.n = n
        m = 2 * n + 1
        s = np.linspace(0, 1, m)
        S, T = np.meshgrid(s, s)  # T[j, i] = s[j], S[j, i] = s[i]
        x = 48 * S
        y = 44 * S + T * (44 - 28 * S)
        self.X = np.column_stack([x.ravel(), y.ravel()])  # node (i, j) -> j m + i
        self.nn = m * m
        conn = []
        for ej in range(n):
            for ei in range(n):
                conn.append([(2 * ej + j) * m + 2 * ei + i for j in range(3) for i in range(3)])
        self.conn = np.array(conn)
        self.edofs = np.stack([2 * self.conn, 2 * self.conn + 1], axis=2).reshape(len(conn), 18)
        self.rows = np.repeat(self.edofs, 18, axis=1).ravel()
        self.cols = np.tile(self.edofs, (1, 18)).ravel()
        self.tip = (m - 1) * m + (m - 1)
        fixed = np.array([[2 * j * m, 2 * j * m + 1] for j in range(m)]).ravel()
        self.free = np.setdiff1d(np.arange(2 * self.nn), fixed)
        # consistent nodal forces of the dead shear traction on x = 48 (i = m - 1): edge length 16
        f = np.zeros(2 * self.nn)
        for e in range(n):
            L = 16.0 / n
            for k, c in zip(range(3), [1 / 6, 4 / 6, 1 / 6]):
                node = (2 * e + k) * m + (m - 1)
                f[2 * node + 1] += TRACTION * L * c
        self.fext = f
        xe = self.X[self.conn]  # (ne, 9, 2)
        self.rules = {}
        for order in (3, 2):
            dNdX, w = [], []
            for a, b, wg in gauss(order):
                d = q9(a, b)
                Jm = np.einsum('eai,aj->eij', xe, d)  # dX_i/dxi_j
                det = np.linalg.det(Jm)
                assert np.all(det > 0)
                Jinv = np.linalg.inv(Jm)
                dNdX.append(np.einsum('aj,eji->eai', d, Jinv))
                w.append(det * wg)
            self.rules[order] = (np.stack(dNdX, 1), np.stack(w, 1))  # (ne, g, 9, 2), (ne, g)


# ---------------------------------------------------------------- material
def piola(F, mu, a, linear=False):
    """First Piola P and A = dP/dF for W = mu/2 (F:F - 2) - mu ln J + a/2 (ln J)^2 (2-D, F_zz = 1).
    linear=True: small-strain isotropic elasticity with shear modulus mu and Lame lambda a,
    sigma = 2 mu eps + a tr(eps) I (its P is taken as sigma(grad u), A constant)."""
    I = np.eye(2)
    if linear:
        H = F - I
        eps = 0.5 * (H + np.swapaxes(H, -1, -2))
        tr = eps[..., 0, 0] + eps[..., 1, 1]
        P = 2 * mu * eps + a * tr[..., None, None] * I
        A0 = (mu * (np.einsum('ik,JL->iJkL', I, I) + np.einsum('iL,Jk->iJkL', I, I))
              + a * np.einsum('iJ,kL->iJkL', I, I))
        return P, np.broadcast_to(A0, F.shape[:-2] + (2, 2, 2, 2))
    # ln J from H = grad u directly (log1p of J - 1): with lam/mu ~ 500 the round-off of
    # log(det F) would otherwise set the residual floor
    H = F - I
    Jm1 = H[..., 0, 0] + H[..., 1, 1] + H[..., 0, 0] * H[..., 1, 1] - H[..., 0, 1] * H[..., 1, 0]
    if np.any(Jm1 <= -1):
        raise FloatingPointError('J <= 0')
    lnJ = np.log1p(Jm1)
    Fi = np.linalg.inv(F)  # Fi[J, i]
    FiT = np.swapaxes(Fi, -1, -2)
    P = mu * F + (a * lnJ[..., None, None] - mu) * FiT
    c = (a * lnJ - mu)[..., None, None, None, None]
    A = (mu * np.einsum('ik,JL->iJkL', I, I)
         + a * np.einsum('...Ji,...Lk->...iJkL', Fi, Fi)
         - c * np.einsum('...Jk,...Li->...iJkL', Fi, Fi))
    return P, A


class Model:
    """Selective-reduced Q9: parts = [(order, mu, a)], each integrated with its Gauss order."""

    def __init__(self, mesh, parts, linear=False):
        self.mesh, self.parts, self.linear = mesh, parts, linear

    def assemble(self, u, tangent=True):
        m = self.mesh
        ue = u[m.edofs].reshape(-1, 9, 2)
        fint = np.zeros((len(m.conn), 9, 2))
        Ke = np.zeros((len(m.conn), 9, 2, 9, 2)) if tangent else None
        for order, mu, a in self.parts:
            dNdX, w = m.rules[order]
            F = np.eye(2) + np.einsum('eai,egaJ->egiJ', ue, dNdX)
            P, A = piola(F, mu, a, self.linear)
            fint += np.einsum('eg,egiJ,egaJ->eai', w, P, dNdX)
            if tangent:
                Ke += np.einsum('eg,egaJ,egiJkL,egbL->eaibk', w, dNdX, A, dNdX, optimize=True)
        r = np.zeros(2 * m.nn)
        np.add.at(r, m.edofs.ravel(), fint.reshape(-1))
        if not tangent:
            return r, None
        K = sp.coo_matrix((Ke.reshape(-1), (m.rows, m.cols)), shape=(2 * m.nn,) * 2).tocsc()
        return r, K

    def solve(self, scale=1.0, steps=4, tol=1e-9, log=None, maxit=25, strict=True):
        m = self.mesh
        u = np.zeros(2 * m.nn)
        fr = m.free
        for st in range(1, steps + 1):
            fext = m.fext * scale * st / steps
            ref = np.linalg.norm(fext[fr])
            small = False
            for it in range(maxit):
                r, K = self.assemble(u)
                res = fext[fr] - r[fr]
                nr = np.linalg.norm(res) / ref
                if log is not None:
                    log.append((st, it, nr))
                if nr < tol or (self.linear and it == 1) or (it > 0 and small):
                    break
                du = spla.spsolve(K[fr][:, fr], res)
                u[fr] += du
                # or stop after a correction at round-off level: lam/mu ~ 500 and the residual's
                # floor is ~1e-9 relative (eps |K| |u| / |f|)
                small = np.abs(du).max() < 1e-10 * np.abs(u).max()
            else:
                if strict:
                    raise RuntimeError('Newton did not converge')
        return u


def parts_for(split, lam, mu):
    kappa = lam if split == 'lam' else lam + 2 * mu / 3
    return [(3, mu, lam - kappa), (2, 0.0, kappa)]


def tip_uy(mesh, u):
    return u[2 * mesh.tip + 1]


# ---------------------------------------------------------------- verification
def verify():
    print('== Verification ==')
    # (a) classical plane-stress Cook's membrane, E = 1, nu = 1/3, linear, Q9 full 3x3 integration
    lam, mu = lame(1.0, 1 / 3)
    lam_ps = 2 * mu * lam / (lam + 2 * mu)
    global TRACTION
    save, TRACTION = TRACTION, 1.0 / 16.0
    mid, tip = [], []
    for n in (4, 8, 16, 32):
        me = Mesh(n)
        u = Model(me, [(3, mu, lam_ps)], linear=True).solve(steps=1)
        k = n * (2 * n + 1) + 2 * n  # node (48, 52), the middle of the loaded edge
        assert np.allclose(me.X[k], [48, 52])
        mid.append(u[2 * k + 1])
        tip.append(tip_uy(me, u))
    TRACTION = save
    print('(a) linear plane stress E=1 nu=1/3 shear 1, Q9 3x3, n=4,8,16,32:\n'
          '    u_y(48,52) = ' + ', '.join('%.4f' % v for v in mid)
          + '   (classical reference 23.96 is at the mid-point of the loaded edge)\n'
          '    u_y(48,60) = ' + ', '.join('%.4f' % v for v in tip))
    # (b1) tangent vs central finite differences of the residual, n = 2, a random finite state
    lam, mu = lame(E, NU)
    me = Mesh(2)
    rng = np.random.default_rng(1)
    for split in ('lam', 'K'):
        mo = Model(me, parts_for(split, lam, mu))
        u0 = 0.02 * rng.standard_normal(2 * me.nn)
        _, K = mo.assemble(u0)
        K = K.toarray()
        Kfd = np.zeros_like(K)
        h = 1e-6
        for j in range(2 * me.nn):
            e = np.zeros(2 * me.nn); e[j] = h
            Kfd[:, j] = (mo.assemble(u0 + e, False)[0] - mo.assemble(u0 - e, False)[0]) / (2 * h)
        print('(b1) tangent vs finite differences (%s split): max rel. error %.1e'
              % (split, np.abs(K - Kfd).max() / np.abs(K).max()))
    # (b2) Newton history, n = 16: the full load in one step, and 20x the load (tip u_y ~ 5 m,
    # strongly nonlinear) in 4 steps
    me = Mesh(16)
    for scale, steps in ((1, 1), (20, 4)):
        log = []
        Model(me, parts_for('lam', lam, mu)).solve(scale=scale, steps=steps, log=log, tol=1e-15,
                                                   maxit=9, strict=False)
        hist = {}
        for st, it, nr in log:
            hist.setdefault(st, []).append(nr)
        print('(b2) Newton |r|/|f| n=16, load x%d, %d step(s), last step: ' % (scale, steps)
              + ' '.join('%.1e' % v for v in hist[steps]))
    # (b3) small-load limit: neo-Hookean and linear u/load at load x 1e-3 and 1e-4, n = 8;
    # the relative difference must be O(load) (about -5e-3 x load)
    me = Mesh(8)
    for split in ('lam', 'K'):
        p = parts_for(split, lam, mu)
        ul = tip_uy(me, Model(me, p, linear=True).solve(steps=1))
        out = []
        for sc in (1e-3, 1e-4):
            un = tip_uy(me, Model(me, p).solve(scale=sc, steps=1)) / sc
            out.append('load x%g: %.8f (%.1e)' % (sc, un, un / ul - 1))
        print('(b3) n=8 %s split: linear %.8f; neo-Hookean u/load (rel. diff) ' % (split, ul)
              + ', '.join(out))
    print()


def richardson(ns, vals):
    """Extrapolate from the last three values (uniform refinement by 2): observed order p."""
    a, b, c = vals[-3:]
    p = np.log2((b - a) / (c - b))
    return c + (c - b) / (2 ** p - 1), p


def main():
    t0 = time.time()
    verify()
    lam, mu = lame(E, NU)
    ns = [4, 8, 16, 32, 64]
    if '--quick' in sys.argv:
        ns = ns[:-1]
    res = {}
    for split in ('lam', 'K'):
        print('== Cook membrane, plane strain, E=%g Pa, nu=%g, shear 1 N, Q9 selective-reduced '
              '(%s split) ==' % (E, NU, 'kappa = lambda' if split == 'lam' else 'kappa = lambda + 2mu/3'))
        print('   n   linear u_y [m]   neo-Hookean u_y [m]   NH/linear   Newton its   time [s]')
        rows = []
        for n in ns:
            t = time.time()
            me = Mesh(n)
            p = parts_for(split, lam, mu)
            ul = tip_uy(me, Model(me, p, linear=True).solve(steps=1))
            log = []
            un = tip_uy(me, Model(me, p).solve(steps=4, log=log))
            rows.append((n, ul, un))
            print('%4d   %.6f         %.6f              %.6f    %d        %.1f'
                  % (n, ul, un, un / ul, len(log) - 4, time.time() - t))
        nl, pl = richardson(ns, [r[1] for r in rows])
        nn_, pn = richardson(ns, [r[2] for r in rows])
        print('   Richardson (last three meshes): linear %.5f (p=%.2f), neo-Hookean %.5f (p=%.2f), '
              'ratio %.5f' % (nl, pl, nn_, pn, nn_ / nl))
        res[split] = nn_
        print()
    print('total run time %.0f s' % (time.time() - t0))
    print('neo-Hookean tip u_y (extrapolated): %.5f m' % res['lam'])


if __name__ == '__main__':
    main()
