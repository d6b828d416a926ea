#!/usr/bin/env bash
# Installs what porompm needs on Debian 12, and nothing that is already there (idempotent).
#   Debian packages: PETSc 3.18 (petsc-dev: MUMPS, hypre, SuperLU_dist, SuiteSparse inside), OpenMPI,
#   HDF5 (OpenMPI build: the one PETSc links, used by porompm's fields.h5 and checkpoint.h5 through
#   hdf5-metno), clang/libclang for bindgen, pkg-config, the serial OpenBLAS (Debian's reference
#   BLAS is several times slower inside the direct solvers), for the PNG plots (plotters' text
#   through font-kit) the fontconfig and FreeType development files and the DejaVu fonts, and
#   ParaView with its Python (`pvbatch`), with which the tests read fields.xdmf back, and SciPy for
#   the study script scripts/schur_spectrum.py.
#   Rust: cargo and rustc through rustup, if no cargo is found.
# Run as root or with sudo available.
set -euo pipefail

packages=(petsc-dev libopenmpi-dev openmpi-bin libhdf5-openmpi-dev clang libclang-dev pkg-config xvfb
          libopenblas0-serial libfontconfig1-dev libfreetype-dev fonts-dejavu-core
          make git ca-certificates curl paraview python3-paraview python3-scipy)
missing=()
for p in "${packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$p")
    fi
done
if [ ${#missing[@]} -gt 0 ]; then
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then
        command -v sudo >/dev/null || { echo "setup: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
        sudo="sudo"
    fi
    echo "setup: installing ${missing[*]}"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if ! command -v cargo >/dev/null && [ ! -x "$HOME/.cargo/bin/cargo" ]; then
    echo "setup: installing the Rust toolchain with rustup"
    curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal >/dev/null
fi
