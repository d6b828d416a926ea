#!/usr/bin/env bash
# The figures of docs/stress_maps.md: porompm's own colour maps (the plots/ of each run) of K_mag on
# the rotated block for every stiffness option of [001], and of σ_m and K_mag on the vertical cut
# with regular MPM, with DM-GC and with DM-G's double-mapped force and strain. Writes
# docs/figures/*.png; about three minutes on two cores.
# Usage: scripts/stress_maps.sh [path/to/porompm] (default target/release/porompm).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-target/release/porompm}
out=$(mktemp -d)
fig=docs/figures
mkdir -p "$fig"
run() { # NAME CASE ARGS...: runs quietly, keeps the plots, stops on failure
    local name=$1 case=$2
    shift 2
    "$bin" run "$case" --out "$out/$name" --quiet "$@"
}
# K_mag / K_FE on the block turned by 20° ([001] §6, Fig. 20; cases/rotated_stiffness.toml).
for option in particle:linear w_star:linear gauss_mapping:linear double_mapping:linear \
    particle:gimp double_mapping_gimp:gimp; do
    stiffness=${option%%:*} basis=${option##*:}
    run "rot-$stiffness-$basis" cases/rotated_stiffness.toml \
        --set stabilisation.stiffness="$stiffness" --set analysis.shape_functions="$basis"
    cp "$out/rot-$stiffness-$basis/plots/k_mag_ratio.png" "$fig/rotated_k_mag_${stiffness}_${basis}.png"
done
# The vertical cut ([001] §7.2; cases/vertical_cut.toml) to 0.1 m of toe displacement with [001]'s
# one linear solve per step: regular MPM (GIMP, the points' stiffness) and DM-GC (DM-G stiffness,
# CMPM recovery); and regular MPM with Newton to 1.0 m.
short=(--set verification.stop_displacement=0.1 --set "verification.snapshots=[0.1]")
run cut-mpm-ksponly cases/vertical_cut.toml "${short[@]}" -- -snes_type ksponly
run cut-dmgc-ksponly cases/vertical_cut.toml "${short[@]}" --set stabilisation.stiffness=double_mapping_gimp \
    --set stabilisation.stress_recovery=cmpm -- -snes_type ksponly
run cut-mpm-newton cases/vertical_cut.toml
# DM-G with the double-mapped force and strain, Newton on its exact tangent, to 1.0 m.
run cut-pair-newton cases/vertical_cut.toml --set stabilisation.stiffness=double_mapping_gimp \
    --set stabilisation.internal_force=mapped --set stabilisation.stress_recovery=mapped \
    --set stabilisation.mapped_stiffness=diagnostics
for m in sigma_m k_mag; do
    cp "$out/cut-mpm-ksponly/plots/${m}_toe_0.1m.png" "$fig/cut_${m}_mpm_one_solve_0.1m.png"
    cp "$out/cut-dmgc-ksponly/plots/${m}_toe_0.1m.png" "$fig/cut_${m}_dmgc_one_solve_0.1m.png"
    cp "$out/cut-mpm-newton/plots/${m}_toe_1m.png" "$fig/cut_${m}_mpm_newton_1m.png"
    cp "$out/cut-pair-newton/plots/${m}_toe_1m.png" "$fig/cut_${m}_mapped_pair_newton_1m.png"
done
for d in "$out"/cut-*; do
    echo "$(basename "$d"): $(python3 -c "import json,sys; s=json.load(open(sys.argv[1])); r=s['results']; print(s['status'], {k: round(v, 4) for k, v in r.items() if 'roughness' in k or 'toe_' in k or 'checker' in k}, round(s['wall_time_s'], 1), 's')" "$d/summary.json")"
done
rm -rf "$out"
