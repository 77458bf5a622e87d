# Every target sets itself up on a fresh machine: it creates .venv and installs what it needs.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
SPECS  := $(wildcard specs/*.yaml)
DEMO   ?= specs/residential-house.yaml
OUT    ?= out
VALIDATOR := $(VENV)/node/node_modules/gltf-validator
CESIUM    := $(VENV)/node/node_modules/cesium

.DEFAULT_GOAL := help
.PHONY: help install demo test test-fast lint format fuzz bench bench-large schema golden grammar city pictures clean

help: ## Show the targets
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | awk 'BEGIN {FS = ":.*## "}; {printf "  make %-9s %s\n", $$1, $$2}'

# the searches are compiled from adp.py/.pxd and network.py/.pxd: editing one reinstalls (rebuilds them)
$(STAMP): pyproject.toml setup.py facadecli/grammar/adp.py facadecli/grammar/adp.pxd facadecli/solver/network.py facadecli/solver/network.pxd
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[all,test,lint,docs]'
	touch $(STAMP)

install: $(STAMP) ## Create .venv and install facadecli with every extra and its test, lint and docs tools

demo: $(STAMP) ## Validate the example specs and solve them into out/ (report + SVG)
	$(BIN)/facade validate $(SPECS)
	$(BIN)/facade solve $(SPECS) -o $(OUT) --labels
	@echo "open $(OUT)/$(notdir $(DEMO:.yaml=.svg)) to see a façade; reports are $(OUT)/*.layout.json"

$(VALIDATOR): | $(STAMP)
	@if command -v npm >/dev/null 2>&1; then \
	  npm install --silent --no-audit --no-fund --prefix $(VENV)/node gltf-validator@2.0.0-dev.3.10; \
	else echo "npm not found: the glTF validator test will be skipped"; fi

# CesiumJS (about 40 MB to fetch, 130 MB on disk, 15-20 s): the 3D Tiles test opens a built
# city's tileset in it, in headless Chromium, and checks where on the globe it stands
$(CESIUM): | $(VALIDATOR)
	@if command -v npm >/dev/null 2>&1; then \
	  npm install --silent --no-audit --no-fund --prefix $(VENV)/node cesium@1.145.0; \
	else echo "npm not found: the CesiumJS test will be skipped"; fi

# the tests on every core (pytest-xdist), a test file to a worker: a fixture a file's tests
# share (a city built once) is built once; TEST_JOBS=0 runs them in this one process
TEST_JOBS ?= logical
TEST_PARALLEL := -n $(TEST_JOBS) --dist loadfile

test: $(STAMP) $(VALIDATOR) $(CESIUM) ## Run the whole test suite (and name its 25 slowest steps)
	$(BIN)/python -m pytest $(TEST_PARALLEL) --durations=25

test-fast: $(STAMP) ## Run the tests not marked slow (under a minute; make test runs them all)
	$(BIN)/python -m pytest $(TEST_PARALLEL) -m "not slow"

lint: $(STAMP) ## ruff (lint + format check) and mypy
	$(BIN)/ruff check facadecli tests docs
	$(BIN)/ruff format --check facadecli tests docs
	$(BIN)/mypy

FUZZ_JOBS ?= 1
fuzz: $(STAMP) ## Fuzz every door (tests/fuzz/*_doors.py), 1,000 cases a door, and print the tally
	$(BIN)/python tests/fuzz/run.py --cases 1000 --jobs $(FUZZ_JOBS)

format: $(STAMP) ## Reformat the code with ruff
	$(BIN)/ruff check --fix facadecli tests
	$(BIN)/ruff format facadecli tests

bench: $(STAMP) ## Time solving the examples, a 24-layer façade, grammar extraction on CMP, cities, infer on CMP (its fidelity to the annotation, its spec at other sizes), and watch from save to page
	$(BIN)/python tests/benchmarks/bench.py
	$(BIN)/python tests/benchmarks/solver_bench.py
	$(BIN)/python tests/benchmarks/grammar_bench.py
	$(BIN)/python tests/benchmarks/city_bench.py
	$(BIN)/python tests/benchmarks/assets_bench.py
	$(BIN)/python tests/benchmarks/tiles_bench.py
	$(BIN)/python tests/benchmarks/walls_bench.py
	$(BIN)/python tests/benchmarks/infer_bench.py
	$(BIN)/python tests/benchmarks/fidelity_bench.py
	$(BIN)/python tests/benchmarks/retarget_bench.py
	$(BIN)/python tests/benchmarks/kinds_bench.py
	$(BIN)/python tests/benchmarks/variations_bench.py
	$(BIN)/python tests/benchmarks/watch_bench.py

bench-large: $(STAMP) ## Time facade grammar on three large generated layouts, and facade city on a generated town of FACADE_BENCH_N buildings (default 100,000: hours; its planning memory first, FACADE_BENCH_PLAN_ONLY=1 stops there; FACADE_BENCH_FORMAT=osm|pbf|gpkg|shp writes the town in that format)
	$(BIN)/python tests/benchmarks/grammar_large_bench.py
	$(BIN)/python tests/benchmarks/city_large_bench.py

schema: $(STAMP) ## Regenerate specs/facade.schema.json
	$(BIN)/facade schema --output specs/facade.schema.json

CITY ?=
SIZE ?= 15x15
grammar: $(STAMP) ## A split grammar of a solved façade, or LAYOUT=file (CMP .xml: SIZE=15x15 its size), and new sizes
	@if [ -z "$(LAYOUT)" ]; then \
	  $(BIN)/facade solve specs/townhouse.yaml -o $(OUT)/grammar --format json && \
	  $(BIN)/facade grammar $(OUT)/grammar/townhouse.layout.json -o $(OUT)/grammar --derive 14x15 --derive 6x9; \
	else $(BIN)/facade grammar $(LAYOUT) -o $(OUT)/grammar $(if $(filter %.xml,$(LAYOUT)),--size $(SIZE)) \
	  --derive 24x15 --derive 15x22.5; fi

city: $(STAMP) ## Build a city: the generated demo district, or CITY=path/to/manifest.yaml
	@if [ -z "$(CITY)" ]; then \
	  $(BIN)/python -c "from pathlib import Path; from facadecli.city.demo import write_demo; write_demo(Path('$(OUT)/city-demo'), Path('specs'))" && \
	  $(BIN)/facade city $(OUT)/city-demo/district.yaml -o $(OUT)/city; \
	else $(BIN)/facade city $(CITY) -o $(OUT)/city; fi

golden: $(STAMP) ## Regenerate the golden SVG elevations of the examples (tests/cases/golden)
	$(BIN)/python tests/golden.py

pictures: $(STAMP) $(CESIUM) ## Render the README's pictures into docs/pictures (needs chromium; installs npm cesium for the 3D Tiles one)
	$(BIN)/python docs/pictures.py

.PHONY: docs
docs: $(STAMP) ## Build the documentation site strictly into site/ (installs the docs extra)
	test -x $(BIN)/mkdocs || $(BIN)/python -m pip install --quiet -e '.[docs]'
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir site

clean: ## Remove the venv, caches and outputs
	rm -rf $(VENV) $(OUT) .pytest_cache .mypy_cache .ruff_cache .hypothesis
