#!/usr/bin/env python3
"""`make bench`: the peer footing benchmark (cases/footing_peer.toml, issue «Analysis types»).

Runs the case RUNS times on 1 rank and on 2 ranks (this machine has 2 cores), one run at a time,
and prints the median wall time, the peak resident memory (rank 0's, and the sum over the ranks
read from each rank's /proc at the end), the Newton iterations, the settlements at q = 3c and 4c
and the time split of summary.json. Writes target/bench/footing_peer.md.
"""
import json, os, statistics, subprocess, sys

RUNS = int(os.environ.get("RUNS", "3"))
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXE = os.path.join(ROOT, "target", "release", "porompm")
CASE = os.environ.get("CASE", "cases/footing_peer.toml")
SETS = [a for s in os.environ.get("SETS", "").split() for a in ("--set", s)]


def run(ranks, k):
    out = os.path.join(ROOT, "target", "bench", f"footing_peer-{ranks}r-{k}")
    cmd = [EXE, "run", CASE, "--out", out, "--quiet"] + SETS
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    if ranks > 1:
        cmd = ["mpirun", "--oversubscribe", "-n", str(ranks)] + cmd
    subprocess.run(cmd, cwd=ROOT, check=True, env=env)
    return json.load(open(os.path.join(out, "summary.json")))


def main():
    rows = []
    for ranks in (1, 2):
        runs = [run(ranks, k) for k in range(RUNS)]
        med = sorted(runs, key=lambda s: s["wall_time_s"])[len(runs) // 2]
        t = med["timings"]
        rows.append((ranks, statistics.median(s["wall_time_s"] for s in runs), med, t,
                     [round(s["wall_time_s"], 2) for s in runs]))
    lines = ["| ranks | wall time [s] (median; all) | peak memory [MiB] rank 0 / all ranks | Newton | "
             "d(3c) [mm] | d(4c) [mm] | kernels+assembly [s] | linear solve [s] | step setup [s] | particle update [s] |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for ranks, wall, s, t, alls in rows:
        r = s["results"]
        lines.append(
            f"| {ranks} | {wall:.2f} ({', '.join(map(str, alls))}) | {s['peak_memory_mib']:.0f} / "
            f"{s.get('peak_memory_total_mib', s['peak_memory_mib']):.0f} | {s['snes_iterations']} | "
            f"{1e3 * r['settlement_at_qc3']:.2f} | {1e3 * r['settlement_at_qc4']:.2f} | {t['assembly_s']:.2f} | "
            f"{t['linear_solve_s']:.2f} | {t['step_setup_s']:.2f} | {t['particle_update_s']:.2f} |")
    text = "\n".join(lines)
    print(text)
    os.makedirs(os.path.join(ROOT, "target", "bench"), exist_ok=True)
    open(os.path.join(ROOT, "target", "bench", "footing_peer.md"), "w").write(text + "\n")


if __name__ == "__main__":
    sys.exit(main())
