# Two commands on a fresh machine: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test setup clean

setup: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e '.[test]'
	touch $(STAMP)

# The main demo. Until a mission demo exists: validate every plan in plans/
# and render each plan tree as text and Graphviz dot (SVG too when Graphviz is installed).
demo: $(STAMP)
	$(BIN)/alica validate plans/
	$(BIN)/alica show plans/lunar/mission.yaml
	$(BIN)/alica show plans/blocksworld/mission.yaml
	$(BIN)/alica render plans/ --out build/plans

test: $(STAMP)
	$(BIN)/python -m pytest

clean:
	rm -rf $(VENV) build
