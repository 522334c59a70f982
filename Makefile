# Two entry points, each doing all set-up on a fresh machine:
#   make bench   quick benchmark run (plots and JSON under results/)
#   make test    the test suite
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
SOURCES := setup.py pyproject.toml constraints.txt $(wildcard boxtrees/*.pyx boxtrees/*.pxd boxtrees/*.h)
# torch is installed first, as the CPU build from PyTorch's index (constraints.txt pins its
# version): stable-baselines3 would otherwise pull PyPI's CUDA build of several GB. Where that
# index cannot be reached, pip's usual indexes give the same version (PyPI's Linux build is
# the CUDA one, unless pip is configured with a CPU file).
TORCH_INDEX := https://download.pytorch.org/whl/cpu

.PHONY: bench test test-slow install clean

bench: $(VENV)/.installed
	$(PY) -m benchmarks.run_all --quick --jobs 2

# a test file per worker, handed out in collection order: the few long files (the games,
# the sanitizer build) start early instead of after xdist's largest-first order
test: $(VENV)/.installed
	$(PY) -m pytest -q -n auto --dist loadfile --no-loadscope-reorder -m "not slow" tests

# the tests marked slow (minutes each: the sanitizers, a Dask cluster, an Atari game end to
# end); CI runs them after `make test`
test-slow: $(VENV)/.installed
	$(PY) -m pytest -q -n auto --dist loadfile --no-loadscope-reorder -m slow tests

install: $(VENV)/.installed

$(VENV)/.installed: $(SOURCES)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -c constraints.txt --index-url $(TORCH_INDEX) --retries 1 --timeout 30 torch \
	    || { echo "torch: nothing from $(TORCH_INDEX); trying pip's usual indexes"; \
	         $(PY) -m pip install -q -c constraints.txt torch; }
	$(PY) -m pip install -q -c constraints.txt -e '.[dev]'
	# ocatari declares numpy<2: the dev extra has what it runs on (the extra atari-deps), and
	# it goes in alone, so NumPy stays at 2 (envs.AtariObjects runs every game on it)
	$(PY) -m pip install -q -c constraints.txt --no-deps ocatari
	touch $@

clean:
	rm -rf build dist $(VENV) boxtrees/*.so boxtrees/*.c boxtrees/*.cpp
