#!/usr/bin/env bash
# hypre MGR against porompm's Schur field split on the dynamic u–p–U tangent (docs/solvers.md,
# "Multigrid reduction"): writes the slumping block's first tangent (one step of 1 ms, pressure
# projection on) at each grid of GRIDS, then solves each with scripts/mgr_study.c: the field split
# by component lists (selfp, GAMG on u, BoomerAMG on the Schur block, as
# petsc_options/fieldsplit-schur-amg.opts) and MGR in the variants of VARIANTS, all with FGMRES to
# 1e-8. Prints a table and writes it to target/studies/mgr.md; about 15 minutes on one core with the
# default grids (the 432 × 324 tangent needs about 4.5 GiB).
# Usage: scripts/mgr_study.sh [path/to/porompm] (default target/release/porompm).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-target/release/porompm}
grids=${GRIDS:-"64,48 216,162 432,324"}
variants=${VARIANTS:-"-mgr_scheme 1|-mgr_scheme 2|-mgr_scheme 1 -mgr_interp 12|-mgr_scheme 1 -mgr_cg 4"}
out=target/studies/mgr
mkdir -p "$out"
inc=$(pkg-config --variable=includedir PETSc)
mpicc -O2 -o "$out/mgr_study" scripts/mgr_study.c -I"$inc" -I/usr/include/hypre \
    $(pkg-config --cflags --libs PETSc) -lHYPRE -lm
split="-use_mgr 0 -pc_type fieldsplit -pc_fieldsplit_block_size 5 -pc_fieldsplit_0_fields 0,1,3,4
    -pc_fieldsplit_1_fields 2 -pc_fieldsplit_type schur -pc_fieldsplit_schur_fact_type lower
    -pc_fieldsplit_schur_precondition selfp -fieldsplit_0_ksp_type preonly -fieldsplit_0_pc_type gamg
    -fieldsplit_0_pc_gamg_agg_nsmooths 1 -fieldsplit_1_ksp_type preonly -fieldsplit_1_pc_type hypre
    -fieldsplit_1_pc_hypre_boomeramg_coarsen_type HMIS -fieldsplit_1_pc_hypre_boomeramg_interp_type ext+i
    -fieldsplit_1_pc_hypre_boomeramg_P_max 4 -fieldsplit_1_pc_hypre_boomeramg_agg_nl 1"
table=target/studies/mgr.md
echo "| grid | preconditioner | result |" > "$table"
echo "|---|---|---|" >> "$table"
for g in $grids; do
    t=${g/,/x}
    rm -rf "$out/run_$t" "$out/A_$t.bin" "$out/b_$t.bin"
    "$bin" run cases/slumping_block.toml --quiet --threads 1 --out "$out/run_$t" \
        --set stages.slump.duration=0.001 --set "grid.cells=[$g]" --set stabilisation.pressure_projection=1.0 \
        --set output.fields_every=0 --options-file petsc_options/fieldsplit-schur-amg.opts -- \
        -ksp_view_mat "binary:$out/A_$t.bin" -ksp_view_rhs "binary:$out/b_$t.bin"
    run() { # LABEL OPTIONS...
        local label=$1
        shift
        local line
        line=$("$out/mgr_study" -A "$out/A_$t.bin" -b "$out/b_$t.bin" "$@" | tail -1)
        echo "| $t | $label | $line |" | tee -a "$table"
    }
    # shellcheck disable=SC2086
    run "field split (selfp)" $split
    IFS='|' read -ra vs <<< "$variants"
    for v in "${vs[@]}"; do
        # shellcheck disable=SC2086
        run "MGR $v" $v
    done
    rm -f "$out/A_$t.bin" "$out/b_$t.bin"
done
echo "table: $table"
