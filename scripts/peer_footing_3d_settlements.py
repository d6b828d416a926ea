#!/usr/bin/env python3
# usage: peer_footing_3d_settlements.py casedir (written by peer_footing_3d_input.py) -> JSON: per output file (index j: load j/N qmax) centre, corner and mean settlement of loaded points
import h5py, glob, re, sys, json, numpy as np
d = sys.argv[1]
m = json.load(open(f"{d}/meta.json")); h = m["h"]; W = m["W"]
under = np.array(json.load(open(f"{d}/entity_sets.json"))["particle_sets"][0]["set"])
pts = np.loadtxt(f"{d}/particles.txt", skiprows=1)
near = lambda p: int(np.argmin(((pts - np.array(p)) ** 2).sum(1)))
centre = near([h / 4, W - h / 4, h / 4]); corner = near([0.5 - h / 4, W - h / 4, 0.5 - h / 4])
rows = []
for fn in sorted(glob.glob(f"{d}/results/footing/*particles*.h5"), key=lambda s: int(re.findall(r"(\d+)\.h5$", s)[0])):
    j = int(re.findall(r"(\d+)\.h5$", fn)[0])
    t = h5py.File(fn)["table"][:]
    ids = t["id"]; uy = t["displacement_y"]
    qc = m["qmax"] * j / m["nsteps"] / 1e4
    rows.append(dict(file=j, qc=qc, centre_mm=-1e3 * float(uy[ids == centre][0]), corner_mm=-1e3 * float(uy[ids == corner][0]),
                     mean_mm=-1e3 * float(uy[np.isin(ids, under)].mean()), sig_yy_mean_kPa=-1e-3 * float(t["stress_yy"][np.isin(ids, under)].mean())))
print(json.dumps({"centre_id": centre, "corner_id": corner, "rows": rows}))
