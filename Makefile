# humanmpc: the README's commands.
#   make test   install what is missing (apt packages as root, .venv, pip) and run the whole suite
#   make demo   generate + build the default solver, run the crossing-group scenario with the MPC and
#               the DWB baseline, print the metrics side by side and write the figure
SHELL := /bin/bash
.DEFAULT_GOAL := help

PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
GEN := $(VENV)/bin/humanmpc-gen
STAMP := $(VENV)/.installed

# Debian packages the suite needs: compilers (gcc, clang + its sanitizer/fuzzer runtime), make and
# CMake for the generated package, binutils for nm, valgrind, Python venv support, and Debian's Ipopt
# (with the BLAS/LAPACK it links) for the C reference solver; the Cortex-M cross compiler, newlib and
# QEMU for the firmware build, g++ and Eigen for the C++ face (docs/firmware.md).
APT_PACKAGES := gcc clang libclang-rt-14-dev make cmake binutils valgrind python3-venv python3-dev \
	coinor-libipopt-dev libblas-dev liblapack-dev \
	gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm libeigen3-dev g++

.PHONY: help test demo bench firmware system-deps venv lint clean

help:
	@echo "make test   - set up everything on a fresh Debian machine and run the whole test suite"
	@echo "make demo   - generate and build the solver of the built-in default spec"
	@echo "make bench  - time the RTI in random crowds; compare with acados and Ipopt (docs/benchmarks.md)"
	@echo "make firmware - the solver on Cortex-M7 (double) and Cortex-M4 (float) under QEMU (docs/firmware.md)"
	@echo "make lint   - ruff and mypy"

system-deps:
	@missing=""; for p in $(APT_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "[setup] installing Debian packages:$$missing"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=""; elif command -v sudo >/dev/null; then SUDO="sudo"; \
	  else echo "[setup] need root to install:$$missing" >&2; exit 1; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq \
	    --no-install-recommends $$missing >/dev/null || exit 1; \
	fi

$(STAMP): pyproject.toml
	@echo "[setup] creating $(VENV) and installing humanmpc[test]"
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	@$(PY) -m pip install -q --upgrade pip
	@$(PY) -m pip install -q -e '.[test]'
	@touch $@

venv: system-deps $(STAMP)

test: venv
	$(PY) -m ruff check codegen python tests
	$(PY) -m pytest tests

demo: venv
	$(GEN) generate -o generated/paper --force
	$(GEN) build generated/paper
	$(GEN) demo --out out/demo

bench: venv
	$(GEN) bench --out out/bench
	$(GEN) bench --compare --compare-out out/compare

# The default spec's solver as firmware: double on a Cortex-M7, float on a Cortex-M4F, each replaying
# a recorded crowd under QEMU and compared with the host library.
firmware: venv
	$(GEN) generate -o generated/paper --force
	$(GEN) firmware generated/paper --cpu cortex-m7
	@mkdir -p out/firmware && printf 'name: paper_float\nprecision: float\n' > out/firmware/paper_float.yaml
	$(GEN) generate out/firmware/paper_float.yaml -o generated/paper_float --force
	$(GEN) firmware generated/paper_float --cpu cortex-m4

lint: venv
	$(PY) -m ruff check codegen python tests
	$(PY) -m mypy codegen python

clean:
	rm -rf build generated/*/ .pytest_cache .ruff_cache .mypy_cache .hypothesis
