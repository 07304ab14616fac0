# Two commands on a fresh machine: `make demo` and `make test`.
#
# Set-up needs Python >= 3.11 and a C++ compiler: openmesh has no wheel and builds from source
# (2-4 minutes). cmake is taken from the system, or else installed from its PyPI wheel into
# .venv (no root needed). As root on Debian/Ubuntu, a missing compiler is installed with apt-get;
# otherwise the set-up stops and says how to install one.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
# The openmesh build calls `cmake` from PATH. The PyPI wheel's .venv/bin/cmake is a Python
# launcher that fails inside pip's isolated build environment (it cannot import its package
# there), so the wheel's binary directory (cmake.CMAKE_BIN_DIR) goes first on PATH instead.
# CMake 4 refuses openmesh's cmake_minimum_required(3.3) unless given a policy minimum (the
# variable is ignored by CMake 3).
CMAKE_BIN := $(PY) -c 'import cmake; print(cmake.CMAKE_BIN_DIR)' 2>/dev/null
# The linear solver (gridshell/solver/linear.py): CHOLMOD through scikit-sparse, which has no
# wheel; 0.4.16 builds against Debian's libsuitesparse-dev 5.12 (Cython < 3, numpy/scipy from the
# venv, hence --no-build-isolation: ~20 s instead of ~4 min isolated). As root on Debian/Ubuntu the
# headers and OpenBLAS (CHOLMOD's BLAS; reference BLAS otherwise) are installed with apt-get:
# ~85 MB installed (Cython, needed for the build only, is removed again). Without them the
# set-up goes on and gridshell uses SuperLU (scipy); see `gridshell --version`.
SKSPARSE  := scikit-sparse==0.4.16
CHOLMOD_H := /usr/include/suitesparse/cholmod.h
# a C++ compiler on PATH: $CXX if set, else the usual names
HAVE_CXX  := { command -v "$${CXX:-c++}" || command -v g++ || command -v clang++; } >/dev/null 2>&1

.PHONY: demo test test-fast bench clean venv browser

venv: $(STAMP)

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(sys.version_info < (3, 11))' 2>/dev/null || { \
	  echo >&2 "error: '$(PYTHON)' is missing or older than Python 3.11; install Python >= 3.11"; \
	  echo >&2 "  or name it: make PYTHON=/path/to/python3.11 $(MAKECMDGOALS)"; exit 1; }
	@if ! $(HAVE_CXX) && [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  echo "no C++ compiler: installing g++ with apt-get (openmesh is built from source)"; \
	  { apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y g++; } >/dev/null 2>&1 \
	    || echo >&2 "apt-get could not install g++"; \
	fi
	@$(HAVE_CXX) || { \
	  echo >&2 "error: no C++ compiler (c++, g++ or clang++, or \$$CXX) on PATH; openmesh is built"; \
	  echo >&2 "  from source and needs one. Install it, then run make again:"; \
	  echo >&2 "  Debian/Ubuntu: sudo apt-get install -y g++; Fedora: sudo dnf install gcc-c++;"; \
	  echo >&2 "  macOS: xcode-select --install"; exit 1; }
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip setuptools wheel
	@if $(PY) -c 'import cmake' 2>/dev/null || command -v cmake >/dev/null 2>&1; then :; else \
	  echo "cmake not found: installing it from PyPI into $(VENV) (pip install cmake)"; \
	  $(PY) -m pip install --quiet "cmake>=3.16,<4" || { \
	    echo >&2 "error: cmake is needed to build openmesh and 'pip install cmake' failed;"; \
	    echo >&2 "  install cmake (e.g. sudo apt-get install -y cmake), then run make again"; \
	    exit 1; }; \
	fi
	cmake_bin=$$($(CMAKE_BIN)); \
	PATH="$${cmake_bin:+$$cmake_bin:}$$PATH" CMAKE_POLICY_VERSION_MINIMUM=3.5 \
	  $(PY) -m pip install --quiet -e ".[test,server,sweep]" || { \
	  echo >&2 "error: installing gridshell and its dependencies failed (see above); openmesh"; \
	  echo >&2 "  builds from source with cmake and a C++ compiler, and pip needs the network"; \
	  exit 1; }
	@if [ ! -f $(CHOLMOD_H) ] && [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  echo "installing libsuitesparse-dev and OpenBLAS with apt-get (CHOLMOD for the linear solver)"; \
	  { apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
	      libsuitesparse-dev libopenblas0-pthread; } >/dev/null 2>&1 \
	    || echo "apt-get could not install libsuitesparse-dev: the linear solver will be SuperLU"; \
	fi
	@if [ -f $(CHOLMOD_H) ]; then \
	  $(PY) -m pip install --quiet "cython>=0.29,<3" && \
	  $(PY) -m pip install --quiet --no-build-isolation "$(SKSPARSE)" \
	    || echo "building $(SKSPARSE) failed: the linear solver will be SuperLU (scipy)"; \
	  $(PY) -m pip uninstall --quiet --yes cython >/dev/null 2>&1; \
	else echo "no libsuitesparse-dev ($(CHOLMOD_H)): the linear solver will be SuperLU (scipy)"; fi
	@$(VENV)/bin/gridshell --version | tail -1
	@touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/gridshell demo -o out/demo

# The report viewer's browser test (tests/render/test_viewer.py) drives Debian's chromium headless. As
# root with apt-get, a missing chromium is installed quietly; otherwise that test is skipped and
# says why.
browser:
	@command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    echo "no chromium: installing it with apt-get (the report viewer's browser test)"; \
	    { apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y chromium; } \
	      >/dev/null 2>&1 || echo >&2 "apt-get could not install chromium; the browser test is skipped"; \
	  else echo "no chromium (not root or no apt-get): the report viewer's browser test is skipped"; \
	  fi; }

test: $(STAMP) browser
	$(PY) -m pytest -q

# The edit loop: the suite without the tests marked slow or browser (pyproject.toml's markers).
test-fast: $(STAMP)
	$(PY) -m pytest -q -m "not slow and not browser"

# Every stage's time and memory, then the timings the README quotes (benchmarks/readme.py:
# benchmarks/readme_timings.json, copied into README.md).
bench: $(STAMP)
	$(PY) benchmarks/run_all.py
	$(PY) benchmarks/readme.py --update-readme

clean:
	rm -rf $(VENV) out build *.egg-info
