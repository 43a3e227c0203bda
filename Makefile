# facetraj — `make run` opens the app on data_samples/, `make test` runs the whole suite.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
XVFB   := $(if $(DISPLAY),,xvfb-run -a -s "-screen 0 1600x1200x24")

.PHONY: run test lint bench fuzz monkey corpus report clean dist check-install

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip

# both distributions from this checkout, editable: the engine (pyproject.toml) and the app
# (packaging/app); the first install takes a minute or two (the libraries, PyQt6 and VTK among them),
# so pip is not quietened: its lines and download bars are the install's progress (issue 38)
APP := packaging/app
$(VENV)/.installed-run: pyproject.toml $(APP)/pyproject.toml $(APP)/setup.py | $(BIN)/python
	@echo "facetraj: installing the engine and the app into $(VENV) (a minute or two the first time; pip shows each package)"
	$(BIN)/pip install --progress-bar on -e . -e $(APP)
	touch $@

# the tests include the corpus generator's bit-for-bit reproduction check, hence the corpus extra
$(VENV)/.installed-test: pyproject.toml $(APP)/pyproject.toml $(APP)/setup.py | $(BIN)/python
	@echo "facetraj: installing the engine, the app and the test tools into $(VENV) (a few minutes the first time; pip shows each package)"
	$(BIN)/pip install --progress-bar on -e ".[test,corpus]" -e $(APP)
	touch $@ $(VENV)/.installed-run $(VENV)/.installed-corpus

$(VENV)/.installed-corpus: pyproject.toml | $(BIN)/python
	@echo "facetraj: installing the corpus generator's libraries into $(VENV)"
	$(BIN)/pip install --progress-bar on -e ".[test,corpus]"
	touch $@

run: $(VENV)/.installed-run
	$(BIN)/facetraj gui data_samples

lint: $(VENV)/.installed-test
	$(BIN)/ruff check .

test: lint
	$(XVFB) $(BIN)/python -m pytest

bench: $(VENV)/.installed-test
	$(XVFB) $(BIN)/python -m benchmarks

# the long bad-input fuzz run (tests/fuzzing.py): thousands of mutated inputs through the command
# line (each in a forked child with a memory limit and a timeout, without a display) and the app
# (a real window, under xvfb-run when there is no display); prints a table per category
# (docs/bad-input.md)
FUZZ_CASES ?= 3300
FUZZ_SEED  ?= 14
fuzz: $(VENV)/.installed-test
	$(XVFB) $(BIN)/python tests/fuzzing.py --cases $(FUZZ_CASES) --seed $(FUZZ_SEED)

# the monkey test (tests/test_monkey_gui.py) for longer than make test runs it, with a new seed each
# time (FACETRAJ_MONKEY_SEED=<seed> replays a run): random sequences of the window's own actions
MONKEY_SECONDS ?= 600
monkey: $(VENV)/.installed-test
	$(XVFB) env FACETRAJ_MONKEY_SECONDS=$(MONKEY_SECONDS) $(BIN)/python -m pytest -q -p no:cacheprovider tests/test_monkey_gui.py

corpus: $(VENV)/.installed-corpus
	$(BIN)/facetraj corpus build data_samples

# every screenshot of the docs (docs/figures/), on a screen big enough for the 1920x1080 window;
# the results figures come from `make report`
figures: $(VENV)/.installed-test
	$(if $(DISPLAY),,xvfb-run -a -s "-screen 0 2000x1400x24") $(BIN)/python -m facetraj_app.gallery docs/figures
	$(BIN)/python docs/figures/make_corpus_figures.py

report: $(VENV)/.installed-test
	$(BIN)/facetraj report data_samples -o docs

# the two wheels and their sdists (docs/install.md): dist/facetraj_engine-*, dist/facetraj-*
dist: $(VENV)/.installed-test
	rm -rf dist
	$(BIN)/python -m build -o dist .
	$(BIN)/python -m build -o dist $(APP)

# both wheels installed into fresh environments (only pip) and used outside the checkout
check-install: $(VENV)/.installed-test
	$(BIN)/python packaging/check_install.py

clean:
	rm -rf $(VENV) build dist packaging/engine/*.egg-info $(APP)/build $(APP)/src/*.egg-info .pytest_cache .ruff_cache
