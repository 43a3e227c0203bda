# facetraj — `make run` opens the app on data_samples/, `make test` runs the whole suite.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
XVFB   := $(if $(DISPLAY),,xvfb-run -a -s "-screen 0 1600x1200x24")

.PHONY: run test lint bench fuzz corpus report clean kernels

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip

$(VENV)/.installed-run: pyproject.toml | $(BIN)/python
	$(BIN)/pip install -q -e .
	touch $@

# the compiled kernels built ahead of time for this machine (engine/method/aot.py; about 15 s),
# again whenever their fingerprint (engine/method/prebuilt.py: sources, processor) says they are
# stale; without them numba compiles or loads its kernels in every process that uses them
kernels: $(VENV)/.installed-run
	@$(BIN)/python -m facetraj_engine.method.aot || \
	  echo "facetraj: prebuilt kernels not built (no C compiler?): numba's just-in-time ones will run"

# the tests include the corpus generator's bit-for-bit reproduction check, hence the corpus extra
$(VENV)/.installed-test: pyproject.toml | $(BIN)/python
	$(BIN)/pip install -q -e ".[test,corpus]"
	touch $@ $(VENV)/.installed-run $(VENV)/.installed-corpus

$(VENV)/.installed-corpus: pyproject.toml | $(BIN)/python
	$(BIN)/pip install -q -e ".[test,corpus]"
	touch $@

run: $(VENV)/.installed-run kernels
	$(BIN)/facetraj gui data_samples

lint: $(VENV)/.installed-test
	$(BIN)/ruff check .

test: lint kernels
	$(XVFB) $(BIN)/python -m pytest

bench: $(VENV)/.installed-test kernels
	$(XVFB) $(BIN)/python -m benchmarks

# the long bad-input fuzz run (tests/fuzzing.py): thousands of mutated inputs through the command
# line (each in a forked child with a memory limit and a timeout, without a display) and the app
# (a real window, under xvfb-run when there is no display); prints a table per category
# (docs/bad-input.md)
FUZZ_CASES ?= 3300
FUZZ_SEED  ?= 14
fuzz: $(VENV)/.installed-test kernels
	$(XVFB) $(BIN)/python tests/fuzzing.py --cases $(FUZZ_CASES) --seed $(FUZZ_SEED)

corpus: $(VENV)/.installed-corpus
	$(BIN)/facetraj corpus build data_samples

# every screenshot of the docs (docs/figures/), on a screen big enough for the 1920x1080 window;
# the results figures come from `make report`
figures: $(VENV)/.installed-test
	$(if $(DISPLAY),,xvfb-run -a -s "-screen 0 2000x1400x24") $(BIN)/python -m facetraj_app.gallery docs/figures
	$(BIN)/python docs/figures/make_corpus_figures.py

report: $(VENV)/.installed-test
	$(BIN)/facetraj report data_samples -o docs

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .ruff_cache engine/method/_kernels_aot.*
