# Everything the project needs is installed by this file into .venv (a fresh machine has none of it).
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: setup run test test-slow mutate lint figures benchmark clean view-check corpus

setup: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e ".[dev]"
	touch $(STAMP)

# Real CNC programs for the tests (tests/data/gcode/SOURCES.md): the example programs a PyPI package ships, taken
# from its wheel at install time (never committed).
CORPUS := $(VENV)/gcode-corpus
corpus: $(CORPUS)/.extracted

$(CORPUS)/.extracted: $(STAMP)
	$(BIN)/pip download --quiet --no-deps --dest $(CORPUS) carvera-controller-community==2026.8.22
	$(BIN)/python -c "import zipfile, glob; z = zipfile.ZipFile(glob.glob('$(CORPUS)/*.whl')[0]); \
	[z.extract(n, '$(CORPUS)') for n in z.namelist() if n.startswith('carveracontroller/gcodes/') \
	or n.endswith(('LICENSE', 'NOTICE', 'METADATA'))]"
	touch $@

run: setup
	$(BIN)/designopt run configs/milling.yaml

# One pytest worker per core (pytest-xdist; a worker that runs dry takes tests from the other): the suite's long
# end-to-end runs are single-threaded (on 2 cores 0.67x the wall of one worker: docs/benchmarks.md).
test: setup corpus
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -n auto --dist worksteal

# The hypothesis fuzz of every config and CSV toolpath at >= 500 cases (see docs/testing.md).
test-slow: setup
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -m slow

# Plausible bugs applied one at a time in a temporary copy; every one must make a test fail.
mutate: setup corpus
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
