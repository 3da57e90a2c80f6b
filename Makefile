# Quick start: `make demo` and `make test`. Both create .venv if absent and install the project.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# Bytecode is cached even where the environment sets PYTHONDONTWRITEBYTECODE (install, demo and tests alike):
# without it every process (each pytest worker, each Dask worker, each command a test starts) compiles odpipe
# again, and every pytest worker rewrites the asserts of every test file.
export PYTHONDONTWRITEBYTECODE :=

.PHONY: demo test bench clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	$(BIN)/python -m odpipe.pipeline.warmup  # numba's on-disk cache, filled once per checkout
	$(BIN)/python -m tests.estimation_cases  # and the kernels of the tests' own estimation cases
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/odpipe demo

# Test files are spread over WORKERS processes, whole files per worker (module fixtures computed once),
# in tests/conftest.py's order (files with slow tests first); xdist's default would reorder them by
# their number of tests and start the long few-test files last. One BLAS thread per process, as odpipe/__init__.py
# sets for the commands: pytest has imported numpy before any test imports odpipe, so there it comes too late.
WORKERS ?= 2
test: $(STAMP)
	OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 $(BIN)/python -m pytest -q -n $(WORKERS) --dist loadfile --no-loadscope-reorder

bench: $(STAMP)
	for f in benchmarks/bench_*.py; do echo "== $$f"; $(BIN)/python $$f || exit 1; done

clean:
	rm -rf $(VENV) build *.egg-info
