# The two commands of the README: `make run` and `make test`. Each sets up what it needs on a
# fresh machine (a virtual environment in .venv, the Python dependencies, the Rust build) and
# is quick the second time (stamps; cargo and maturin rebuild only what changed).

PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
OUT    ?= out
RUST_SRC := $(shell find crates -name '*.rs' -o -name 'Cargo.toml' -o -name '*.toml' | sort) Cargo.toml

.PHONY: run test test-rust test-python docs build reproduce bench bench-quick fuzz elliptic-refs rigid-body-refs capytaine-box capytaine-hulls clean

run: $(VENV)/.built
	$(BIN)/phsplit simulate --out $(OUT)

test: test-rust test-python docs

test-rust:
	cargo test -p phsplit-core -p phsplit-fmu --release

test-python: $(VENV)/.built
	$(BIN)/python -m pytest -q python/tests

build: $(VENV)/.built

# The documentation site (mkdocs.yml; docs/about.md), built strictly into site/: any warning,
# broken link or failing example fails it. Every example of the pages runs in the build, with
# the package of .venv and its `phsplit` command.
$(VENV)/.docs-deps: $(VENV)/.deps python/requirements-docs.txt
	$(BIN)/python -m pip install --quiet -r python/requirements-docs.txt
	touch $@

docs: $(VENV)/.built $(VENV)/.docs-deps
	PATH=$(abspath $(BIN)):$$PATH NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --quiet

$(VENV)/.deps: python/requirements-dev.txt
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -r python/requirements-dev.txt
	touch $@

# The FMU's binary (crates/phsplit-fmu, no Python inside) is shipped in the package, next to
# the extension module, for `phsplit fmu export` (docs/fmu.md).
FMU_BIN := python/src/phsplit/_fmu/binaries/linux64/phsplit_fmu.so

$(VENV)/.built: $(VENV)/.deps $(RUST_SRC) python/pyproject.toml
	cargo build -p phsplit-fmu --release
	mkdir -p $(dir $(FMU_BIN)) && cp target/release/libphsplit_fmu.so $(FMU_BIN)
	cd python && VIRTUAL_ENV=$(abspath $(VENV)) PATH=$(abspath $(BIN)):$$PATH $(abspath $(BIN))/maturin develop --release --quiet
	touch $@

# The paper's §4: Figs. 2-4, the stability sweep and a report, in reproduction/.
reproduce: $(VENV)/.built
	$(BIN)/phsplit reproduce --out reproduction

# Benchmarks (not part of `make test`): criterion micro-benchmarks of the core, then the
# work-precision / stability / memory study against scipy and SUNDIALS CVODE, written to
# benchmarks/results/ (CSV, Markdown summary, plots).
$(VENV)/.bench-deps: $(VENV)/.deps benchmarks/requirements.txt
	$(BIN)/python -m pip install --quiet -r benchmarks/requirements.txt
	touch $@

bench: $(VENV)/.built $(VENV)/.bench-deps
	cargo bench -p phsplit-core --bench flows
	$(BIN)/python benchmarks/work_precision.py
	$(BIN)/python benchmarks/workloads.py
	$(BIN)/python benchmarks/energy_accuracy.py
	PHSPLIT_BENCH_PROJECT=1 $(BIN)/python benchmarks/work_precision.py --out benchmarks/results/projected
	$(BIN)/python benchmarks/sweep_throughput.py
	$(BIN)/python benchmarks/sweep_throughput.py --linear-flow exact
	$(BIN)/python benchmarks/weather_stability.py
	$(BIN)/python benchmarks/general_vessel.py
	$(BIN)/python benchmarks/fmu_speed.py
	$(BIN)/python benchmarks/pipe_moordyn.py
	$(BIN)/python benchmarks/pipe_vs_moordyn.py

bench-quick: $(VENV)/.built $(VENV)/.bench-deps
	$(BIN)/python benchmarks/work_precision.py --quick --out benchmarks/results-quick

# Fuzz the input parsers for a minute (not part of `make test`; hypothesis covers them there).
FUZZ_SECONDS ?= 60
fuzz: $(VENV)/.built
	$(BIN)/python -m pip install --quiet -r fuzz/requirements.txt
	mkdir -p fuzz/corpus-run && cp -n fuzz/corpus/* fuzz/corpus-run/ 2>/dev/null || true
	$(BIN)/python fuzz/fuzz_inputs.py -max_total_time=$(FUZZ_SECONDS) fuzz/corpus-run

# Regenerate the mpmath reference table of the elliptic functions (checked in).
elliptic-refs: $(VENV)/.deps
	$(BIN)/python scripts/gen_elliptic_refs.py

# The mpmath table for the free rigid body (minutes; the table is committed).
rigid-body-refs: $(VENV)/.deps
	$(BIN)/python scripts/gen_rigid_body_refs.py

# The Capytaine datasets (recomputed, about a minute): the tests' box barge
# (python/tests/data/box_barge_capytaine.nc, and box_barge_capytaine_cg.nc about its centre of
# gravity) and dp-weather's box (python/src/phsplit/scenarios/paper_box_capytaine.nc), with
# Capytaine 3.x (3.0.0 when made) in its own environment: it is not a dependency of phsplit
# (docs/hydrodynamic-data.md).
capytaine-box:
	test -x .venv-capytaine/bin/python || $(PYTHON) -m venv .venv-capytaine
	.venv-capytaine/bin/python -m pip install --quiet "capytaine>=3,<4"
	.venv-capytaine/bin/python scripts/gen_capytaine_box.py

# Hydrodynamic data of a ship-like hull fitted to the osv preset
# (python/src/phsplit/scenarios/osv_capytaine.nc) and the peer RAO of the preset computed by
# Capytaine (python/tests/data/osv_capytaine_rao.nc): scripts/gen_capytaine_hulls.py.
capytaine-hulls:
	test -x .venv-capytaine/bin/python || $(PYTHON) -m venv .venv-capytaine
	.venv-capytaine/bin/python -m pip install --quiet "capytaine>=3,<4"
	.venv-capytaine/bin/python scripts/gen_capytaine_hulls.py

clean:
	rm -rf $(VENV) target $(OUT)
