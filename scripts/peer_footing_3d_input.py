#!/usr/bin/env python3
"""3D flexible square footing (quarter model) for geomechanics/mpm (implicit, ED3H8, P3DBBAR).
Same geometry as porompm's tests/cases/footing_square_3d.toml: h = B/(2k+1), B = 1 m, soil cube of
(3k+2) cells, two empty layers above (y vertical), 2x2x2 points per cell at the quarter points.
Load: uniform traction on the top faces of the top layer of points with x, z < B/2 (quarter footing),
ramped so that step s (0-based) carries (s+1)/N of qmax (N = nsteps: like porompm's dt = 1/N).
Rollers on x=0, x=W, z=0, z=W (normal fixed); base y=0 fixed.
usage: peer_footing_3d_input.py outdir k material(MC|LE) nsteps qmax[Pa] E[Pa] output_steps
(cases/footing_peer_3d.toml at k: `peer_footing_3d_input.py DIR k MC 40 4.0e4 1.0e8 10`; the peer then
runs `mpm -f DIR/ -i mpm.json`, and peer_footing_3d_settlements.py DIR reads its settlements)"""
import json, sys, os
out, k, mat = sys.argv[1], int(sys.argv[2]), sys.argv[3]
nsteps, qmax, E, every = int(sys.argv[4]), float(sys.argv[5]), float(sys.argv[6]), int(sys.argv[7])
B = 1.0
h = B / (2 * k + 1)
n = 3 * k + 2                       # soil cells per direction
nx, ny, nz = n, n + 2, n
W = n * h
os.makedirs(out, exist_ok=True)
nid = lambda i, j, l: l * (nx + 1) * (ny + 1) + j * (nx + 1) + i
with open(f"{out}/mesh.txt", "w") as f:
    f.write("! elementShape hexahedron\n! elementNumPoints 8\n")
    f.write(f"{(nx+1)*(ny+1)*(nz+1)}\t{nx*ny*nz}\n")
    for l in range(nz + 1):
        for j in range(ny + 1):
            for i in range(nx + 1):
                f.write(f"{i*h:.12g}\t{j*h:.12g}\t{l*h:.12g}\n")
    for l in range(nz):
        for j in range(ny):
            for i in range(nx):
                f.write("\t".join(str(v) for v in (
                    nid(i, j, l), nid(i+1, j, l), nid(i+1, j+1, l), nid(i, j+1, l),
                    nid(i, j, l+1), nid(i+1, j, l+1), nid(i+1, j+1, l+1), nid(i, j+1, l+1))) + "\n")
pts = []
for l in range(n):
    for j in range(n):
        for i in range(n):
            for c in (0.25, 0.75):
                for b in (0.25, 0.75):
                    for a in (0.25, 0.75):
                        pts.append(((i + a) * h, (j + b) * h, (l + c) * h))
with open(f"{out}/particles.txt", "w") as f:
    f.write(f"{len(pts)}\n")
    for x, y, z in pts:
        f.write(f"{x:.12g}\t{y:.12g}\t{z:.12g}\n")
R = range
xmin = [nid(0, j, l) for l in R(nz + 1) for j in R(ny + 1)]
xmax = [nid(nx, j, l) for l in R(nz + 1) for j in R(ny + 1)]
ymin = [nid(i, 0, l) for l in R(nz + 1) for i in R(nx + 1)]
zmin = [nid(i, j, 0) for j in R(ny + 1) for i in R(nx + 1)]
zmax = [nid(i, j, nz) for j in R(ny + 1) for i in R(nx + 1)]
under = [p for p, (x, y, z) in enumerate(pts) if x < B / 2 and z < B / 2 and y > W - 0.5 * h]
centre = min(range(len(pts)), key=lambda p: (pts[p][0] - h/4)**2 + (pts[p][1] - (W - h/4))**2 + (pts[p][2] - h/4)**2)
json.dump({"node_sets": [{"id": 0, "set": xmin}, {"id": 1, "set": xmax}, {"id": 2, "set": ymin},
                         {"id": 3, "set": zmin}, {"id": 4, "set": zmax}],
           "particle_sets": [{"id": 1, "set": under}]}, open(f"{out}/entity_sets.json", "w"))
json.dump({"k": k, "h": h, "W": W, "qmax": qmax, "nsteps": nsteps, "npoints": len(pts),
           "under": len(under), "centre_id": centre, "centre": pts[centre], "every": every},
          open(f"{out}/meta.json", "w"))
if mat == "MC":
    material = {"id": 0, "type": "MohrCoulomb3D", "density": 1800.0,
                "youngs_modulus": E, "poisson_ratio": 0.3, "softening": False,
                "friction": 0.0, "dilation": 0.0, "cohesion": 1.0e4,
                "residual_friction": 0.0, "residual_dilation": 0.0,
                "residual_cohesion": 1.0e4, "peak_pdstrain": 0.0,
                "residual_pdstrain": 0.0, "tension_cutoff": 1.0e5}
else:
    material = {"id": 0, "type": "LinearElastic3D", "density": 1800.0,
                "youngs_modulus": E, "poisson_ratio": 0.3}
lin = {"dof": "displacement", "solver_type": "DirectEigen", "sub_solver_type": "lu",
       "preconditioner_type": "none", "max_iter": 5000, "tolerance": 1e-10, "verbosity": 0}
dt = 0.01
cfg = {
  "title": "square footing implicit 3D",
  "mesh": {"mesh": "mesh.txt", "entity_sets": "entity_sets.json", "io_type": "Ascii3D",
           "check_duplicates": False, "isoparametric": False, "node_type": "N3D",
           "cell_type": "ED3H8",
           "boundary_conditions": {"displacement_constraints": [
               {"nset_id": 0, "dir": 0, "displacement": 0.0},
               {"nset_id": 1, "dir": 0, "displacement": 0.0},
               {"nset_id": 2, "dir": 0, "displacement": 0.0},
               {"nset_id": 2, "dir": 1, "displacement": 0.0},
               {"nset_id": 2, "dir": 2, "displacement": 0.0},
               {"nset_id": 3, "dir": 2, "displacement": 0.0},
               {"nset_id": 4, "dir": 2, "displacement": 0.0},
               ]}},
  "particles": [{"generator": {"type": "file", "material_id": [0], "pset_id": 0,
                 "io_type": "Ascii3D", "particle_type": "P3DBBAR",
                 "check_duplicates": False, "location": "particles.txt"}}],
  "materials": [material],
  "external_loading_conditions": {"gravity": [0.0, 0.0, 0.0],
      "particle_surface_traction": [{"pset_id": 1, "dir": 1, "traction": -qmax, "math_function_id": 0}]},
  # step s (t = s dt) carries (s+1)/N of the load
  "math_functions": [{"id": 0, "type": "Linear", "xvalues": [-dt, (nsteps - 1) * dt, 1e6],
                      "fxvalues": [0.0, 1.0, 1.0]}],
  "analysis": {"type": "MPMImplicit3D", "mpm_scheme": "newmark",
               "scheme_settings": {"nonlinear": True, "quasi_static": True,
                                   "beta": 0.25, "gamma": 0.5, "max_iteration": 30,
                                   "displacement_tolerance": 1e-10,
                                   "residual_tolerance": 1e-10,
                                   "relative_residual_tolerance": 1e-6,
                                   "verbosity": 1},
               "locate_particles": True, "pressure_smoothing": False,
               "dt": dt, "nsteps": nsteps, "uuid": "footing",
               "resume": {"resume": False, "uuid": "footing", "step": 0},
               "linear_solver": {"assembler_type": "EigenImplicit3D", "solver_settings": [lin]}},
  "post_processing": {"path": "results/", "output_steps": every}}
json.dump(cfg, open(f"{out}/mpm.json", "w"), indent=1)
print(f"k {k} h {h:.5f} cells {nx*ny*nz} (soil {n**3}), nodes {(nx+1)*(ny+1)*(nz+1)}, particles {len(pts)}, "
      f"loaded particles {len(under)} (area {len(under)*(h/2)**2:.4f} m2), centre id {centre} at {pts[centre]}")
