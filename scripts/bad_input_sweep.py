#!/usr/bin/env python3
"""A sweep of bad inputs (run from the repository root: `python3 scripts/bad_input_sweep.py`): each is run with `porompm check` (and `run` where the fault shows only at
run time), classified as clear (non-zero exit, one `error:` line naming the key/flag), silent (exit 0),
panic, backtrace/PETSc internals, or hang (timeout)."""
import subprocess, sys, json, os, shutil
BIN = sys.argv[1] if len(sys.argv) > 1 else "./target/release/porompm"
os.makedirs("/tmp/badsweep", exist_ok=True)
cases = {
 "terzaghi": "cases/terzaghi.toml", "footing_sd": "cases/footing_sd.toml", "dam_break": "cases/dam_break.toml",
 "landslide_3d": "cases/landslide_3d.toml", "slope_clay": "cases/slope_clay.toml", "footing_ld": "cases/footing_ld.toml",
 "hollow_cylinder": "cases/hollow_cylinder.toml", "elastic_column": "cases/elastic_column.toml",
}
inputs = []
# Values a key takes legitimately are not bad input (a regular arrangement, an inviscid fluid).
VALID = {("footing_sd", "bodies.soil.perturbation", "0"), ("dam_break", "materials.water.model.viscosity", "0")}
# numeric keys x bad values
numeric = {
 "terzaghi": ["time.dt", "materials.soil.porosity", "materials.soil.hydraulic_conductivity", "materials.soil.model.young_modulus",
              "bodies.column.particles_per_cell", "stages.consolidation.duration", "loads.surface.traction", "grid.size", "grid.cells"],
 "footing_sd": ["parameters.h", "materials.clay.model.cohesion", "bodies.soil.perturbation", "verification.tolerance"],
 "dam_break": ["materials.water.model.viscosity" , "time.dt"],
 "landslide_3d": ["grid.cells", "bodies.0.z"],
}
bad_values = ["nan", "inf", "-1", "0", "1e300", "\"abc\"", "[]"]
for c, keys in numeric.items():
    for k in keys:
        for v in bad_values:
            if (c, k, v) not in VALID:
                inputs.append((c, [f"{k}={v}"], [], "check"))
# geometry
geo = [
 ("terzaghi", ["bodies.column.shape={rectangle={min=[0.0,0.0],max=[0.1,0.01]}}"]),
 ("terzaghi", ["bodies.column.shape={rectangle={min=[0.05,0.0],max=[0.05,1.0]}}"]),
 ("terzaghi", ["bodies.column.shape={polygon={vertices=[[0.0,0.0],[0.1,1.0],[0.1,0.0],[0.0,1.0]]}}"]),
 ("terzaghi", ["bodies.column.shape={polygon={vertices=[[0.0,0.0],[0.1,0.0],[0.1,0.0],[0.0,1.0]]}}"]),
 ("terzaghi", ["bodies.column.shape={polygon={vertices=[[0.0,0.0],[0.1,0.0]]}}"]),
 ("terzaghi", ["bodies.column.shape={rectangle={min=[0.0,0.0],max=[0.2,1.0]}}"]),
 ("terzaghi", ["bodies.column.shape={rectangle={min=[0.1,0.0],max=[0.0,1.0]}}"]),
 ("terzaghi", ["loads.surface.region={min=[0.0,0.5],max=[0.1,1.0],z=[0.0,1.0]}"]),
 ("terzaghi", ["loads.surface.region={min=[0.0,2.0],max=[0.1,3.0]}"]),
 ("terzaghi", ["probes.0.point=[0.05,1.5]"]),
 ("footing_ld", ["bodies.soil.shape={rectangle={min=[0.0,0.0],max=[5.0,5.25]}}"]),
 ("footing_ld", ["bodies.footing.shape={rectangle={min=[0.0,4.0],max=[0.5,4.5]}}"]),
 ("footing_ld", ["bodies.footing.shape={rectangle={min=[0.0,5.0],max=[0.5,5.01]}}"]),
 ("slope_clay", ["bodies.0.shape={polygon={vertices=[[0.0,0.0],[1.0,1.0],[1.0,0.0],[0.0,1.0]]}}"]),
 ("elastic_column", ["stages.1.name=self_weight"]),
 ("terzaghi", ["parameters.h=0.5"]),
 ("footing_sd", ["parameters.H=0.5"]),
 ("terzaghi", ["stages.0.loads=[\"surface\",\"surface\"]"]),
 ("terzaghi", ["grid.cells=[6000,6000]"]),
 ("landslide_3d", ["bodies.0.z=[0.5,0.1]"]),
 ("hollow_cylinder", ["loads.0.points=[[0.0,0.0]]"]),
]
for c, s in geo:
    inputs.append((c, s, [], "check"))
# run-time faults
runtime = [
 ("terzaghi", ["loads.surface.region={min=[0.0,0.0],max=[0.1,0.4]}"], []),
 ("terzaghi", [], ["--", "snes_type", "newtonls"]),
 ("terzaghi", [], ["--", "-snes_type", "newtonls", "basic"]),
 ("terzaghi", [], ["--", "-snes_type", "nonsense"]),
 ("terzaghi", [], ["--", "-pc_type", "nonsense"]),
 ("terzaghi", [], ["--", "-ksp_rtol", "abc"]),
 ("terzaghi", [], ["--", "-snes_max_it", "-5"]),
 ("terzaghi", [], ["--checkpoint-every", "-1"]),
 ("terzaghi", [], ["--checkpoint-every", "0"]),
 ("terzaghi", [], ["--threads", "0"]),
 ("terzaghi", [], ["--restart", "/nonexistent.h5"]),
 ("terzaghi", [], ["--restart", "cases/terzaghi.toml"]),
 ("terzaghi", [], ["--options-file", "/nonexistent.opts"]),
 ("terzaghi", [], ["--options-file", "cases/terzaghi.toml"]),
 ("terzaghi", [], ["--balance-threshold", "0.5"]),
 ("terzaghi", ["grid.cells=[6000,6000]"], []),
]
for c, s, a in runtime:
    inputs.append((c, s, a, "run"))
rows = []
for i, (c, sets, extra, mode) in enumerate(inputs):
    out = f"/tmp/badsweep/{i}"
    shutil.rmtree(out, ignore_errors=True)
    args = [BIN, mode, cases[c]]
    if mode == "run":
        args += ["--out", out, "--quiet"]
    for s in sets:
        args += ["--set", s]
    args += extra
    try:
        p = subprocess.run(args, capture_output=True, text=True, timeout=120)
        err, code = p.stderr, p.returncode
    except subprocess.TimeoutExpired:
        rows.append((i, c, sets + extra, "hang", "")); continue
    lines = [l for l in err.splitlines() if l.strip()]
    errors = [l for l in lines if l.startswith("error:")]
    if "panicked" in err: kind = "panic"
    elif "PETSC ERROR" in err or "stack backtrace" in err or "[0]PETSC" in err: kind = "backtrace"
    elif code == 0: kind = "silent"
    elif len(errors) == 1 and len(lines) == 1: kind = "clear"
    else: kind = "several lines"
    rows.append((i, c, sets + extra, kind, errors[0] if errors else (lines[-1] if lines else "")))
from collections import Counter
cnt = Counter(r[3] for r in rows)
print(f"{len(rows)} inputs:", dict(cnt))
for r in rows:
    if r[3] != "clear":
        print(r[3], r[1], " ".join(r[2]), "|", r[4][:200])
json.dump(rows, open("/tmp/badsweep/table.json", "w"), indent=1)
