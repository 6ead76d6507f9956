# The README's two commands: `make demo` and `make test`. Both create .venv when it is missing.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test test-fast lint results clean

# torch is installed first and alone so that nothing resolves it to a CUDA build.
$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet torch==2.13.0
	$(BIN)/python -m pip install --quiet -e '.[dev,ray,rerun]'
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/hsgplan demo --agent learned

# The whole suite, in a random order (pytest-randomly), on both cores; what CI runs. A worker
# that runs out of tests takes some of the other's (worksteal), so no core idles at the end.
test: lint
	$(BIN)/python -m pytest -q -n 2 --dist worksteal tests

# Everything but the tests marked slow: under two minutes, for the edit-test loop.
test-fast: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist worksteal -m "not slow" tests

# Every published table made again: data, three trainings of each network, the test split's
# runs, pasted into the README and docs (configs/results/plan.toml; resumes where it stopped).
results: $(STAMP)
	$(BIN)/hsgplan results --paste $(RESULTS_FLAGS)

# Style, and the layer contracts in pyproject.toml ([tool.importlinter]).
lint: $(STAMP)
	$(BIN)/ruff check hsgplan tests scripts
	$(BIN)/ruff format --check hsgplan tests scripts
	$(BIN)/lint-imports

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
