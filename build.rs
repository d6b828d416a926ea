//! Embeds the git revision and the PETSc version and packages (from `petsc-sys`'s `links`
//! metadata) so that `porompm --version` prints them.

use std::process::Command;

fn main() {
    let rev = Command::new("git")
        .args(["describe", "--always", "--dirty", "--exclude", "*"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=POROMPM_GIT_REV={rev}");
    println!("cargo:rerun-if-changed=.git/HEAD");
    println!("cargo:rerun-if-changed=.git/index");
    let version = std::env::var("DEP_PETSC_VERSION").unwrap_or_else(|_| "unknown".into());
    let packages: Vec<&str> = ["mumps", "hypre", "superlu_dist", "suitesparse", "hdf5"]
        .into_iter()
        .filter(|p| std::env::var(format!("DEP_PETSC_{}", p.to_uppercase())).as_deref() == Ok("1"))
        .collect();
    println!("cargo:rustc-env=POROMPM_PETSC_VERSION={version}");
    println!("cargo:rustc-env=POROMPM_PETSC_PACKAGES={}", packages.join(", "));
}
