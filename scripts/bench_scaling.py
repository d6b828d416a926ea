#!/usr/bin/env python3
"""`make bench-scaling`: strong scaling from one to two ranks at 10^5 unknowns, and the communication
a step costs, for the weak-scaling model of docs/distributed.md.

Part 1, strong scaling. The slumping block (cases/slumping_block.toml) on a 216 x 162 grid: 104 112
u-p-U unknowns under the block, 82 944 material points, stabilised by the pressure projection
(alpha = 1), 20 steps of 1e-3 s. Two solver strategies (petsc_options/fieldsplit-schur-amg.opts and
petsc_options/direct-lu.opts), each run as: one rank with one thread, one rank with two threads
(the default on this 2-core machine: the particle loops on both cores, PETSc on one), two ranks
with one thread each (STRATEGIES="..." chooses the option files). RUNS runs of each (default 3), one at a time; the median wall time and its
phases. Speed-up = wall time of one rank with one thread / wall time of two ranks (and of one rank
with two threads / two ranks, what a user of the default gains).

Part 2, communication per step (COMM=1, the default). The same problem at three sizes on two and
four ranks (four oversubscribe the 2 cores: only counts are read there, not times) with `-log_view`:
PETSc's messages, bytes and reductions per rank and step (ghost updates of the residual and tangent
assembly, off-rank COO entries, the Krylov solver's mat-vecs and dot products), porompm's own
collectives (summary.json.collectives, rank 0) and the points migrated; each the difference of a
10-step and a 5-step run over 5 steps, so that the set-up (first matrix, repartition) drops out.

Part 3, the same counts in three dimensions (COMM3D=1; off by default): the consolidating layer of
cases/consolidation_layer_3d.toml on 13^3, 21^3 and 29^3 cells, per Krylov iteration. Writes
target/bench/scaling.md and scaling.json.
"""
import json, os, re, statistics, subprocess, sys

RUNS = int(os.environ.get("RUNS", "3"))
COMM = os.environ.get("COMM", "1") != "0"
STRONG = os.environ.get("STRONG", "1") != "0"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXE = os.path.join(ROOT, "target", "release", "porompm")
OUT = os.path.join(ROOT, "target", "bench")
CASE = "cases/slumping_block.toml"
BASE = ["--set", "stabilisation.pressure_projection=1.0"]
STRATEGIES = os.environ.get("STRATEGIES", "fieldsplit-schur-amg direct-lu").split()
CONFIGS = [(1, 1), (1, 2), (2, 1)]  # (ranks, threads per rank)
PHASES = ["step_setup_s", "assembly_s", "linear_solve_s", "particle_update_s", "output_s"]


def run(name, ranks, threads, cells, duration, extra=(), case=None):
    """One run of the slumping block on `cells` for `duration`, or of `case` = (file, its --set
    arguments) instead."""
    out = os.path.join(OUT, "scaling", name)
    if case is None:
        case = (CASE, ["--set", f"grid.cells=[{cells[0]},{cells[1]}]", "--set", f"stages.slump.duration={duration}"]
                + BASE)
    cmd = [EXE, "run", case[0], "--out", out, "--quiet", "--threads", str(threads)] + case[1]
    cmd += list(extra)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    if ranks > 1:
        cmd = ["mpirun", "--oversubscribe", "-n", str(ranks)] + cmd
    p = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    s = json.load(open(os.path.join(out, "summary.json")))
    if p.returncode != 0 or s["status"] != "completed":
        sys.exit(f"bench-scaling: {' '.join(cmd)} did not complete: {s.get('error')}\n{p.stderr[-2000:]}")
    return s, p.stdout


def strong():
    rows = {}
    for strategy in STRATEGIES:
        opts = ["--options-file", f"petsc_options/{strategy}.opts"]
        for ranks, threads in CONFIGS:
            runs = [run(f"{strategy}-{ranks}r{threads}t-{k}", ranks, threads, (216, 162), 0.02, opts)[0]
                    for k in range(RUNS)]
            med = sorted(runs, key=lambda s: s["wall_time_s"])[len(runs) // 2]
            rows[(strategy, ranks, threads)] = (med, [s["wall_time_s"] for s in runs])
    lines = ["| strategy | ranks x threads | wall time [s] (median; all runs) | speed-up vs 1x1 | vs 1x2 | "
             "Newton | Krylov | step setup [s] | assembly [s] | linear solve [s] | particle update [s] | "
             "output [s] | peak memory, all ranks [MiB] |", "|" + "---|" * 13]
    table = []
    for strategy in STRATEGIES:
        w11 = statistics.median(rows[(strategy, 1, 1)][1])
        w12 = statistics.median(rows[(strategy, 1, 2)][1])
        for ranks, threads in CONFIGS:
            s, alls = rows[(strategy, ranks, threads)]
            w = statistics.median(alls)
            t = s["timings"]
            lines.append(
                f"| {strategy} | {ranks} x {threads} | {w:.1f} ({', '.join(f'{a:.1f}' for a in alls)}) | "
                f"{w11 / w:.2f} | {w12 / w:.2f} | {s['snes_iterations']} | {s['ksp_iterations']} | "
                + " | ".join(f"{t[p]:.2f}" for p in PHASES)
                + f" | {s['peak_memory_total_mib']:.0f} |")
            table.append({"strategy": strategy, "ranks": ranks, "threads": threads, "wall_s": w, "runs": alls,
                          "dofs": s["dofs"], "particles": s["particles"], "newton": s["snes_iterations"],
                          "krylov": s["ksp_iterations"], "timings": t, "memory_mib": s["peak_memory_total_mib"]})
    s = rows[(STRATEGIES[0], 1, 1)][0]
    head = f"Strong scaling: {s['dofs']} unknowns, {s['particles']} material points, {s['steps']} steps."
    return head + "\n\n" + "\n".join(lines), table


LOG = {"messages": r"^MPI Msg Count:\s+(\S+)\s+\S+\s+(\S+)\s+(\S+)",
       "bytes": r"^MPI Msg Len \(bytes\):\s+(\S+)\s+\S+\s+(\S+)\s+(\S+)",
       "reductions": r"^MPI Reductions:\s+(\S+)"}


def counts(cells, ranks, duration, case=None, options="fieldsplit-schur-amg"):
    """One run with -log_view: its summary and PETSc's message counts (per rank: messages, bytes;
    reductions)."""
    s, log = run(f"comm-{cells[0]}-{ranks}-{duration}", ranks, 1, cells, duration,
                 ["--options-file", f"petsc_options/{options}.opts", "--", "-log_view"], case)
    found = {}
    for key, pat in LOG.items():
        m = re.search(pat, log, re.M)
        if not m:
            sys.exit("bench-scaling: -log_view printed no MPI message summary")
        found[key] = [float(v) for v in m.groups()]
    # PETSc 3.18 prints Max, Max/Min, Avg and Total; the regular expressions keep Max, Avg and
    # Total. Messages: the average per rank. Bytes: the Avg column is the mean message length, so
    # the bytes per rank are the total over the ranks.
    return s, {"messages": found["messages"][1], "bytes": found["bytes"][2] / ranks,
               "reductions": found["reductions"][0], "own_calls": s["collectives"]["calls"],
               "own_bytes": s["collectives"]["bytes"], "krylov": s["ksp_iterations"], "newton": s["snes_iterations"],
               "migrated": s["migrated_particles"] / ranks}


def comm():
    """Messages, bytes and reductions per rank and step: the difference of a 10-step and a 5-step run
    over 5 steps, so that the set-up (the first matrix, the repartition after the first step) drops out."""
    lines = ["| cells | ranks | unknowns | points per rank | Krylov / Newton | PETSc messages / rank / step | "
             "PETSc kB / rank / step | PETSc reductions / step | porompm collectives / step | porompm kB / step | "
             "migrated points / rank / step |", "|" + "---|" * 11]
    table = []
    for cells in [(108, 81), (216, 162), (432, 324)]:
        for ranks in (2, 4):
            s5, a = counts(cells, ranks, 0.005)
            s10, b = counts(cells, ranks, 0.010)
            d = {k: (b[k] - a[k]) / 5 for k in a}
            row = {"cells": cells, "ranks": ranks, "dofs": s10["dofs"], "points_per_rank": s10["particles"] / ranks,
                   "krylov_per_newton": d["krylov"] / d["newton"], **{f"{k}_per_step": v for k, v in d.items()}}
            table.append(row)
            lines.append(f"| {cells[0]} x {cells[1]} | {ranks} | {s10['dofs']} | {row['points_per_rank']:.0f} | "
                         f"{row['krylov_per_newton']:.1f} | {d['messages']:.0f} | {d['bytes'] / 1e3:.0f} | "
                         f"{d['reductions']:.0f} | {d['own_calls']:.0f} | {d['own_bytes'] / 1e3:.1f} | {d['migrated']:.1f} |")
    return "\n".join(lines), table


def comm3d():
    """Part 3 (COMM3D=1): the same counts for the three-dimensional consolidating layer
    (cases/consolidation_layer_3d.toml, quasi-static u-p, fixed-stress split) on n^3 cells, per step
    and per Krylov iteration, steps 6-10 (Delta t = 2e-4 s for steps 4-6, 4e-4 s for 7-9, 8e-4 s for
    the tenth)."""
    lines = ["| n | ranks | unknowns | points per rank | Krylov / Newton | PETSc messages / rank / Krylov | "
             "PETSc kB / rank / Krylov | PETSc reductions / Krylov | porompm collectives / step |", "|" + "---|" * 9]
    table = []
    for n in [13, 21, 29]:
        for ranks in (2, 4):
            runs = []
            for steps, duration in [(5, 7e-4), (10, 2.9e-3)]:
                case = ("cases/consolidation_layer_3d.toml", ["--set", f"parameters.n={n}", "--set",
                        f"stages.consolidation.duration={duration}", "--set", "output.fields_every=0"])
                s, c = counts((n, n), ranks, duration, case, "fieldsplit-fixed-stress")
                if s["steps"] != steps:
                    sys.exit(f"bench-scaling: {steps} steps expected, {s['steps']} taken")
                runs.append((s, c))
            (_, a), (s10, b) = runs
            d = {k: b[k] - a[k] for k in a}
            row = {"n": n, "ranks": ranks, "dofs": s10["dofs"], "points_per_rank": s10["particles"] / ranks,
                   "krylov_per_newton": d["krylov"] / d["newton"],
                   **{f"{k}_per_krylov": d[k] / d["krylov"] for k in ("messages", "bytes", "reductions")},
                   "own_calls_per_step": d["own_calls"] / 5}
            table.append(row)
            lines.append(f"| {n} | {ranks} | {s10['dofs']} | {row['points_per_rank']:.0f} | "
                         f"{row['krylov_per_newton']:.1f} | {row['messages_per_krylov']:.1f} | "
                         f"{row['bytes_per_krylov'] / 1e3:.0f} | {row['reductions_per_krylov']:.1f} | "
                         f"{row['own_calls_per_step']:.0f} |")
    return "\n".join(lines), table


def main():
    os.makedirs(OUT, exist_ok=True)
    text, result = "", {}
    if STRONG:
        text, result["strong"] = strong()
        print(text, flush=True)
    if COMM:
        ctext, comm_rows = comm()
        print("\n" + ctext)
        text += ("\n\nCommunication per step (fieldsplit-schur-amg, -log_view, steps 6-10; 4 ranks oversubscribe "
                 "2 cores):\n\n" + ctext)
        result["comm"] = comm_rows
    if os.environ.get("COMM3D", "0") != "0":
        ctext, result["comm3d"] = comm3d()
        print("\n" + ctext)
        text += "\n\nCommunication per Krylov iteration, three-dimensional u-p layer (fieldsplit-fixed-stress):\n\n" + ctext
    open(os.path.join(OUT, "scaling.md"), "w").write(text + "\n")
    json.dump(result, open(os.path.join(OUT, "scaling.json"), "w"), indent=1)


if __name__ == "__main__":
    sys.exit(main())
