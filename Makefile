# Two entry points, each doing all set-up on a fresh machine:
#   make bench   quick benchmark run (plots and JSON under results/)
#   make test    the test suite
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
SOURCES := setup.py pyproject.toml constraints.txt $(wildcard boxtrees/*.pyx boxtrees/*.pxd boxtrees/*.h)

.PHONY: bench test install clean

bench: $(VENV)/.installed
	$(PY) -m benchmarks.run_all --quick --jobs 2

test: $(VENV)/.installed
	$(PY) -m pytest -q tests

install: $(VENV)/.installed

$(VENV)/.installed: $(SOURCES)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -c constraints.txt torch==2.13.0
	$(PY) -m pip install -q -c constraints.txt -e '.[dev]'
	touch $@

clean:
	rm -rf build $(VENV) boxtrees/*.so boxtrees/*.c boxtrees/*.cpp
