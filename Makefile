# enamel-dem — the front door. `make help` lists the targets.
#
#   make deps     install the Debian packages the project needs (idempotent; needs root to install)
#   make build    configure and build the solver and the C++ tests (Release)
#   make test     all C++ and Python tests (runs deps and build first when needed)

SHELL := /bin/bash
BUILD_DIR ?= build
JOBS ?= 2

# Debian packages: the complete set needed to build, test and draw figures.
DEB_PACKAGES := g++ make cmake pkg-config git \
  libeigen3-dev libsuitesparse-dev libhdf5-dev libtomlplusplus-dev libcli11-dev libgtest-dev \
  python3 python3-numpy python3-h5py python3-matplotlib python3-meshio python3-pytest

# An interpreter that can import the pipeline's modules. The `python3` first on PATH may be a
# pyenv one without them, so probe the Debian interpreter first; fall back to it (after
# `make deps` it has everything).
PY_MODULES := numpy,h5py,matplotlib,meshio
PYTHON ?= $(shell for p in /usr/bin/python3 python3; do \
    if $$p -c 'import $(PY_MODULES)' >/dev/null 2>&1; then command -v $$p; exit 0; fi; done; \
    echo /usr/bin/python3)

ENAMEL := $(BUILD_DIR)/enamel-dem

.PHONY: help deps build test test-cpp test-python clean

help:
	@sed -n '1,/^$$/p' $(firstword $(MAKEFILE_LIST)) | sed 's/^# \{0,1\}//'

deps:
	@missing=$$(for p in $(DEB_PACKAGES); do \
	    dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed' || echo $$p; done); \
	if [ -z "$$missing" ]; then echo "deps: all Debian packages present"; exit 0; fi; \
	echo "deps: missing Debian packages:" $$missing; \
	if [ "$$(id -u)" != 0 ]; then \
	  if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then SUDO=sudo; else \
	    echo "deps: ERROR: installing packages needs root. Run 'sudo make deps' (or as root:" >&2; \
	    echo "      apt-get install $$missing), then re-run this command." >&2; exit 1; fi; \
	fi; \
	$$SUDO apt-get update -qq && \
	DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing

$(BUILD_DIR)/CMakeCache.txt: CMakeLists.txt | deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	$(MAKE) --no-print-directory test-cpp test-python

test-cpp:
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

test-python:
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m pytest -q tests/python

clean:
	rm -rf $(BUILD_DIR)
