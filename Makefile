# porompm: the two commands of the README are `make run` and `make test`; both set up what is missing.
SHELL := /bin/bash
export PATH := $(HOME)/.cargo/bin:$(PATH)

# The instruction set: where the processor runs x86-64-v3 (AVX2 and FMA; glibc's loader says so),
# every build targets it, so that the three-dimensional tangent's loops run four values wide (a
# Jacobian 16 % cheaper per point, docs/dimensions.md); the answers are the same to the bit, since
# Rust fuses no multiplication and addition on its own. RUSTFLAGS given by the caller win.
X86_64_V3 := $(shell /lib64/ld-linux-x86-64.so.2 --help 2>/dev/null | grep -q 'x86-64-v3 .supported' && echo yes)
ifeq ($(origin RUSTFLAGS)$(X86_64_V3),undefinedyes)
export RUSTFLAGS := -C target-cpu=x86-64-v3
endif

CASE ?= cases/terzaghi.toml
OUT  ?= out/terzaghi

.PHONY: setup build run test study study-cook study-footing study-footing-3d study-dam study-landslide gold gold-table bench bench-scaling bench-solvers study-mgr maps lint clean

setup:
	@bash scripts/setup.sh

build: setup
	cargo build --release --locked

# Runs the default case (Terzaghi consolidation) into out/terzaghi.
run: build
	./target/release/porompm run $(CASE) --out $(OUT)

# The whole test suite (unit, PETSc smoke, CLI and MPI, verification against analytical solutions),
# by cargo-nextest where it is installed (every test its own process, two at a time across all
# test files, the longest first: .config/nextest.toml), else by cargo test.
test: setup
	@if cargo nextest --version >/dev/null 2>&1; then \
		cargo nextest run --release --locked; \
	else \
		echo "cargo-nextest not found: cargo test runs the suite (one test file after the other)"; \
		cargo test --release --locked; \
	fi

# Long convergence studies (tables in target/studies/) and the long runs the default suite leaves
# out (README, "Tests and studies").
study: build
	cargo test --release --locked --test studies --test gold --test verification --test extreme --test explicit --test stiffness_options --test three_dimensions -- --ignored --nocapture --test-threads=1 --skip cook_membrane_item_13 --skip footing_fbar_item_14 --skip dam_break_item_15 --skip footing_square_3d_finest --skip landslide_item_16
	python3 scripts/terzaghi_family.py

# [002] §4.1 Cook's membrane: the tip's displacement and the stress chequerboard of F̄ and standard
# MPM with uGIMP and B-splines (eight runs on two ranks, about 7 hours; COOK_H=1 for the 1 m grid
# only, about 30 minutes).
study-cook: build
	cargo test --release --locked --test studies cook_membrane_item_13 -- --ignored --nocapture

# [002] §4.2 strip footing on Hencky–J2 clay: the bearing capacity of F̄ and standard MPM against
# Prandtl's 2 + π (nine runs on two ranks, about 80 minutes).
study-footing: build
	cargo test --release --locked --test studies footing_fbar_item_14 -- --ignored --nocapture

# [002] §4.3 dam break at the water's stiffness: hydrostatic pressure, front and pressure chequerboard
# of F̄ and standard MPM (four runs on two ranks, about 7 minutes; it reports the unmet assertions
# and fails).
study-dam: build
	cargo test --release --locked --test studies dam_break_item_15 -- --ignored --nocapture

# The square footing at the finest mesh that runs here (k = 10, ≈ 10⁵ unknowns, GAMG on two ranks,
# about 25 minutes) within 5 % of N_c = 5.91, and one against two ranks at k = 3.
study-footing-3d: build
	cargo test --release --locked --test studies footing_square_3d_finest -- --ignored --nocapture

# [002] §4.4 landslide, reconstructed (four runs on two ranks, about an hour): the run-outs of F̄ and
# standard MPM with uGIMP and B-splines, compared by their ratios (the geometry is not the paper's).
study-landslide: build
	cargo test --release --locked --test studies landslide_item_16 -- --ignored --nocapture

# Every case against its gold values, one rank: the largest relative difference of each
# (target/gold/table.md), the before/after table of a change that must not change the answers.
gold-table: setup
	cargo test --release --locked --test gold -- --ignored --nocapture every_case_against_its_gold_values_table

# Rewrites the gold values of every case (cases/gold/*.json) from fresh runs; review the diff.
gold: setup
	PORO_GOLD_REFRESH=1 cargo test --release --locked --test gold

# The peer footing benchmark (cases/footing_peer.toml) on 1 and 2 ranks, median of 3 runs each:
# wall time, peak memory, Newton iterations, settlements at q = 3c and 4c, the time split.
bench: build
	python3 scripts/bench_footing_peer.py

# Strong scaling 1 -> 2 ranks at 1.04e5 unknowns (slumping block, field split and MUMPS; median of
# RUNS=3) and the communication per step at 2 and 4 ranks for the weak-scaling model
# (target/bench/scaling.md; about 40 minutes; STRONG=0 or COMM=0 skips a part).
bench-scaling: build
	python3 scripts/bench_scaling.py

# The linear solvers from 1e4 to 1e6 unknowns on 1 and 2 ranks: the iterative field split against MUMPS
# (target/bench/solvers.md; about 90 minutes; SIZES, RANKS, STRATEGIES, RUNS, STEPS choose; docs/solvers.md).
bench-solvers: build
	python3 scripts/bench_solvers.py

# hypre's multigrid reduction (MGR, through a shell preconditioner in scripts/mgr_study.c) against
# the Schur field split on the dynamic u–p–U tangent at three grids (target/studies/mgr.md; about
# 15 minutes on one core; GRIDS and VARIANTS choose; docs/solvers.md).
study-mgr: build
	scripts/mgr_study.sh

# The colour maps of docs/stress_maps.md (docs/figures/*.png) from fresh runs; about two minutes.
maps: build
	scripts/stress_maps.sh

lint:
	cargo fmt --check
	cargo clippy --release --all-targets --locked -- -D warnings

clean:
	cargo clean
	rm -rf out
