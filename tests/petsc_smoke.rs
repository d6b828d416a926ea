//! PETSc smoke tests of the safe layer, run in one process (PETSc and MPI can be initialised only
//! once per process, so this file is its own harness).
//!
//! * every `.opts` file in `petsc_options/` assembles and solves a small symmetric indefinite
//!   five-field system on a DMDA (same layout as the u-p-U problem) through SNES, and the solution
//!   matches the manufactured one;
//! * SNES solves a small nonlinear system with a hand-coded tangent that agrees with a
//!   finite-difference Jacobian, and converges quadratically;
//! * errors from PETSc, from callbacks and from panics in callbacks come back as `Err` with a message;
//!   a domain error ends the solve as diverged; unused options are reported.

mod common;

use petsc::ksp::KspOps;
use petsc::mat::MatOps;
use petsc::snes::NonlinearProblem;
use petsc::{BlockOps, CallbackError, Comm, DmDa, IndexSet, Mat, MatRef, Options, Petsc, Snes, VecOps, VecRef, Vector};
use std::path::{Path, PathBuf};

type TestResult = Result<(), String>;
type TestFn = fn() -> TestResult;

fn e<T: std::fmt::Display>(x: T) -> String {
    x.to_string()
}

/// A linear five-field system `A x = b` on a DMDA: Laplacian + identity on the fields 0,1,3,4,
/// minus a small mass on field 2, coupled symmetrically to field 0. Symmetric indefinite.
struct SaddleSystem<'a> {
    dm: &'a DmDa,
    rhs: Vec<f64>,
}

impl SaddleSystem<'_> {
    fn assemble(&self, a: &mut dyn MatOps) -> Result<(), petsc::Error> {
        let info = *self.dm.info();
        let g = info.ghosted;
        let [nx, ny] = info.nodes;
        for j in info.owned_start[1]..info.owned_start[1] + info.owned_count[1] {
            for i in info.owned_start[0]..info.owned_start[0] + info.owned_count[0] {
                let row_node = g.node(i, j).unwrap();
                for f in 0..5 {
                    let r = (row_node * 5 + f) as i32;
                    if f == 2 {
                        a.set_values_local(&[r], &[r], &[-0.05], true)?;
                        let c = (row_node * 5) as i32;
                        a.set_values_local(&[r], &[c], &[0.3], true)?;
                        a.set_values_local(&[c], &[r], &[0.3], true)?;
                        continue;
                    }
                    a.set_values_local(&[r], &[r], &[5.0], true)?;
                    let nbrs = [(i.wrapping_sub(1), j), (i + 1, j), (i, j.wrapping_sub(1)), (i, j + 1)];
                    for (ni, nj) in nbrs {
                        if ni < nx && nj < ny {
                            let c = (g.node(ni, nj).unwrap() * 5 + f) as i32;
                            a.set_values_local(&[r], &[c], &[-1.0], true)?;
                        }
                    }
                }
            }
        }
        a.assemble()
    }
}

impl NonlinearProblem for SaddleSystem<'_> {
    fn residual(&mut self, x: &VecRef, f: &mut VecRef) -> Result<(), CallbackError> {
        // F(x) = A x - b, with A applied through a freshly assembled matrix (keeps the test simple).
        let mut a = self.dm.create_matrix().map_err(|e| CallbackError::Fatal(e.to_string()))?;
        self.assemble(&mut a).map_err(|e| CallbackError::Fatal(e.to_string()))?;
        a.mult(x, f).map_err(|e| CallbackError::Fatal(e.to_string()))?;
        let mut fa = f.write().map_err(|e| CallbackError::Fatal(e.to_string()))?;
        for (fi, bi) in fa.iter_mut().zip(&self.rhs) {
            *fi -= bi;
        }
        Ok(())
    }

    fn jacobian(&mut self, _x: &VecRef, j: &mut MatRef, _p: Option<&mut MatRef>) -> Result<(), CallbackError> {
        j.zero_entries().map_err(|e| CallbackError::Fatal(e.to_string()))?;
        self.assemble(j).map_err(|e| CallbackError::Fatal(e.to_string()))?;
        Ok(())
    }
}

/// As porompm does (`assembly::splits`): a field split gets the splits `u` (ux, uy, Ux, Uy; block
/// size 4) and `p`, by index sets.
fn define_splits(snes: &mut Snes, dm: &DmDa, comm: Comm) -> TestResult {
    let mut ksp = snes.ksp().map_err(e)?;
    let mut pc = ksp.pc().map_err(e)?;
    if pc.type_name().map_err(e)? != "fieldsplit" {
        return Ok(());
    }
    let v = dm.create_global_vector().map_err(e)?;
    let (lo, hi) = v.ownership_range().map_err(e)?;
    let pick = |cs: &[usize]| -> Vec<petsc::Int> {
        (lo..hi).filter(|q| cs.contains(&((q - lo) % 5))).map(|q| q as petsc::Int).collect()
    };
    let mut u = IndexSet::new_general(comm, &pick(&[0, 1, 3, 4])).map_err(e)?;
    u.set_block_size(4).map_err(e)?;
    let p = IndexSet::new_general(comm, &pick(&[2])).map_err(e)?;
    pc.field_split_set_is("u", &u).map_err(e)?;
    pc.field_split_set_is("p", &p).map_err(e)?;
    Ok(())
}

fn solve_with_options_file(path: &Path) -> TestResult {
    let comm = Comm::world();
    let mut opts = Options::new().map_err(e)?;
    opts.insert_file(comm, path).map_err(e)?;
    opts.push().map_err(e)?;
    let dm = DmDa::new_2d(comm, [6, 5], 1, &["ux", "uy", "p", "Ux", "Uy"]).map_err(e)?;
    // Manufactured solution and right-hand side b = A x*.
    let mut a = dm.create_matrix().map_err(e)?;
    let sys0 = SaddleSystem { dm: &dm, rhs: Vec::new() };
    sys0.assemble(&mut a).map_err(e)?;
    let mut xstar = dm.create_global_vector().map_err(e)?;
    {
        let (lo, _) = xstar.ownership_range().map_err(e)?;
        let mut w = xstar.write().map_err(e)?;
        for (k, v) in w.iter_mut().enumerate() {
            *v = ((lo + k) as f64 * 0.37).sin() + 0.1;
        }
    }
    let mut b = dm.create_global_vector().map_err(e)?;
    a.mult(&xstar, &mut b).map_err(e)?;
    let rhs = b.read().map_err(e)?.to_vec();
    let mut problem = SaddleSystem { dm: &dm, rhs };

    let mut snes = Snes::new(comm).map_err(e)?;
    snes.set_dm(&dm).map_err(e)?;
    // Defaults in code (as the application does), then the options file on top.
    {
        let mut ksp = snes.ksp().map_err(e)?;
        ksp.set_type("preonly").map_err(e)?;
        ksp.pc().map_err(e)?.set_type("lu").map_err(e)?;
    }
    snes.set_tolerances(None, Some(1e-10), None, Some(50)).map_err(e)?;
    snes.set_from_options().map_err(e)?;
    define_splits(&mut snes, &dm, comm)?;
    let mut x = dm.create_global_vector().map_err(e)?;
    x.set_all(0.0).map_err(e)?;
    let mut jac = dm.create_matrix().map_err(e)?;
    let out = snes.solve(&mut x, &mut jac, None, &mut problem).map_err(e)?;
    if !out.converged {
        return Err(format!("SNES did not converge: {}", out.reason_text));
    }
    x.axpy(-1.0, &xstar).map_err(e)?;
    let err = x.norm2().map_err(e)? / xstar.norm2().map_err(e)?;
    if err > 1e-7 {
        return Err(format!("solution error {err:.3e} > 1e-7"));
    }
    // porompm's own options (`-porompm_…`) are read by the application, not by PETSc's objects.
    let unused: Vec<_> = opts.unused().map_err(e)?.into_iter().filter(|o| !o.name.starts_with("porompm_")).collect();
    drop(snes);
    opts.pop().map_err(e)?;
    if !unused.is_empty() {
        return Err(format!(
            "options not used: {}",
            unused.iter().map(|o| o.to_string()).collect::<Vec<_>>().join(" ")
        ));
    }
    println!(
        "    {}: rel. error {err:.2e}, {} Newton, {} Krylov iterations",
        path.display(),
        out.iterations,
        out.linear_iterations
    );
    Ok(())
}

fn every_options_file_solves_the_saddle_system() -> TestResult {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("petsc_options");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map_err(e)?
        .flatten()
        .map(|d| d.path())
        .filter(|p| p.extension().is_some_and(|x| x == "opts"))
        .collect();
    files.sort();
    if files.len() < 5 {
        return Err(format!("expected at least five .opts files in {}, found {}", dir.display(), files.len()));
    }
    for f in files {
        solve_with_options_file(&f).map_err(|m| format!("{}: {m}", f.display()))?;
    }
    Ok(())
}

/// F_i(x) = x_i^3 + (L x)_i - b_i with L the 1D Laplacian: a small nonlinear system.
struct Cubic {
    n: usize,
    b: Vec<f64>,
    calls: usize,
    mode: Mode,
}

#[derive(Clone, Copy, PartialEq)]
enum Mode {
    Normal,
    Fatal,
    Panic,
    Domain,
    /// The tangent's entries are all zero (the same nonzero pattern): a singular matrix.
    Singular,
}

impl Cubic {
    fn eval(&self, x: &[f64]) -> Vec<f64> {
        (0..self.n)
            .map(|i| {
                let mut lx = 2.0 * x[i];
                if i > 0 {
                    lx -= x[i - 1];
                }
                if i + 1 < self.n {
                    lx -= x[i + 1];
                }
                x[i].powi(3) + lx - self.b[i]
            })
            .collect()
    }

    fn tangent(&self, x: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut j = vec![0.0; n * n];
        for i in 0..n {
            j[i * n + i] = 3.0 * x[i] * x[i] + 2.0;
            if i > 0 {
                j[i * n + i - 1] = -1.0;
            }
            if i + 1 < n {
                j[i * n + i + 1] = -1.0;
            }
        }
        j
    }
}

impl NonlinearProblem for Cubic {
    fn residual(&mut self, x: &VecRef, f: &mut VecRef) -> Result<(), CallbackError> {
        self.calls += 1;
        match self.mode {
            Mode::Fatal => return Err(CallbackError::Fatal("the residual refuses".into())),
            Mode::Panic => panic!("deliberate panic in a residual callback"),
            Mode::Domain => return Err(CallbackError::Domain("volume became negative".into())),
            Mode::Normal | Mode::Singular => {}
        }
        let xv = x.read().map_err(|e| CallbackError::Fatal(e.to_string()))?.to_vec();
        let r = self.eval(&xv);
        f.write().map_err(|e| CallbackError::Fatal(e.to_string()))?.copy_from_slice(&r);
        Ok(())
    }

    fn jacobian(&mut self, x: &VecRef, j: &mut MatRef, _p: Option<&mut MatRef>) -> Result<(), CallbackError> {
        let xv = x.read().map_err(|e| CallbackError::Fatal(e.to_string()))?.to_vec();
        let mut t = self.tangent(&xv);
        if self.mode == Mode::Singular {
            t.fill(0.0);
        }
        let idx: Vec<i32> = (0..self.n as i32).collect();
        j.zero_entries().map_err(|e| CallbackError::Fatal(e.to_string()))?;
        j.set_values(&idx, &idx, &t, false).map_err(|e| CallbackError::Fatal(e.to_string()))?;
        j.assemble().map_err(|e| CallbackError::Fatal(e.to_string()))
    }
}

fn dense_matrix(n: usize) -> Result<Mat, petsc::Error> {
    let nnz = vec![n as i32; n];
    Mat::new_aij(Comm::self_(), n, n, &nnz, &vec![0; n])
}

fn snes_self(problem: &mut Cubic) -> Result<petsc::SolveOutcome, petsc::Error> {
    let mut snes = Snes::new(Comm::self_())?;
    snes.set_prefix("cubic_")?;
    {
        let mut ksp = snes.ksp()?;
        ksp.set_type("preonly")?;
        ksp.pc()?.set_type("lu")?;
    }
    snes.set_tolerances(Some(1e-14), Some(1e-12), Some(0.0), Some(30))?;
    snes.set_from_options()?;
    let mut x = Vector::from_slice(&vec![0.5; problem.n])?;
    let mut j = dense_matrix(problem.n)?;
    snes.solve(&mut x, &mut j, None, problem)
}

/// A Newton solve whose MUMPS factorisation fails (a singular Jacobian) ends as diverged, and the
/// next solve with the same SNES and the same nonzero pattern converges: PETSc 3.18's MUMPS
/// interface would otherwise skip that factorisation and fail hard in the solve (INFOG(1) = −3),
/// which `Snes::solve` prevents by dropping the failed factors (`forget_failed_factorisation`).
fn a_failed_mumps_factorisation_leaves_the_next_solve_free() -> TestResult {
    let n = 6;
    let mut snes = Snes::new(Comm::self_()).map_err(e)?;
    {
        let mut ksp = snes.ksp().map_err(e)?;
        ksp.set_type("preonly").map_err(e)?;
        let mut pc = ksp.pc().map_err(e)?;
        pc.set_type("lu").map_err(e)?;
        pc.set_factor_solver_type("mumps").map_err(e)?;
    }
    snes.set_tolerances(Some(1e-12), Some(1e-10), Some(0.0), Some(30)).map_err(e)?;
    let mut j = dense_matrix(n).map_err(e)?;
    let mut solve = |mode| {
        let mut p = Cubic { n, b: vec![1.0; n], calls: 0, mode };
        let mut x = Vector::from_slice(&vec![0.5; n])?;
        snes.solve(&mut x, &mut j, None, &mut p)
    };
    let first = solve(Mode::Singular).map_err(e)?;
    if first.converged || first.reason_text != "DIVERGED_LINEAR_SOLVE" {
        return Err(format!("a singular Jacobian gave {}", first.reason_text));
    }
    let second = solve(Mode::Normal).map_err(|err| format!("the solve after the failed factorisation: {err}"))?;
    if !second.converged {
        return Err(format!("the regular solve after the singular one: {}", second.reason_text));
    }
    println!("    singular: {}; then {} in {} iterations", first.reason_text, second.reason_text, second.iterations);
    Ok(())
}

/// After a solve the solver holds its matrix, and its preconditioner what it built from it;
/// `Snes::release_operators` lets go of both for a factorisation and for GAMG (whose levels PETSc
/// 3.18's `PCReset` would keep, with their old sizes), so that the matrix has no holder but its
/// handle and the next solve, with a matrix and vectors of another size, builds everything anew.
/// A field split keeps its splits and everything else: nothing is released.
fn releasing_the_operators_frees_the_matrix_and_the_next_solve_builds_anew() -> TestResult {
    for (pc_type, ksp_type) in [("lu", "preonly"), ("gamg", "gmres"), ("fieldsplit", "gmres")] {
        let mut snes = Snes::new(Comm::self_()).map_err(e)?;
        snes.set_prefix(&format!("release_{pc_type}_")).map_err(e)?;
        {
            let mut ksp = snes.ksp().map_err(e)?;
            ksp.set_type(ksp_type).map_err(e)?;
            ksp.pc().map_err(e)?.set_type(pc_type).map_err(e)?;
        }
        snes.set_tolerances(Some(1e-12), Some(1e-10), Some(0.0), Some(30)).map_err(e)?;
        snes.set_from_options().map_err(e)?;
        let sizes: &[usize] = if pc_type == "fieldsplit" { &[40] } else { &[200, 300] };
        for &n in sizes {
            let mut j = dense_matrix(n).map_err(e)?;
            if pc_type == "fieldsplit" {
                let mut ksp = snes.ksp().map_err(e)?;
                let mut pc = ksp.pc().map_err(e)?;
                let halves = [(0..n as i32 / 2).collect::<Vec<_>>(), (n as i32 / 2..n as i32).collect()];
                for (name, rows) in ["a", "b"].into_iter().zip(halves) {
                    pc.field_split_set_is(name, &IndexSet::new_general(Comm::self_(), &rows).map_err(e)?).map_err(e)?;
                }
            }
            let mut p = Cubic { n, b: vec![1.0; n], calls: 0, mode: Mode::Normal };
            let mut x = Vector::from_slice(&vec![0.5; n]).map_err(e)?;
            let out = snes.solve(&mut x, &mut j, None, &mut p).map_err(|err| format!("{pc_type}, n = {n}: {err}"))?;
            if !out.converged {
                return Err(format!("{pc_type}, n = {n}: {}", out.reason_text));
            }
            let held = j.holders().map_err(e)?;
            if held < 2 {
                return Err(format!("{pc_type}: the solver does not hold its matrix after a solve ({held} holder)"));
            }
            let released = snes.release_operators().map_err(e)?;
            let after = j.holders().map_err(e)?;
            match (pc_type, released, after) {
                ("fieldsplit", false, a) if a == held => {}
                ("lu" | "gamg", true, 1) => {}
                _ => {
                    return Err(format!(
                        "{pc_type}, n = {n}: release_operators gave {released}, the matrix has {after} holders \
                         after it ({held} before)"
                    ))
                }
            }
            println!("    {pc_type}, n = {n}: {} Newton iterations; holders {held} → {after}", out.iterations);
        }
    }
    Ok(())
}

fn hand_tangent_matches_finite_differences_and_newton_is_quadratic() -> TestResult {
    let n = 8;
    let mut p = Cubic { n, b: (0..n).map(|i| 1.0 + 0.3 * i as f64).collect(), calls: 0, mode: Mode::Normal };
    // Central finite differences of the residual at a generic point, column by column.
    let x0: Vec<f64> = (0..n).map(|i| 0.2 + 0.1 * (i as f64).cos()).collect();
    let t = p.tangent(&x0);
    let h = 1e-6;
    let mut max_err: f64 = 0.0;
    for c in 0..n {
        let (mut xp, mut xm) = (x0.clone(), x0.clone());
        xp[c] += h;
        xm[c] -= h;
        let (fp, fm) = (p.eval(&xp), p.eval(&xm));
        for r in 0..n {
            let fd = (fp[r] - fm[r]) / (2.0 * h);
            max_err = max_err.max((fd - t[r * n + c]).abs());
        }
    }
    if max_err > 1e-7 {
        return Err(format!("tangent differs from finite differences by {max_err:.3e}"));
    }
    let out = snes_self(&mut p).map_err(e)?;
    if !out.converged {
        return Err(format!("Newton did not converge: {}", out.reason_text));
    }
    let h = &out.residual_history;
    // Quadratic convergence: in the last iterations log(r_{k+1}) ~ 2 log(r_k) (ratio r_{k+1}/r_k^2 bounded).
    let k = h.len();
    if k < 4 {
        return Err(format!("expected several Newton iterations, history {h:?}"));
    }
    let rate = (h[k - 2] / h[k - 3]).ln() / (h[k - 3] / h[k - 4]).ln();
    if rate < 1.8 {
        return Err(format!("Newton convergence order {rate:.2} < 1.8 (history {h:?})"));
    }
    println!("    FD tangent error {max_err:.1e}; Newton history {:?}; observed order {rate:.2}", h);
    Ok(())
}

fn callback_errors_panics_and_domain_errors_are_reported() -> TestResult {
    let n = 4;
    let mk = |mode| Cubic { n, b: vec![1.0; n], calls: 0, mode };
    match snes_self(&mut mk(Mode::Fatal)) {
        Err(err) if err.message.contains("the residual refuses") => {}
        other => return Err(format!("fatal callback error not reported: {:?}", other.map(|o| o.reason_text))),
    }
    // Silence the default hook's message for the deliberate panic.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let r = snes_self(&mut mk(Mode::Panic));
    std::panic::set_hook(hook);
    match r {
        Err(err) if err.message.contains("panicked") && err.message.contains("deliberate panic") => {}
        other => return Err(format!("panic in callback not reported: {:?}", other.map(|o| o.reason_text))),
    }
    match snes_self(&mut mk(Mode::Domain)) {
        Ok(out) if !out.converged && out.domain_error.as_deref() == Some("volume became negative") => {}
        other => {
            return Err(format!(
                "domain error not reported as divergence: {:?}",
                other.map(|o| (o.converged, o.reason_text))
            ))
        }
    }
    Ok(())
}

fn petsc_errors_carry_petsc_messages() -> TestResult {
    // Inserting outside the preallocated pattern of a matrix that forbids new nonzeros fails.
    let mut m = dense_matrix(3).map_err(e)?;
    let r = m.set_values(&[7], &[0], &[1.0], false);
    match r {
        Err(err) if err.message.contains("MatSetValues") || err.message.to_lowercase().contains("out of range") => {
            println!("    PETSc error reported as: {}", err.message);
            Ok(())
        }
        Err(err) => Err(format!("unexpected message: {}", err.message)),
        Ok(()) => Err("out-of-range insertion was accepted".into()),
    }
}

fn unused_options_are_reported() -> TestResult {
    let mut opts = Options::new().map_err(e)?;
    opts.insert_string("-snes_rtol 1e-9 -this_option_does_not_exist 3").map_err(e)?;
    opts.push().map_err(e)?;
    let mut p = Cubic { n: 3, b: vec![1.0; 3], calls: 0, mode: Mode::Normal };
    let mut snes = Snes::new(Comm::self_()).map_err(e)?;
    snes.set_from_options().map_err(e)?;
    let mut x = Vector::from_slice(&[0.0; 3]).map_err(e)?;
    let mut j = dense_matrix(3).map_err(e)?;
    snes.solve(&mut x, &mut j, None, &mut p).map_err(e)?;
    // porompm's own options (`-porompm_…`) are read by the application, not by PETSc's objects.
    let unused: Vec<_> = opts.unused().map_err(e)?.into_iter().filter(|o| !o.name.starts_with("porompm_")).collect();
    drop(snes);
    opts.pop().map_err(e)?;
    let names: Vec<String> = unused.iter().map(|o| o.name.clone()).collect();
    if names != ["this_option_does_not_exist"] {
        return Err(format!("unused options reported as {names:?}"));
    }
    Ok(())
}

/// A three-dimensional DMDA: the ranks' owned slabs cover the grid, the ghosted block's numbering
/// (x fastest, then y, then z) inverts, the ghost exchange brings every node its owner's values
/// (each global entry set to its node's number, read back through the local vector), and adding a
/// local vector of ones counts each node once per rank whose block holds it. Rank-agnostic: run
/// it on two ranks with `mpirun -n 2 PETSC_SMOKE_BINARY three_dimensional`.
fn a_three_dimensional_dmda_numbers_and_exchanges_its_nodes() -> TestResult {
    let comm = Comm::world();
    let nodes = [5usize, 4, 3];
    let dm = DmDa::new_3d(comm, nodes, 1, &["a", "b"], None).map_err(e)?;
    let info = *dm.info();
    let dof = info.dof;
    let owned: usize = info.owned_count.iter().product();
    let mut global = dm.create_global_vector().map_err(e)?;
    if global.local_size().map_err(e)? != owned * dof {
        return Err(format!("{owned} owned nodes but a local size of {}", global.local_size().map_err(e)?));
    }
    if comm.sum_usize(owned).map_err(e)? != nodes.iter().product::<usize>() {
        return Err("the owned blocks do not cover the grid".into());
    }
    let ranges = dm.ownership().map_err(e)?;
    if ranges.iter().map(|r| r.len()).product::<usize>() != comm.size()
        || ranges.iter().zip(nodes).any(|(r, n)| r.iter().sum::<usize>() != n)
    {
        return Err(format!("ownership ranges {ranges:?} do not match {} ranks and {nodes:?}", comm.size()));
    }
    let g = info.ghosted;
    let number = |n: [usize; 3]| (n[2] * nodes[1] + n[1]) * nodes[0] + n[0];
    let ltog = dm.local_to_global();
    let (mut idx, mut vals) = (Vec::new(), Vec::new());
    for l in 0..g.len() {
        let n = g.indices(l);
        if g.local(n) != Some(l) {
            return Err(format!("local node {l} is {n:?}, whose local number is {:?}", g.local(n)));
        }
        let own = (0..3).all(|d| n[d] >= info.owned_start[d] && n[d] < info.owned_start[d] + info.owned_count[d]);
        for c in 0..dof {
            if own {
                idx.push(ltog[l * dof + c]);
                vals.push((number(n) * 10 + c) as f64);
            }
        }
    }
    global.set_values(&idx, &vals, false).map_err(e)?;
    global.assemble().map_err(e)?;
    let mut local = dm.create_local_vector().map_err(e)?;
    dm.global_to_local(&global, &mut local).map_err(e)?;
    {
        let lv = local.read().map_err(e)?;
        for l in 0..g.len() {
            for c in 0..dof {
                let want = (number(g.indices(l)) * 10 + c) as f64;
                if lv[l * dof + c] != want {
                    return Err(format!(
                        "local node {l} dof {c}: {} after the exchange, {want} expected",
                        lv[l * dof + c]
                    ));
                }
            }
        }
    }
    local.set_all(1.0).map_err(e)?;
    global.set_all(0.0).map_err(e)?;
    dm.local_to_global_add(&local, &mut global).map_err(e)?;
    let mut ones = global.duplicate().map_err(e)?;
    ones.set_all(1.0).map_err(e)?;
    let total = global.dot(&ones).map_err(e)?;
    let expected = comm.sum_usize(g.len() * dof).map_err(e)? as f64;
    if total != expected {
        return Err(format!("local-to-global added {total}, the ranks' blocks hold {expected} entries"));
    }
    Ok(())
}

/// A matrix of node-pair blocks (on one rank; the gold values on two and three ranks cover the
/// blocks of rows another rank owns): preallocated from its block rows, every block lands where
/// its nodes say whatever the order it is listed in, a second fill replaces the first instead of
/// adding to it, threads filling bands of rising rows give the same matrix, and bands of falling
/// rows, a block outside the pattern or an unsorted block row are refused.
fn a_block_matrix_holds_its_blocks_where_they_belong() -> TestResult {
    let comm = Comm::world();
    if comm.size() != 1 {
        return Ok(());
    }
    let (nx, ny, bs) = (4usize, 3usize, 2usize);
    let dm = DmDa::new_2d(comm, [nx, ny], 1, &["a", "b"]).map_err(e)?;
    let n = nx * ny;
    let near = |a: usize, b: usize| (a % nx).abs_diff(b % nx) <= 1 && (a / nx).abs_diff(b / nx) <= 1;
    let (mut starts, mut cols) = (vec![0 as petsc::Int], Vec::new());
    for a in 0..n {
        cols.extend((0..n).filter(|&b| near(a, b)).map(|b| b as petsc::Int));
        starts.push(cols.len() as petsc::Int);
    }
    let mut m = dm.create_matrix_blocks(&starts, &cols).map_err(e)?;
    // The blocks listed from the last row to the first.
    let blocks: Vec<(petsc::Int, petsc::Int)> = (0..n)
        .rev()
        .flat_map(|a| (0..n).filter(move |&b| near(a, b)).map(move |b| (a as petsc::Int, b as petsc::Int)))
        .collect();
    let value = |a: usize, c: usize, b: usize, d: usize| (a * n + b) as f64 + 0.1 * c as f64 + 0.01 * d as f64;
    let values: Vec<f64> = blocks
        .iter()
        .flat_map(|&(a, b)| (0..bs * bs).map(move |k| value(a as usize, k / bs, b as usize, k % bs)))
        .collect();
    let places = m.block_places(bs, &blocks).map_err(e)?;
    m.set_blocks(&places, &values).map_err(e)?;
    m.set_blocks(&places, &values).map_err(e)?;
    let (_, dense) = m.local_rows_dense().map_err(e)?;
    for (r, row) in dense.chunks_exact(n * bs).enumerate() {
        for (q, &v) in row.iter().enumerate() {
            let (a, c, b, d) = (r / bs, r % bs, q / bs, q % bs);
            let want = if near(a, b) { value(a, c, b, d) } else { 0.0 };
            if v != want {
                return Err(format!("entry ({r}, {q}) is {v}, {want} expected"));
            }
        }
    }
    // Bands of blocks written as threads write them: the blocks listed by rising rows, cut in
    // three bands, give the same matrix; bands whose rows fall are refused.
    let rising: Vec<(petsc::Int, petsc::Int)> = blocks.iter().rev().copied().collect();
    let rising_places = m.block_places(bs, &rising).map_err(e)?;
    let third = rising.partition_point(|&(a, _)| a < (n / 3) as petsc::Int);
    let two_thirds = rising.partition_point(|&(a, _)| a < (2 * n / 3) as petsc::Int);
    let cuts = [0, third, two_thirds, rising.len()];
    m.fill_blocks(&rising_places, |fill| -> Result<(), String> {
        let bands = fill.bands(&cuts).map_err(e)?;
        std::thread::scope(|scope| {
            for (w, mut band) in cuts.windows(2).zip(bands) {
                let rising = &rising;
                scope.spawn(move || {
                    for (k, &(a, b)) in rising.iter().enumerate().take(w[1]).skip(w[0]) {
                        let (a, b) = (a as usize, b as usize);
                        for c in 0..bs {
                            for (d, v) in band.row_mut(k, c).iter_mut().enumerate() {
                                *v += value(a, c, b, d);
                            }
                        }
                    }
                });
            }
        });
        Ok(())
    })
    .map_err(e)??;
    let (_, banded) = m.local_rows_dense().map_err(e)?;
    if banded != dense {
        return Err("the banded fill differs from the listed one".into());
    }
    let falling =
        m.fill_blocks(&places, |fill| fill.bands(&[0, blocks.len() / 2, blocks.len()]).map(|b| b.len())).map_err(e)?;
    if falling.is_ok() {
        return Err("bands of falling rows were accepted".into());
    }
    match m.block_places(bs, &[(0, n as petsc::Int - 1)]) {
        Err(err) if err.to_string().contains("not in the matrix's pattern") => {}
        other => return Err(format!("a block outside the pattern was placed: {:?}", other.map(|p| p.len()))),
    }
    let mut unsorted = cols.clone();
    unsorted.swap(0, 1);
    if dm.create_matrix_blocks(&starts, &unsorted).is_ok() {
        return Err("an unsorted block row was accepted".into());
    }
    Ok(())
}

/// The tests of this file, in the order they run.
const TESTS: &[(&str, TestFn)] = &[
    ("every_options_file_solves_the_saddle_system", every_options_file_solves_the_saddle_system),
    (
        "hand_tangent_matches_finite_differences_and_newton_is_quadratic",
        hand_tangent_matches_finite_differences_and_newton_is_quadratic,
    ),
    ("callback_errors_panics_and_domain_errors_are_reported", callback_errors_panics_and_domain_errors_are_reported),
    ("petsc_errors_carry_petsc_messages", petsc_errors_carry_petsc_messages),
    (
        "a_failed_mumps_factorisation_leaves_the_next_solve_free",
        a_failed_mumps_factorisation_leaves_the_next_solve_free,
    ),
    ("unused_options_are_reported", unused_options_are_reported),
    (
        "releasing_the_operators_frees_the_matrix_and_the_next_solve_builds_anew",
        releasing_the_operators_frees_the_matrix_and_the_next_solve_builds_anew,
    ),
    (
        "a_three_dimensional_dmda_numbers_and_exchanges_its_nodes",
        a_three_dimensional_dmda_numbers_and_exchanges_its_nodes,
    ),
    ("a_block_matrix_holds_its_blocks_where_they_belong", a_block_matrix_holds_its_blocks_where_they_belong),
];

fn main() {
    let Some(chosen) = common::harness::selected(TESTS) else { return };
    let petsc = match Petsc::initialize(&[], None, "porompm PETSc smoke tests") {
        Ok(p) => p,
        Err(err) => {
            eprintln!("cannot initialise PETSc: {err}");
            std::process::exit(1);
        }
    };
    let ok = common::harness::run(&chosen, |t| t());
    drop(petsc);
    std::process::exit(if ok { 0 } else { 101 });
}
