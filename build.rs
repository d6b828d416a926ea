//! Embeds the git revision and the PETSc version and packages (from `petsc-sys`'s build metadata)
//! so that `porompm --version` can print them.

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
    // petsc-sys declares `links = "petsc"`, so its metadata reaches us only through the `petsc`
    // crate; read it from petsc-sys's environment if forwarded, else leave it to run time.
    let version = std::env::var("DEP_PETSC_VERSION").unwrap_or_default();
    println!("cargo:rustc-env=POROMPM_PETSC_HEADERS={version}");
}
