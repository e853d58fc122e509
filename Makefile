# Everything the project needs is installed by this file into .venv (a fresh machine has none of it).
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: setup run test test-slow mutate lint figures benchmark clean view-check

setup: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e ".[dev]"
	touch $(STAMP)

run: setup
	$(BIN)/designopt run configs/milling.yaml

test: setup
	MPLBACKEND=Agg $(BIN)/python -m pytest -q

# The hypothesis fuzz of every config and CSV toolpath at >= 500 cases (see docs/testing.md).
test-slow: setup
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -m slow

# Plausible bugs applied one at a time in a temporary copy; every one must make a test fail.
mutate: setup
	$(BIN)/python tests/mutate.py

# The interactive view in a real browser: Debian's headless Chromium screenshots the first and last frame of
# the main job's view.html (apt-get install chromium first). Not part of `make test`.
view-check: setup
	$(BIN)/designopt run configs/milling.yaml --name view-check --out /tmp/designopt-view-check --resume
	$(BIN)/python benchmarks/view_screenshot.py /tmp/designopt-view-check/milling/view-check/view.html --out docs/figures

lint: setup
	$(BIN)/ruff check .

# Every figure and table of the paper's results section, into results/ (see docs/results.md).
# Sweeps resume: re-running `make figures` finishes an interrupted sweep instead of starting over.
figures: setup
	$(BIN)/designopt continuous configs/continuous.yaml --name paper
	$(BIN)/designopt waypoints configs/continuous.yaml --name paper
	$(BIN)/designopt sweep-structures --config configs/structures.yaml --name paper --resume
	$(BIN)/designopt sweep-structures --config configs/structures_physical.yaml --name paper --resume
	$(BIN)/designopt modular configs/modular.yaml --name paper
	$(BIN)/designopt modular-study configs/modular.yaml --name paper

benchmark: setup
	$(BIN)/python benchmarks/bench_solve.py

clean:
	rm -rf $(VENV) .pytest_cache
