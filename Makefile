# The README's commands. Every target sets itself up from a fresh Debian
# machine: gfortran (apt, only when missing), a venv in .venv, the package.
SHELL := /bin/bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := help
.DELETE_ON_ERROR:

PYTHON ?= python3
VENV   := .venv
BIN    := $(CURDIR)/$(VENV)/bin
# meson-python runs `meson` from PATH: the venv's bin must come first.
export PATH := $(BIN):$(PATH)
export DEBIAN_FRONTEND := noninteractive
# No display on CI or a server.
export MPLBACKEND ?= Agg

# Persistent meson build dir shared by `pip install` and `meson test`: one
# compile serves the wheel and the Fortran unit tests, and re-runs are no-ops.
BUILDDIR := $(CURDIR)/build/py
# The tutorial's six cases, then the mechanisms beyond it (springs, dampers, static friction,
# contact records), then scenes of N bodies (their plots: the space-time picture).
SCENES   := case1 case2 case3 case4 case5 case6 impact_oscillator stick_slip gear_rattle breakaway mounted_stop \
            inner_stop newtons_cradle train ball_stack gear_train geared_train burridge_knopoff vibrating_table \
            drill_string lift_table

# What the installed package is made of: a change re-installs it (folders too,
# so that a deleted file counts).
PKG_SOURCES := $(shell find src app wrapper -not -path '*/__pycache__*' 2>/dev/null) \
               meson.build pyproject.toml .f2py_f2cmap

DEPS_STAMP    := $(VENV)/.build-deps
INSTALL_STAMP := $(VENV)/.installed

.PHONY: help setup demo test clean gfortran study

help:
	@echo "make setup   gfortran (apt, if missing), .venv, pip install .[test]"
	@echo "make demo    run the scenes in input/ (the six cases, springs, stick-slip, rattle, break-away,"
	@echo "             contact records, Newton's cradle, a train, a ball stack, two gear trains (unit ratios; ratios 3 and 1/2), a"
	@echo "             Burridge-Knopoff chain, a vibrating table, a drill string in stick-slip,"
	@echo "             a ball in a lift),"
	@echo "             plot them, animate case 3, the cradle and the train (docs/*.gif)"
	@echo "make test    Fortran unit tests (meson test), then pytest"
	@echo "make study   case 5's rest time over (r_left, r_right), the impact oscillator's bifurcation diagram"
	@echo "make bench   accuracy and speed studies, Siconos and CVODE as peers (apt, if missing)"
	@echo "             -> docs/accuracy.md, docs/performance.md"
	@echo "make clean   remove .venv, build/ and output files"

setup: gfortran $(INSTALL_STAMP)

# apt-get only when gfortran is missing; sudo only when not root and present.
gfortran:
	@if ! command -v gfortran >/dev/null 2>&1; then \
	  if [ "$$(id -u)" -eq 0 ]; then SUDO=""; \
	  elif command -v sudo >/dev/null 2>&1; then SUDO="sudo -E"; \
	  else echo "error: gfortran is missing and we are not root (no sudo): install gfortran" >&2; exit 1; fi; \
	  echo "installing gfortran with apt-get"; \
	  $$SUDO apt-get update -q; \
	  $$SUDO apt-get install -y -q gfortran; \
	fi
	@gfortran --version | head -n 1

$(BIN)/python:
	@if ! $(PYTHON) -m venv $(VENV); then \
	  echo "python3 -m venv failed: installing python3-venv with apt-get" >&2; \
	  rm -rf $(VENV); \
	  if [ "$$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo -E"; fi; \
	  $$SUDO apt-get update -q && $$SUDO apt-get install -y -q python3-venv python3-dev; \
	  $(PYTHON) -m venv $(VENV); \
	fi

# Build requirements for --no-build-isolation (meson-python needs them in the env).
$(DEPS_STAMP): $(BIN)/python
	$(BIN)/python -m pip install -q meson-python meson ninja numpy
	@touch $@

# Regular (not editable) install: it is what puts the `impact1d` executable
# on PATH. A missing build dir also forces it (meson test runs there).
$(INSTALL_STAMP): $(DEPS_STAMP) $(PKG_SOURCES) $(BUILDDIR)/build.ninja
	$(BIN)/python -m pip install -q --no-build-isolation \
	    -Cbuild-dir=$(BUILDDIR) '.[test]'
	@touch $@

$(BUILDDIR)/build.ninja: ;

demo: setup
	@mkdir -p output
	@for name in $(SCENES); do \
	  echo "== $$name"; \
	  impact1d input/$$name.nml; \
	  impact1d-plot output/$$name.dat; \
	done
	@echo "== case3, Newton's cradle and the train animated (README)"
	impact1d-plot --animate output/case3.dat -o docs/case3.gif --max-frames 150 --fps 15
	impact1d-plot --animate output/newtons_cradle.dat -o docs/cradle.gif --fps 20
	impact1d-plot --animate output/train.dat -o docs/train.gif --t-to 2 --max-frames 80 --fps 10

# An example study (README): 400 runs of case 5 on every core, then the heatmap.
study: setup
	impact1d-sweep input/case5.nml --vary r_left=0:0.95:20 --vary r_right=0:0.95:20 \
	    --vary t_end=10 -o output/case5_rest.csv
	impact1d-plot output/case5_rest.csv --x r_left --y r_right --value t_rest \
	    -o docs/study_case5_rest.png
	$(BIN)/python studies/impact_oscillator_bifurcation.py docs/study_impact_oscillator.png

test: setup
	meson test -C $(BUILDDIR) --print-errorlogs
	$(BIN)/python -m pytest -q tests

clean:
	rm -rf $(VENV) build .pytest_cache .hypothesis
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
	find output -mindepth 1 ! -name README.md -delete 2>/dev/null || true

# Accuracy and speed studies (bench/): a few minutes; writes docs/accuracy.md,
# docs/performance.md and their figures (docs/*.png). Numbers are measured, not asserted.
.PHONY: bench siconos sundials
bench: setup siconos sundials
	$(BIN)/python bench/run_all.py

# An optional bench peer's Debian package: $(1) the package, $(2) what the bench then runs
# without, $(3) a shell test that is true when it is already there. apt-get only when it is
# missing; where it cannot be installed the bench says so and goes on.
define optional_peer
	@if ! $(3); then \
	  if [ "$$(id -u)" -eq 0 ]; then SUDO=""; \
	  elif command -v sudo >/dev/null 2>&1; then SUDO="sudo -E"; \
	  else SUDO="none"; fi; \
	  if [ "$$SUDO" = none ] || ! command -v apt-get >/dev/null 2>&1; then \
	    echo "note: $(1) is not installed and apt-get cannot install it here: the bench runs without $(2)"; \
	  else \
	    echo "installing $(1) with apt-get"; \
	    $$SUDO apt-get update -q || true; \
	    $$SUDO apt-get install -y -q $(1) \
	      || echo "note: apt-get could not install $(1): the bench runs without $(2)"; \
	  fi; \
	fi
endef

# The Siconos peer (bench/siconos_peer.py) runs under the system interpreter with Debian's
# python3-siconos.
SICONOS_PYTHON ?= /usr/bin/python3
export SICONOS_PYTHON
siconos:
	$(call optional_peer,python3-siconos,Siconos,$(SICONOS_PYTHON) -c 'import siconos.kernel' >/dev/null 2>&1)

# The CVODE peer (bench/cvode_peer.c, compiled by bench/cvode_peer.py into build/bench) links
# Debian's SUNDIALS (its CVODE header tells whether it is there).
sundials:
	$(call optional_peer,libsundials-dev,CVODE,[ -f /usr/include/cvode/cvode.h ])
