# Every target sets itself up on a fresh machine: it creates .venv and installs what it needs.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
SPECS  := $(wildcard specs/*.yaml)
DEMO   ?= specs/residential-house.yaml
OUT    ?= out

.DEFAULT_GOAL := help
.PHONY: help install demo test lint format bench schema clean

help: ## Show the targets
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | awk 'BEGIN {FS = ":.*## "}; {printf "  make %-8s %s\n", $$1, $$2}'

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test,lint]'
	touch $(STAMP)

install: $(STAMP) ## Create .venv and install facadecli with its test and lint tools

demo: $(STAMP) ## Validate the example specs and preview the words of one into out/
	$(BIN)/facade validate $(SPECS)
	mkdir -p $(OUT)
	$(BIN)/facade words $(DEMO) | tee $(OUT)/$(notdir $(DEMO:.yaml=.words.txt))
	$(BIN)/facade schema --output $(OUT)/facade.schema.json
	@echo "demo outputs are in $(OUT)/"

test: $(STAMP) ## Run the whole test suite
	$(BIN)/python -m pytest

lint: $(STAMP) ## ruff (lint + format check) and mypy
	$(BIN)/ruff check facadecli tests
	$(BIN)/ruff format --check facadecli tests
	$(BIN)/mypy

format: $(STAMP) ## Reformat the code with ruff
	$(BIN)/ruff check --fix facadecli tests
	$(BIN)/ruff format facadecli tests

bench: $(STAMP) ## Time spec loading and word enumeration (benchmarks are not tests)
	$(BIN)/python tests/benchmarks/bench.py

schema: $(STAMP) ## Regenerate specs/facade.schema.json
	$(BIN)/facade schema --output specs/facade.schema.json

clean: ## Remove the venv, caches and outputs
	rm -rf $(VENV) $(OUT) .pytest_cache .mypy_cache .ruff_cache .hypothesis
