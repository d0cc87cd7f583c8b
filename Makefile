# Two commands on a fresh machine: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
DOCS_STAMP := $(VENV)/.installed-docs

.PHONY: demo test check docs setup clean

setup: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e '.[test]'
	touch $(STAMP)

# The main demo. Until the lunar mission demo with robots exists: validate every
# plan, render the plan trees, run the lunar mission's team in simulation
# (--stand-ins: its skills have no implementation yet, so scripted stand-ins run
# them; Scout crashes and Stummel takes over the exploration), then
# the blocks-world mission in pybullet (planned at run time, real skills).
demo: $(STAMP)
	$(BIN)/alica validate plans/
	$(BIN)/alica render plans/ --out build/plans
	$(BIN)/alica run plans/lunar/mission.yaml --agents scout,stummel,amparo \
		--fact "found(a) and found(b)@5" --crash scout@2 --loss 0.1 --delay 20 \
		--seed 1 --stand-ins --trace build/lunar.jsonl
	$(BIN)/alica demo blocksworld --agents 3 --blocks 5 --seed 1 --out build/blocks

test: $(STAMP)
	$(BIN)/python tools/quality.py
	$(BIN)/python -m pytest

# The quality gates: ruff (lint, format), mypy, the import-linter layer contracts.
check: $(STAMP)
	$(BIN)/python tools/quality.py

# The documentation site (mkdocs, Material, API reference by mkdocstrings) into
# build/site/. Its tools are the `docs` extra, installed here only, so that
# `make test` does not need them.
$(DOCS_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e '.[test,docs]'
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict -d build/site

clean:
	rm -rf $(VENV) build
