//! Build script of `petsc-sys`.
//!
//! 1. Finds PETSc with `pkg-config` (module `PETSc`, which on Debian links `-lpetsc_real`) and the
//!    OpenMPI headers (module `ompi-c`); when something is missing it prints one message naming every
//!    missing piece and the Debian package that provides it, then stops.
//! 2. Reads `petscconf.h` and checks the configuration the safe layer relies on: `PetscInt` is 32-bit,
//!    `PetscReal` is `double` and `PetscScalar` is real.
//! 3. Records which external packages this PETSc was built with (MUMPS, hypre, SuperLU_dist,
//!    SuiteSparse, HDF5)
//!    as `cfg` flags (`petsc_have_mumps`, ...) and as `links` metadata, visible to dependants as
//!    `DEP_PETSC_MUMPS`, `DEP_PETSC_VERSION`, ...
//! 4. Generates the raw bindings with bindgen. MPI types are not generated: they are taken from
//!    rsmpi's `mpi-sys`, so that PETSc and rsmpi share one `MPI_Comm` type.

use std::env;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One piece the build needs, and the Debian package that provides it.
struct Missing {
    what: &'static str,
    package: &'static str,
}

fn pkg_config(args: &[&str]) -> Option<String> {
    let out = Command::new("pkg-config").args(args).output().ok()?;
    if out.status.success() {
        Some(String::from_utf8_lossy(&out.stdout).trim().to_string())
    } else {
        None
    }
}

fn have_pkg_config() -> bool {
    Command::new("pkg-config").arg("--version").output().map(|o| o.status.success()).unwrap_or(false)
}

/// bindgen loads libclang at run time; look where Debian's `libclang-dev` and `libclang1-*` put it.
fn have_libclang() -> bool {
    if let Ok(p) = env::var("LIBCLANG_PATH") {
        if Path::new(&p).exists() {
            return true;
        }
    }
    let mut dirs: Vec<PathBuf> = vec![PathBuf::from("/usr/lib/x86_64-linux-gnu"), PathBuf::from("/usr/lib")];
    if let Ok(rd) = std::fs::read_dir("/usr/lib") {
        for e in rd.flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            if name.starts_with("llvm-") {
                dirs.push(e.path().join("lib"));
            }
        }
    }
    dirs.iter().any(|d| {
        std::fs::read_dir(d)
            .map(|rd| rd.flatten().any(|e| e.file_name().to_string_lossy().starts_with("libclang")))
            .unwrap_or(false)
    })
}

fn include_dirs(cflags: &str) -> Vec<PathBuf> {
    cflags.split_whitespace().filter_map(|f| f.strip_prefix("-I")).map(PathBuf::from).collect()
}

fn main() {
    println!("cargo:rerun-if-changed=wrapper.h");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=PKG_CONFIG_PATH");
    for flag in
        ["petsc_have_mumps", "petsc_have_hypre", "petsc_have_superlu_dist", "petsc_have_suitesparse", "petsc_have_hdf5"]
    {
        println!("cargo:rustc-check-cfg=cfg({flag})");
    }
    let found = find();
    check_configuration(&include_dirs(&found.petsc_cflags));
    link(&found.petsc_libs);
    bindings(&found);
}

/// The compiler and linker flags of PETSc and MPI.
struct Found {
    petsc_cflags: String,
    petsc_libs: String,
    mpi_cflags: String,
}

/// Step 1: finds everything, and reports everything that is missing at once.
fn find() -> Found {
    let mut missing = Vec::new();
    let has_pc = have_pkg_config();
    if !has_pc {
        missing.push(Missing { what: "pkg-config (used to find PETSc and MPI)", package: "pkg-config" });
    }
    let petsc_cflags = if has_pc { pkg_config(&["--cflags", "PETSc"]) } else { None };
    let petsc_libs = if has_pc { pkg_config(&["--libs", "PETSc"]) } else { None };
    if has_pc && (petsc_cflags.is_none() || petsc_libs.is_none()) {
        missing
            .push(Missing { what: "PETSc 3.18 development files (pkg-config module `PETSc`)", package: "petsc-dev" });
    }
    let mpi_cflags = if has_pc { pkg_config(&["--cflags", "ompi-c"]) } else { None };
    if has_pc && mpi_cflags.is_none() {
        missing.push(Missing { what: "OpenMPI headers (pkg-config module `ompi-c`)", package: "libopenmpi-dev" });
    }
    if !have_libclang() {
        missing.push(Missing { what: "libclang (bindgen parses the PETSc headers with it)", package: "libclang-dev" });
    }
    match (petsc_cflags, petsc_libs, mpi_cflags) {
        (Some(petsc_cflags), Some(petsc_libs), Some(mpi_cflags)) if missing.is_empty() => {
            Found { petsc_cflags, petsc_libs, mpi_cflags }
        }
        _ => report_missing(&missing),
    }
}

/// Names every missing piece and its Debian package, then stops the build.
fn report_missing(missing: &[Missing]) -> ! {
    let mut msg = String::from("\n\npetsc-sys cannot be built; missing:\n");
    for m in missing {
        msg.push_str(&format!("  - {}  -> Debian package `{}`\n", m.what, m.package));
    }
    let pkgs: Vec<&str> = missing.iter().map(|m| m.package).collect();
    msg.push_str(&format!("Install them with:  apt-get install -y {}\n", pkgs.join(" ")));
    msg.push_str("(or run `make setup`, which installs every system dependency of porompm)\n\n");
    eprintln!("{msg}");
    println!("cargo:warning={}", msg.replace('\n', " "));
    std::process::exit(1);
}

/// Steps 2 and 3: checks the PETSc configuration in `petscconf.h` (in the include directories
/// `incs`), and records the version and the external packages.
fn check_configuration(incs: &[PathBuf]) {
    let conf = incs
        .iter()
        .map(|d| d.join("petscconf.h"))
        .find(|p| p.exists())
        .unwrap_or_else(|| fail(&format!("petscconf.h not found in the PETSc include directories {incs:?}")));
    let conf_text =
        std::fs::read_to_string(&conf).unwrap_or_else(|e| fail(&format!("cannot read {}: {e}", conf.display())));
    let defined = |name: &str| conf_text.lines().any(|l| l.split_whitespace().take(2).eq(["#define", name]));
    if defined("PETSC_USE_64BIT_INDICES") {
        fail("this PETSc uses 64-bit PetscInt; porompm's bindings expect the 32-bit build of Debian's petsc-dev");
    }
    if !defined("PETSC_USE_REAL_DOUBLE") {
        fail("this PETSc is not built with double-precision PetscReal; install Debian's petsc-dev (real, double)");
    }
    if defined("PETSC_USE_COMPLEX") {
        fail("this PETSc uses complex PetscScalar; porompm needs the real build (-lpetsc_real)");
    }
    println!("cargo:version={}", version(incs));
    println!("cargo:include={}", incs.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(":"));
    for (macro_name, key, cfg) in [
        ("PETSC_HAVE_MUMPS", "mumps", "petsc_have_mumps"),
        ("PETSC_HAVE_HYPRE", "hypre", "petsc_have_hypre"),
        ("PETSC_HAVE_SUPERLU_DIST", "superlu_dist", "petsc_have_superlu_dist"),
        ("PETSC_HAVE_SUITESPARSE", "suitesparse", "petsc_have_suitesparse"),
        ("PETSC_HAVE_HDF5", "hdf5", "petsc_have_hdf5"),
    ] {
        let have = defined(macro_name);
        println!("cargo:{key}={}", if have { 1 } else { 0 });
        if have {
            println!("cargo:rustc-cfg={cfg}");
        }
    }
}

/// PETSc's version from `petscversion.h` (`unknown` without it).
fn version(incs: &[PathBuf]) -> String {
    let version_h = incs.iter().map(|d| d.join("petscversion.h")).find(|p| p.exists());
    version_h
        .and_then(|p| std::fs::read_to_string(p).ok())
        .map(|t| {
            let get = |key: &str| {
                t.lines()
                    .find_map(|l| {
                        let mut w = l.split_whitespace();
                        (w.next() == Some("#define") && w.next() == Some(key))
                            .then(|| w.next().unwrap_or("?").to_string())
                    })
                    .unwrap_or_else(|| "?".into())
            };
            format!("{}.{}.{}", get("PETSC_VERSION_MAJOR"), get("PETSC_VERSION_MINOR"), get("PETSC_VERSION_SUBMINOR"))
        })
        .unwrap_or_else(|| "unknown".into())
}

/// Links PETSc with the flags `petsc_libs`.
fn link(petsc_libs: &str) {
    for flag in petsc_libs.split_whitespace() {
        if let Some(dir) = flag.strip_prefix("-L") {
            println!("cargo:rustc-link-search=native={dir}");
        } else if let Some(lib) = flag.strip_prefix("-l") {
            println!("cargo:rustc-link-lib={lib}");
        }
    }
}

/// Step 4: the raw bindings, generated by bindgen.
fn bindings(found: &Found) {
    let mut builder = bindgen::Builder::default()
        .header("wrapper.h")
        .allowlist_function("(Petsc|Vec|Mat|KSP|PC|SNES|DM|DMDA|IS|ISLocalToGlobalMapping)[A-Za-z0-9_]*")
        .allowlist_function("PETSC_VIEWER_STDOUT_")
        .allowlist_type("(Petsc|Vec|Mat|KSP|PC|SNES|DM|DMDA|IS|InsertMode|ScatterMode|NormType)[A-Za-z0-9_]*")
        .allowlist_var("(PETSC|Petsc|KSP|PC|SNES|MAT|VEC|DM)[A-Za-z0-9_]*")
        .blocklist_type("MPI_.*")
        .blocklist_type("ompi_.*")
        .blocklist_type("MPIX_.*")
        .blocklist_function("MPI_.*|PMPI_.*")
        .raw_line("#[allow(unused_imports)] pub use mpi_sys::*;")
        // Newtype enums: a value PETSc writes back can never be an invalid Rust enum.
        .default_enum_style(bindgen::EnumVariation::NewType { is_bitfield: false, is_global: false })
        .derive_default(true)
        .layout_tests(false)
        .generate_comments(false)
        .parse_callbacks(Box::new(bindgen::CargoCallbacks::new()));
    for d in include_dirs(&found.petsc_cflags).iter().chain(include_dirs(&found.mpi_cflags).iter()) {
        builder = builder.clang_arg(format!("-I{}", d.display()));
    }
    for f in found.petsc_cflags.split_whitespace().filter(|f| f.starts_with("-D")) {
        builder = builder.clang_arg(f);
    }
    let bindings = builder.generate().unwrap_or_else(|e| fail(&format!("bindgen failed on the PETSc headers: {e}")));
    let out = PathBuf::from(env::var("OUT_DIR").unwrap()).join("bindings.rs");
    bindings.write_to_file(&out).unwrap_or_else(|e| fail(&format!("cannot write {}: {e}", out.display())));
}

fn fail(msg: &str) -> ! {
    eprintln!("\n\npetsc-sys: {msg}\n");
    println!("cargo:warning=petsc-sys: {msg}");
    std::process::exit(1);
}
