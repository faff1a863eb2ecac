# humanmpc: the README's commands.
#   make test   install what is missing (apt packages as root, .venv, pip) and run the whole suite
#   make demo   generate + build the default solver (once, into generated/.cache/), run the crossing-group
#               scenario with the MPC and the DWB baseline, print the metrics side by side and write the figure
# Each target installs only what it uses: the demo the compiler and the tool's own Python
# dependencies; the firmware target the Cortex-M cross compiler and QEMU; the tests everything.
SHELL := /bin/bash
.DEFAULT_GOAL := help

PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
GEN := $(VENV)/bin/humanmpc-gen
STAMP_RUN := $(VENV)/.installed-run
STAMP_TEST := $(VENV)/.installed-test

# Debian packages. The tool: a C compiler, make, Python venv support (and its headers, for cffi).
APT_RUN := gcc make binutils python3-venv python3-dev
# The Cortex-M cross compiler, newlib and QEMU (docs/firmware.md).
APT_FIRMWARE := gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm
# Debian's ROS 1 for the generated ROS node (docs/ros.md): catkin, roscpp and the message packages
# (ros-core-dev), tf2 for C++ and Python, rostest, rosbag and rospy for the simulation node.
APT_ROS := ros-core-dev libtf2-ros-dev libtf2-geometry-msgs-dev python3-tf2-ros python3-rospy \
	python3-rostest python3-rosbag python3-nav-msgs python3-sensor-msgs python3-geometry-msgs \
	python3-visualization-msgs python3-diagnostic-msgs
# The suite on top: clang (+ its sanitizer/fuzzer runtime), CMake for the generated package, valgrind,
# Debian's Ipopt (with the BLAS/LAPACK it links) for the C reference solver, g++ and Eigen for the C++
# face, and the firmware toolchain for the firmware tests.
APT_TEST := $(APT_RUN) $(APT_FIRMWARE) $(APT_ROS) clang libclang-rt-14-dev cmake valgrind \
	coinor-libipopt-dev libblas-dev liblapack-dev libeigen3-dev g++

.PHONY: help test demo bench firmware venv venv-test lint clean

help:
	@echo "make test   - set up everything on a fresh Debian machine and run the whole test suite"
	@echo "make demo   - generate and build the default solver, run the demo scenario (installs only what it needs)"
	@echo "make bench  - time the RTI in random crowds; compare with acados and Ipopt (docs/benchmarks.md)"
	@echo "make firmware - the solver on Cortex-M7 (double) and Cortex-M4 (float) under QEMU (docs/firmware.md)"
	@echo "make lint   - ruff, mypy and the import layers"

# apt-install the packages named in $(1) that are missing (as root, or through sudo).
define apt_install
	@missing=""; for p in $(1); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "[setup] installing Debian packages:$$missing"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=""; elif command -v sudo >/dev/null; then SUDO="sudo"; \
	  else echo "[setup] need root to install:$$missing" >&2; exit 1; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq \
	    --no-install-recommends $$missing >/dev/null || exit 1; \
	fi
endef

$(STAMP_RUN): pyproject.toml
	$(call apt_install,$(APT_RUN))
	@echo "[setup] creating $(VENV) and installing humanmpc"
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	@$(PY) -m pip install -q --upgrade pip
	@$(PY) -m pip install -q -e .
	@touch $@

$(STAMP_TEST): $(STAMP_RUN) pyproject.toml
	$(call apt_install,$(APT_TEST))
	@echo "[setup] installing humanmpc[test,dev]"
	@$(PY) -m pip install -q -e '.[test,dev]'
	@touch $@

venv: $(STAMP_RUN)

venv-test: $(STAMP_TEST)

test: venv-test
	$(PY) -m ruff check codegen python tests
	$(PY) -m mypy codegen python
	$(PY) -m pytest tests

# The demo generates and builds the default solver into the tools' cache (generated/.cache/paper-<hash>/)
# when it is not there yet; it writes no other solver folder.
demo: venv
	$(GEN) demo --out out/demo

# Timed on libraries tuned to this machine's CPU (HUMANMPC_NATIVE=1: -march=native, the same results bit
# for bit as the portable default), as docs/benchmarks.md states.
bench: venv
	HUMANMPC_NATIVE=1 $(GEN) bench --out out/bench
	HUMANMPC_NATIVE=1 $(GEN) bench --compare --compare-out out/compare

# The default spec's solver and navigation controller as firmware: double on a Cortex-M7, float on a
# Cortex-M4F, each replaying a recorded crowd (the solver) and a recorded closed loop (the controller)
# under QEMU and compared with the host library (docs/firmware.md).
firmware: venv
	$(call apt_install,$(APT_FIRMWARE))
	$(GEN) generate -o generated/paper --force
	$(GEN) firmware generated/paper --cpu cortex-m7
	@mkdir -p out/firmware && printf 'name: paper_float\nprecision: float\n' > out/firmware/paper_float.yaml
	$(GEN) generate out/firmware/paper_float.yaml -o generated/paper_float --force
	$(GEN) firmware generated/paper_float --cpu cortex-m4

lint: venv-test
	$(PY) -m ruff check codegen python tests
	$(PY) -m mypy codegen python
	$(PY) -m pytest -q tests/test_packaging.py -k import_layer

clean:
	rm -rf build generated/*/ generated/.cache .pytest_cache .ruff_cache .mypy_cache .hypothesis
