#!/usr/bin/env python3
"""`make bench-solvers`: how the linear solvers scale from 10^4 to 10^6 unknowns, on one and two ranks.

Two problems (PROBLEMS="consolidation slumping" chooses; both by default), each stabilised by the pressure
projection (alpha = 1), 2 x 2 material points per cell, on three grids of about 1e4, 1e5 and 1e6 unknowns:

* consolidation: the consolidating layer (cases/consolidation_layer.toml; u-p, quasi-static, Biot) for its
  first steps (STEPS x 1e-4 s of its time, default 6 steps: Delta t = 1e-4 s doubling after three steps), on
  58 x 58, 182 x 182 and 576 x 576 cells, with petsc_options/fieldsplit-fixed-stress.opts (GMRES, lower Schur
  field split, GAMG on the displacements, porompm's fixed-stress Schur approximation with BoomerAMG) and MUMPS
  (petsc_options/direct-lu.opts);
* slumping: the slumping block (cases/slumping_block.toml; u-p-U, dynamic) for its first STEPS steps of
  1e-3 s, on 64 x 48, 216 x 162 and 672 x 504 cells, with petsc_options/fieldsplit-schur-amg.opts (GMRES,
  lower Schur field split, GAMG on the displacements, selfp with BoomerAMG) and MUMPS.

MUMPS is skipped at 10^6 unknowns (extrapolated from 10^4 and 10^5 its factorisation needs far more than
this machine's 24 GiB; set MUMPS_LARGE=1 to try).

For each run: Newton iterations, Krylov iterations per Newton iteration, and the time per Newton iteration
split into assembly (residual and tangent, porompm's own timer; with the fixed-stress split it includes
forming the Schur approximation), preconditioner set-up (PETSc's PCSetUp event: AMG hierarchies, selfp's
product, or the factorisation) and solve (the rest of the Newton solve outside the assembly: Krylov
iterations, V-cycles, triangular solves, porompm's per-field residual checks), and the peak memory summed
over the ranks. The mat-vec alone: one product with the whole tangent (summary.json
timings.tangent_matvec_s, timed after each linear solve where porompm measures the field residuals),
against the bandwidth bound of an AIJ mat-vec (12 bytes per nonzero, 20 bytes per row) at the triad
bandwidth of one core measured by scripts/triad.c.

RUNS runs of each configuration up to 10^5 unknowns (default 3, median by wall time) and RUNS_LARGE at
10^6 (default 1). SIZES="small medium large" chooses sizes, RANKS="1 2" the rank counts, STRATEGIES (a
list of option files' names) keeps only those of each problem's strategies. Writes
target/bench/solvers.md and solvers.json.
"""
import json, os, re, statistics, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXE = os.path.join(ROOT, "target", "release", "porompm")
OUT = os.path.join(ROOT, "target", "bench")
STEPS = int(os.environ.get("STEPS", "6"))
RUNS = int(os.environ.get("RUNS", "3"))
RUNS_LARGE = int(os.environ.get("RUNS_LARGE", "1"))
PROBLEMS = {
    "consolidation": {
        "title": "Consolidating layer (u-p, quasi-static), stabilised (alpha = 1)",
        "case": "cases/consolidation_layer.toml", "duration": "stages.consolidation.duration",
        # Delta t = 1e-4 s for three steps, then 2e-4 s.
        "time": lambda steps: 1e-4 * min(steps, 3) + 2e-4 * max(steps - 3, 0), "dofs_per_node": 3,
        "grids": {"small": (58, 58), "medium": (182, 182), "large": (576, 576)},
        "strategies": ["fieldsplit-fixed-stress", "direct-lu"],
    },
    "slumping": {
        "title": "Slumping block (u-p-U, dynamic), stabilised (alpha = 1)",
        "case": "cases/slumping_block.toml", "duration": "stages.slump.duration",
        "time": lambda steps: 1e-3 * steps, "dofs_per_node": 5,
        "grids": {"small": (64, 48), "medium": (216, 162), "large": (672, 504)},
        "strategies": ["fieldsplit-schur-amg", "direct-lu"],
    },
}
SELECTED = os.environ.get("PROBLEMS", "consolidation slumping").split()
SIZES = os.environ.get("SIZES", "small medium large").split()
RANKS = [int(r) for r in os.environ.get("RANKS", "1 2").split()]
ONLY = os.environ.get("STRATEGIES", "").split()
MUMPS_LARGE = os.environ.get("MUMPS_LARGE", "0") != "0"
EVENTS = ["KSPSolve", "PCSetUp", "SNESSolve"]


def triad():
    exe = os.path.join(OUT, "triad")
    subprocess.run(["cc", "-O2", "-o", exe, os.path.join(ROOT, "scripts", "triad.c")], check=True)
    return float(subprocess.run([exe], capture_output=True, text=True, check=True).stdout.split()[0])


def events(log):
    """Time [s] (max over ranks) and count of each event, summed over PETSc's logging stages."""
    out = {e: [0.0, 0] for e in EVENTS}
    for line in log.splitlines():
        m = re.match(r"^(\w+)\s+(\d+)\s+[\d.]+\s+([\d.eE+-]+)\s", line)
        if m and m.group(1) in out:
            out[m.group(1)][0] += float(m.group(3))
            out[m.group(1)][1] += int(m.group(2))
    return out


def nonzeros(log, bs):
    """Rows and nonzeros of the whole tangent (the outermost matrix of block size `bs` -ksp_view prints)."""
    rows = nnz = None
    lines = log.splitlines()
    for i, line in enumerate(lines):
        m = re.search(rf"rows=(\d+), cols=\d+, bs={bs}", line)
        if m:
            for nxt in lines[i + 1:i + 4]:
                z = re.search(r"total: nonzeros=(\d+)", nxt)
                if z:
                    rows, nnz = int(m.group(1)), int(z.group(1))
                    break
    return rows, nnz


def run(problem, name, ranks, cells, strategy):
    out = os.path.join(OUT, "solvers", name)
    duration = problem["time"](STEPS)
    cmd = [EXE, "run", problem["case"], "--out", out, "--quiet", "--threads", "1",
           "--set", f"grid.cells=[{cells[0]},{cells[1]}]", "--set", f"{problem['duration']}={duration:.6g}",
           "--set", "stabilisation.pressure_projection=1.0", "--set", "output.fields_every=0",
           "--options-file", f"petsc_options/{strategy}.opts", "--", "-log_view", "-ksp_view"]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    if ranks > 1:
        cmd = ["mpirun", "--oversubscribe", "-n", str(ranks)] + cmd
    p = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    try:
        s = json.load(open(os.path.join(out, "summary.json")))
    except (OSError, ValueError):
        s = {"status": "no summary", "error": p.stderr[-2000:]}
    if p.returncode != 0 or s.get("status") != "completed":
        sys.exit(f"bench-solvers: {' '.join(cmd)} did not complete: {s.get('error')}\n{p.stderr[-2000:]}")
    return s, events(p.stdout), nonzeros(p.stdout, problem["dofs_per_node"])


def main():
    os.makedirs(OUT, exist_ok=True)
    bandwidth = triad()
    rows = []
    for key in SELECTED:
        rows += measure(key, PROBLEMS[key], bandwidth)
    write(rows, bandwidth)


def measure(key, problem, bandwidth):
    rows = []
    for size in SIZES:
        cells = problem["grids"][size]
        for strategy in problem["strategies"]:
            if ONLY and strategy not in ONLY:
                continue
            if strategy.startswith("direct") and size == "large" and not MUMPS_LARGE:
                continue
            for ranks in RANKS:
                n = RUNS_LARGE if size == "large" else RUNS
                runs = [run(problem, f"{key}-{size}-{strategy}-{ranks}r-{k}", ranks, cells, strategy) for k in range(n)]
                runs.sort(key=lambda r: r[0]["wall_time_s"])
                s, ev, (mrows, nnz) = runs[len(runs) // 2]
                newton = s["snes_iterations"]
                setup = ev["PCSetUp"][0]
                solve = s["timings"]["linear_solve_s"] - setup
                # One product with the whole tangent, timed by porompm's field monitor (PETSc's MatMult
                # event also counts the sub-blocks' and coarse levels' products inside the preconditioners).
                per_mm = s["timings"].get("tangent_matvec_s") or float("nan")
                bound = (12.0 * nnz + 20.0 * mrows) / (bandwidth * 1e9) / ranks if nnz else float("nan")
                rows.append({
                    "problem": key, "size": size, "cells": cells, "strategy": strategy, "ranks": ranks,
                    "unknowns": s["dofs"], "particles": s["particles"], "newton": newton,
                    "krylov": s["ksp_iterations"], "krylov_per_newton": s["ksp_iterations"] / newton,
                    "assembly_per_newton_s": s["timings"]["assembly_s"] / newton,
                    "pc_setup_per_newton_s": setup / newton, "solve_per_newton_s": solve / newton,
                    "newton_iteration_s": (s["timings"]["assembly_s"] + s["timings"]["linear_solve_s"]) / newton,
                    "memory_mib": s.get("peak_memory_total_mib"), "wall_s": [r[0]["wall_time_s"] for r in runs],
                    "matrix_rows": mrows, "nonzeros": nnz, "matmult_s": per_mm, "matmult_bound_s": bound,
                    "newton_per_bound_matvecs": (s["timings"]["assembly_s"] + s["timings"]["linear_solve_s"])
                    / newton / bound if nnz else float("nan"),
                    "field_residuals": s.get("field_residuals"),
                })
                r = rows[-1]
                print(f"{key} {size} {strategy} {ranks}r: {r['unknowns']} unknowns, {r['krylov_per_newton']:.1f} Krylov/Newton, "
                      f"{r['newton_iteration_s']:.2f} s/Newton (asm {r['assembly_per_newton_s']:.2f}, "
                      f"setup {r['pc_setup_per_newton_s']:.2f}, solve {r['solve_per_newton_s']:.2f}), "
                      f"{r['memory_mib']:.0f} MiB, tangent mat-vec {per_mm * 1e3:.2f} ms (bound {bound * 1e3:.2f} ms)", flush=True)
    return rows


def write(rows, bandwidth):
    import math
    lines = [f"First {STEPS} steps of each problem; triad bandwidth of one core {bandwidth:.1f} GB/s."]
    for key in SELECTED:
        problem = PROBLEMS[key]
        rs = [r for r in rows if r["problem"] == key]
        lines += ["", f"{problem['title']}:", "",
                  "| grid | unknowns | strategy | ranks | Newton | Krylov per Newton | s per Newton iteration | "
                  "assembly | PC set-up | solve | peak memory, all ranks [MiB] | tangent mat-vec [ms] | "
                  "bandwidth bound [ms] |",
                  "|" + "---|" * 13]
        for r in rs:
            lines.append(
                f"| {r['cells'][0]} x {r['cells'][1]} | {r['unknowns']} | {r['strategy']} | {r['ranks']} | "
                f"{r['newton']} | {r['krylov_per_newton']:.1f} | {r['newton_iteration_s']:.3f} | "
                f"{r['assembly_per_newton_s']:.3f} | {r['pc_setup_per_newton_s']:.3f} | {r['solve_per_newton_s']:.3f} | "
                f"{r['memory_mib']:.0f} | {r['matmult_s'] * 1e3:.2f} | {r['matmult_bound_s'] * 1e3:.2f} |")
        # Growth between sizes (same strategy and ranks): time per Newton iteration ~ n^k.
        lines.append("")
        for strategy in problem["strategies"]:
            for ranks in RANKS:
                sr = [r for r in rs if r["strategy"] == strategy and r["ranks"] == ranks]
                for a, b in zip(sr, sr[1:]):
                    k = math.log(b["newton_iteration_s"] / a["newton_iteration_s"]) / math.log(b["unknowns"] / a["unknowns"])
                    g = b["krylov_per_newton"] / a["krylov_per_newton"]
                    lines.append(f"- {strategy}, {ranks} rank(s), {a['unknowns']} -> {b['unknowns']} unknowns: time per "
                                 f"Newton iteration ~ n^{k:.2f}, Krylov iterations per Newton x{g:.2f}")
    text = "\n".join(lines) + "\n"
    open(os.path.join(OUT, "solvers.md"), "w").write(text)
    json.dump({"bandwidth_gb_s": bandwidth, "rows": rows}, open(os.path.join(OUT, "solvers.json"), "w"), indent=1)
    print(text)


if __name__ == "__main__":
    main()
