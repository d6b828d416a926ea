# porompm: the two commands of the README are `make run` and `make test`; both set up what is missing.
SHELL := /bin/bash
export PATH := $(HOME)/.cargo/bin:$(PATH)

CASE ?= cases/terzaghi.toml
OUT  ?= out/terzaghi

.PHONY: setup build run test study gold lint clean

setup:
	@bash scripts/setup.sh

build: setup
	cargo build --release --locked

# Runs the default case (Terzaghi consolidation) into out/terzaghi.
run: build
	./target/release/porompm run $(CASE) --out $(OUT)

# The whole test suite (unit, PETSc smoke, CLI and MPI, verification against analytical solutions).
test: setup
	cargo test --release --locked

# Long convergence studies (tables in target/studies/).
study: build
	cargo test --release --locked --test studies --test gold -- --ignored --nocapture --test-threads=1

# Rewrites the gold values of every case (cases/gold/*.json) from fresh runs; review the diff.
gold: setup
	PORO_GOLD_REFRESH=1 cargo test --release --locked --test gold

lint:
	cargo fmt --check
	cargo clippy --release --all-targets --locked -- -D warnings

clean:
	cargo clean
	rm -rf out
