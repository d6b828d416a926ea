#!/usr/bin/env python3
"""The Terzaghi family (issue «Analysis types»): cases/terzaghi.toml over conductivity k, Young's
modulus E, the number of steps to T_v = 0.6 and cells N, in `dynamic` (the default scheme) and
`quasi_static` stages. The stage lasts until T_v = 0.6 whatever k and E (t = 0.6 H²/c_v), so Δt
follows from the number of steps. Prints a markdown table: the dimensionless step c_v Δt/h², the
settlement error and the RMS pore-pressure error at T_v = 0.5 (over particles, normalised by the
load), e_p of [003] Eq. 33, and the largest step-to-step alternation of the base pressure after 20
steps |p_{k+1} − 2p_k + p_{k−1}|/q (equal steps only). `make study` runs it into
target/studies/terzaghi_family.md.

The load is q = 1 kPa × min(1, E/1e8 Pa), so that the strain q/E_c stays at 1e-5: Terzaghi's series
is the small-strain answer, and at E = 1e5 Pa a 1 kPa load strains the column by 1 % (its
finite-strain settlement and pressures then differ from the series by a few 1e-3 at every N:
measured p RMS 4.1e-3 → 5.7e-3 for N = 10 → 40 at 1 kPa, 8.8e-4 → 6.8e-5 at 1 Pa).
"""
import csv, itertools, json, os, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXE = os.path.join(ROOT, "target", "release", "porompm")
Q_LOAD, H, GW, KW, NU = 1000.0, 1.0, 9810.0, 2.2e9, 0.0
N_POROSITY = 0.3


def cv(k, e):
    ec = e * (1 - NU) / ((1 + NU) * (1 - 2 * NU))
    inv_q = N_POROSITY / KW
    return k / (GW * (1 / ec + inv_q))


def load(e):
    """The surface load [Pa]: a strain of 1e-5 at most (see the module documentation)."""
    return Q_LOAD * min(1.0, e / 1e8)


def run(k, e, steps, n, analysis):
    c = cv(k, e)
    t_end = 0.6 * H * H / c
    dt = t_end / steps
    out = os.path.join(ROOT, "target", "studies", "terzaghi_family", f"{analysis}-{k}-{e}-{steps}-{n}")
    sets = [f"materials.soil.hydraulic_conductivity={k}", f"materials.soil.model.young_modulus={e}",
            f"grid.cells=[1,{n}]", f"time.dt={dt}", f"stages.consolidation.duration={t_end}",
            f"loads.surface.traction=[0.0,{-load(e)}]",
            "output.history_every=1", f"stages.consolidation.analysis={analysis}"]
    cmd = [EXE, "run", "cases/terzaghi.toml", "--out", out, "--quiet"] + [a for s in sets for a in ("--set", s)]
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    s = json.load(open(os.path.join(out, "summary.json")))
    if s["status"] != "completed":
        return dict(status=s["status"], error=s.get("error", ""))
    rows = list(csv.DictReader(open(os.path.join(out, "history.csv"))))
    t = [float(x["time"]) for x in rows]
    p = [float(x["base.p"]) for x in rows]
    alt = 0.0
    for i in range(21, len(p) - 1):
        if abs((t[i + 1] - t[i]) - (t[i] - t[i - 1])) < 1e-9 * (t[i] - t[i - 1]):
            alt = max(alt, abs(p[i + 1] - 2 * p[i] + p[i - 1]) / load(e))
    v = {m: x["value"] for m, x in s["verification"].items()}
    h = H / n
    return dict(status="completed", courant=c * dt / h / h, settle=v["settlement_rel_error_Tv0.5"],
                prms=v["p_rms_error_Tv0.5"], ep=v["e_p_Tv0.5"], alt=alt, wall=s["wall_time_s"])


def main():
    ks = [float(x) for x in os.environ.get("KS", "1e-2 1e-4 1e-6 1e-8 1e-10").split()]
    es = [float(x) for x in os.environ.get("ES", "1e5 1e8").split()]
    steps = [int(x) for x in os.environ.get("STEPS", "60 600").split()]
    ns = [int(x) for x in os.environ.get("NS", "10 20 40 80").split()]
    lines = ["| analysis | k [m/s] | E [Pa] | q [Pa] | steps | N | c_v Δt/h² | settlement error | p RMS error | e_p | "
             "alternation after 20 steps | wall [s] |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for analysis, k, e, st, n in itertools.product(["dynamic", "quasi_static"], ks, es, steps, ns):
        r = run(k, e, st, n, analysis)
        if r["status"] != "completed":
            lines.append(f"| {analysis} | {k:g} | {e:g} | {load(e):g} | {st} | {n} | – | {r['status']}: {r['error'][:80]} |||||")
        else:
            lines.append(f"| {analysis} | {k:g} | {e:g} | {load(e):g} | {st} | {n} | {r['courant']:.3g} | {r['settle']:.2e} | "
                         f"{r['prms']:.2e} | {r['ep']:.2e} | {r['alt']:.1e} | {r['wall']:.2f} |")
        print(lines[-1], flush=True)
    os.makedirs(os.path.join(ROOT, "target", "studies"), exist_ok=True)
    open(os.path.join(ROOT, "target", "studies", "terzaghi_family.md"), "w").write("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
