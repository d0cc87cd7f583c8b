# Two commands on a fresh machine: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
DOCS_STAMP := $(VENV)/.installed-docs

.PHONY: demo test test-fast check docs setup clean browser

setup: $(STAMP)

# Debian's chromium for the control center's browser tests (tests/center/test_browser.py),
# only when asked (`make browser`; CI does in .ci/run): it is a system package, outside the
# venv. Without it the browser tests are skipped and say how to get it.
browser:
	@[ -x /usr/bin/chromium ] || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium >/dev/null || echo "note: could not install chromium; the browser tests will be skipped"; \
	  else echo "note: no /usr/bin/chromium and no root to install it (apt-get install chromium); the browser tests will be skipped"; fi; }

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e '.[test]'
	touch $(STAMP)

# The main demo: validate every plan, render the plan trees, then the lunar
# mission in pybullet with the real skills (three robots explore a 40 x 40 m
# field with 60 rocks, find drill samples, the first two found are planned
# for at run time and carried to g; Scout crashes at 20 s and 10 % of the
# messages are lost; map, trace and plan in build/lunar), then the
# blocks-world mission (planned at run time, real skills).
demo: $(STAMP)
	$(BIN)/alica validate alica:plans
	$(BIN)/alica render alica:plans --out build/plans
	$(BIN)/alica demo lunar --seed 1 --crash scout@20 --loss 0.1 --out build/lunar
	$(BIN)/alica demo blocksworld --robots 3 --blocks 5 --seed 1 --out build/blocks

test: $(STAMP)
	$(BIN)/python tools/quality.py
	$(BIN)/python -m pytest

# A fast subset (about a minute): the language, the engine and the CLI, without the
# simulator, the process teams, the planners' benchmarks and the browser.
test-fast: $(STAMP)
	$(BIN)/python -m pytest tests/lang tests/model tests/io tests/engine tests/allocation tests/test_cli.py

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
