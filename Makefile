# rwall_fem: set-up and test driver (Debian 12, run as root or with sudo).
#
#   make test                  run the pytest suite on every DOLFINx leg, serially and on NP ranks,
#                              and (on the Debian leg) build the documentation (`make docs`)
#   make test DOLFINX=0.5      only the Debian leg:  DOLFINx 0.5 (apt) + Open MPI, venv .venv
#   make test DOLFINX=0.11     only the PyPI leg:    dolfinx-solver-real 0.11 + MPICH, venv .venv-0.11
#   make venv                  set-up only (honours DOLFINX too)
#   make demo                  run demos/bar_impact.toml on the Debian leg into results/bar_impact
#   make demos                 run every demo (scenes and Python scripts) into results/
#   make docs                  the documentation site (Sphinx + MyST) into docs/_build/html,
#                              warnings as errors; on the Debian leg, a few seconds, runs no demo
#   make study / make bench    accuracy vs wall time per element technology (results/study, copied
#                              to docs/); benchmark (bench/results.md, bench/effects.md); both on
#                              the Debian leg, long runs
#   make clean                 remove both venvs, test logs, Python caches and the built docs
#                              (results/ is kept)
#   make clean-wheels          remove the wheelhouses (see below; the next set-up refills them)
#
# Set-up is incremental: apt runs only when a package is missing (one dpkg-query otherwise),
# and pip runs only when a venv is new or pyproject.toml is newer than the venv's stamp.
#
# Wheel cache: pip's own HTTP cache (~/.cache/pip) does not fill on this network (the proxy
# sends no caching headers), so each leg keeps a wheelhouse outside the clone, by default
# ~/.cache/rwall_fem/wheels/<leg>/py<X.Y> (or under $XDG_CACHE_HOME; knob WHEELHOUSE, empty
# = none).  tools/pip-install-cached.sh installs with `pip install --no-index --find-links`
# from it, so a fresh clone (CI) downloads nothing once it is filled; only when that fails
# (first run, a new dependency in pyproject.toml) does it fetch the missing wheels from the
# index into the wheelhouse, prune the ones no longer used, and install from it.
# `make clean-wheels` empties it.
#
# The 0.11 leg needs Python >= 3.12 (pyenv 3.12.x / 3.13.x, or python3.12 / python3.13 on
# PATH; override with PY011=/path/to/python3.12).  Without one it prints a single
# "SKIPPED: ..." line and succeeds.
#
# Each test run is its own target and make runs with --keep-going, so one `make test` runs
# every leg and reports every failure, and still exits non-zero if anything failed.

SHELL       := /bin/bash
.SHELLFLAGS := -eu -o pipefail -c
MAKEFLAGS   += --keep-going --no-print-directory
.DELETE_ON_ERROR:
.NOTPARALLEL:                 # one leg at a time: readable output, and only 2 cores anyway

# ---- knobs ----------------------------------------------------------------------------------
# Which legs: all | 0.5 | 0.11
DOLFINX      ?= all
# MPI ranks for the parallel runs
NP           ?= 2
# No -x: under MPI, one rank stopping early would strand the other in a collective.
PYTEST_ARGS  ?= -q tests
# Seconds per pytest run, so a deadlocked MPI job cannot hang CI (0 = no limit).
TEST_TIMEOUT ?= 3600
# --foreground: Ctrl-C still reaches pytest/mpirun; on time-out mpirun takes its ranks down.
TIMEOUT       = timeout --foreground $(TEST_TIMEOUT)

# ---- the two legs ---------------------------------------------------------------------------
# Leg 0.5: Debian's DOLFINx. Always Debian's interpreter: `python3` on PATH may be pyenv's.
SYS_PYTHON   := /usr/bin/python3
VENV         := .venv
LOGS_0.5     := $(VENV)/mpi-logs
APT_0.5      := python3-dolfinx python3-petsc4py python3-slepc4py python3-mpi4py python3-gmsh \
                python3-pytest python3-venv openmpi-bin \
                libegl1 libgl1-mesa-dri libegl-mesa0 libosmesa6
# Open MPI 4.1 refuses root without --allow-run-as-root, and refuses NP > cores without
# --oversubscribe.  single_copy_mechanism=none: CMA (process_vm_readv) is blocked in many
# containers and then large messages fail with "Read -1, expected ..., errno = 1".
MPIRUN_0.5   := $(TIMEOUT) env OMPI_MCA_btl_vader_single_copy_mechanism=none \
                mpirun --allow-run-as-root --oversubscribe

# Leg 0.11: the dolfinx-solver-real wheel (bundles PETSc, SLEPc, MPICH); its own mpiexec.
VENV011      := .venv-0.11
LOGS_0.11    := $(VENV011)/mpi-logs
WHEEL_0.11   := dolfinx-solver-real==0.11.* gmsh
# The wheel is self-contained, but its FFCx JIT needs a C compiler and VTK's off-screen
# rendering needs EGL/Mesa (all already pulled in by the 0.5 leg's packages).
APT_0.11     := gcc libc6-dev libegl1 libgl1-mesa-dri libegl-mesa0 libosmesa6
MPIRUN_0.11  := $(TIMEOUT) env UCX_TLS=self,sm,tcp $(VENV011)/bin/mpiexec

# Environment of the demo and test runs: off-screen pyvista through EGL, headless matplotlib.
RUN_ENV      := env VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow PYVISTA_OFF_SCREEN=true MPLBACKEND=Agg
# Tests add: one BLAS/OpenMP thread per rank (NP ranks share the cores), live output.
TEST_ENV     := $(RUN_ENV) OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 PYTHONUNBUFFERED=1
# Under MPI each rank is its own pytest session: skip .pytest_cache (both ranks would write
# it) and give each rank its own temporary tree (two sessions pruning the shared
# /tmp/pytest-of-<user> race).  {rank} is filled in by tools/mpi-run-logged.sh.
MPI_PYTEST    = -m pytest -p no:cacheprovider --basetemp=$(1)/tmp-rank{rank} $(PYTEST_ARGS)

PIP_ENV      := env PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_NO_INPUT=1
# Persistent wheel cache, one wheelhouse per leg (and Python version): see the header.
WHEELHOUSE   ?= $(or $(XDG_CACHE_HOME),$(HOME)/.cache)/rwall_fem/wheels
# $(call PIP_INSTALL,LEG,VENV) PIP-INSTALL-ARGS...: pip install into VENV via LEG's wheelhouse.
PIP_INSTALL   = $(PIP_ENV) bash tools/pip-install-cached.sh '$(if $(WHEELHOUSE),$(WHEELHOUSE)/$(1))' $(2)/bin/python

# ---- leg selection --------------------------------------------------------------------------
DOLFINX := $(strip $(DOLFINX))
ifeq ($(DOLFINX),all)
  LEGS := 0.5 0.11
else ifneq ($(filter $(DOLFINX),0.5 0.11),)
  LEGS := $(DOLFINX)
else
  $(error DOLFINX must be all, 0.5 or 0.11 (got '$(DOLFINX)'))
endif

# The Python >= 3.12 for the 0.11 leg, looked up only when that leg is wanted.
ifneq ($(filter 0.11,$(LEGS)),)
  ifeq ($(origin PY011),undefined)
    PY011 := $(shell bash tools/find-python-0.11.sh)
  endif
endif

.PHONY: test venv demo demos docs study bench clean clean-wheels apt-0.5 apt-0.11 venv-0.5 venv-0.11 FORCE \
        test-0.5 test-0.5-serial test-0.5-mpi test-0.11 test-0.11-serial test-0.11-mpi

test: $(addprefix test-,$(LEGS))
venv: $(addprefix venv-,$(LEGS))

# ---- leg 0.5: Debian packages + .venv -------------------------------------------------------
# Order-only on apt-0.5: the (cheap) dpkg check runs every time but never forces a re-install.
apt-0.5:
	@bash tools/ensure-apt-packages.sh $(APT_0.5)

# A venv is (re)made when missing or when its interpreter is gone (dangling bin/python);
# its fresh pyvenv.cfg then makes the pip stamp out of date.
ifeq ($(realpath $(VENV)/bin/python),)
$(VENV)/pyvenv.cfg: FORCE
endif
$(VENV)/pyvenv.cfg: | apt-0.5
	@echo ">>> creating $(VENV) ($(SYS_PYTHON), with system site packages)"
	rm -rf $(VENV)
	$(SYS_PYTHON) -m venv --system-site-packages $(VENV)

# numpy is pinned to Debian's: a newer numpy from PyPI breaks Debian's petsc4py (ABI).
# The docs extra (Sphinx, MyST) goes here too: `make docs` builds on this leg.
$(VENV)/.installed: pyproject.toml $(VENV)/pyvenv.cfg | apt-0.5
	@echo ">>> pip install -e '.[test,mp4,docs]' into $(VENV)"
	echo "numpy==$$($(SYS_PYTHON) -c 'import numpy; print(numpy.__version__)')" > $(VENV)/constraints.txt
	$(call PIP_INSTALL,0.5,$(VENV)) -c $(VENV)/constraints.txt -e '.[test,mp4,docs]'
	touch $@

venv-0.5: $(VENV)/.installed

# The docs build first: a quick failure (a warning, a broken link to a page) shows early,
# and --keep-going still runs the test suite after it.
test-0.5: docs test-0.5-serial test-0.5-mpi

test-0.5-serial: venv-0.5
	@echo "===== DOLFINx 0.5 (Debian): pytest, serial ====="
	$(TEST_ENV) $(TIMEOUT) $(VENV)/bin/python -m pytest $(PYTEST_ARGS)

test-0.5-mpi: venv-0.5
	@echo "===== DOLFINx 0.5 (Debian): pytest, $(NP) MPI ranks (rank 0 shown, all in $(LOGS_0.5)) ====="
	$(TEST_ENV) bash tools/mpi-run-logged.sh $(NP) $(LOGS_0.5) $(MPIRUN_0.5) \
	    -- $(VENV)/bin/python $(call MPI_PYTEST,$(LOGS_0.5))

# ---- leg 0.11: PyPI wheel + .venv-0.11 ------------------------------------------------------
ifneq ($(PY011),)

ifeq ($(realpath $(VENV011)/bin/python),)
$(VENV011)/pyvenv.cfg: FORCE
endif
apt-0.11:
	@bash tools/ensure-apt-packages.sh $(APT_0.11)

$(VENV011)/pyvenv.cfg: | apt-0.11
	@echo ">>> creating $(VENV011) ($(PY011))"
	rm -rf $(VENV011)
	$(PY011) -m venv $(VENV011)

$(VENV011)/.installed: pyproject.toml $(VENV011)/pyvenv.cfg | apt-0.11
	@echo ">>> pip install $(WHEEL_0.11) -e '.[test,mp4]' into $(VENV011)"
	$(call PIP_INSTALL,0.11,$(VENV011)) $(WHEEL_0.11) -e '.[test,mp4]'
	touch $@

venv-0.11: $(VENV011)/.installed

test-0.11: test-0.11-serial test-0.11-mpi

test-0.11-serial: venv-0.11
	@echo "===== DOLFINx 0.11 (PyPI wheel): pytest, serial ====="
	$(TEST_ENV) $(TIMEOUT) $(VENV011)/bin/python -m pytest $(PYTEST_ARGS)

test-0.11-mpi: venv-0.11
	@echo "===== DOLFINx 0.11 (PyPI wheel): pytest, $(NP) MPI ranks (rank 0 shown, all in $(LOGS_0.11)) ====="
	$(TEST_ENV) bash tools/mpi-run-logged.sh $(NP) $(LOGS_0.11) $(MPIRUN_0.11) \
	    -- $(VENV011)/bin/python $(call MPI_PYTEST,$(LOGS_0.11))

else  # no Python >= 3.12: skip the leg loudly, but do not fail

venv-0.11 test-0.11:
	@echo "SKIPPED: DOLFINx 0.11 leg (no Python >= 3.12)"

endif

FORCE:

# ---- demo and clean ---------------------------------------------------------------------------
demo: venv-0.5
	$(RUN_ENV) $(VENV)/bin/rwall-fem run demos/bar_impact.toml --out results/bar_impact

# Every demo at its full resolution, serially (~2 minutes): scenes into results/NAME/, the
# Python demos write their own results/ folders.  A scene's gallery picture
# (docs/gallery/NAME.png) is a frame of it, full size, seen as its [output.view] says: the
# last (the outcome), but the 13th of the bar (the wave in it, before it leaves the wall)
# and of the perforation (the sphere in the hole it tears, the petals and the damage).
demos: venv-0.5
	for scene in demos/*.toml; do \
	  name=$$(basename $$scene .toml); \
	  $(RUN_ENV) $(VENV)/bin/rwall-fem run $$scene --out results/$$name; \
	  case $$name in bar_impact | perforation_weldox) pick=results/$$name/frames/frame_0012.png ;; \
	    *) pick=$$(ls results/$$name/frames/frame_*.png 2>/dev/null | tail -n 1) ;; esac; \
	  if [ -f "$$pick" ] && [ -f docs/gallery/$$name.png ]; then cp $$pick docs/gallery/$$name.png; fi; \
	done
	for script in demos/demo_*.py; do $(RUN_ENV) $(VENV)/bin/python $$script; done

# The documentation (docs/index.md is its front page): Sphinx with MyST, the Python API by autodoc (so on the
# Debian leg, where DOLFINx imports).  -W: a warning fails the build.  -E: a fresh environment
# each time, so that a page read by an earlier build cannot hide its warnings from this one.
# The demos are not run: the tutorial pages show the committed pictures of docs/gallery/.
DOCS_OUT     := docs/_build/html
docs: venv-0.5
	@echo "===== documentation: sphinx-build -W into $(DOCS_OUT) ====="
	$(RUN_ENV) $(VENV)/bin/python -m sphinx -W --keep-going -E -q -b html docs $(DOCS_OUT)
	@echo "    open $(DOCS_OUT)/index.html"

# The full study (four element technologies) takes 15-30 minutes, and shells against solids
# (the struck plate) 10 more; their tables and plots are copied into docs/ for the README.
study: venv-0.5
	$(RUN_ENV) OMP_NUM_THREADS=1 $(VENV)/bin/rwall-fem study --out results/study
	$(RUN_ENV) OMP_NUM_THREADS=1 $(VENV)/bin/rwall-fem study --shells --out results/study-shells
	mkdir -p docs
	cat results/study/study.md results/study-shells/shells.md > docs/study.md
	cp results/study/study_*.png docs/

# The kernels against the old BAIJ product, whole steps, 2-rank efficiency, the 80k-hexahedron
# scene, material costs, memory, start-up, the Taylor rod (bench/results.md, ~45 minutes), then
# the cost of each effect (bench/effects.md) and of failure and erosion (bench/erosion.md), and
# the shell kernels against the J2 hexahedron's, 1 and 2 ranks (bench/shell_kernels.md).
# OLD_TREE: a worktree of the old code (commit c11ba60, with its .venv) whose time loop on the
# 80k scene is run alternately with the new. PRE_EROSION_TREE: a checkout of the code before
# failure and erosion, whose kernels bench/erosion.py times beside the new ones.
# PRE_CORNER_TREE: a checkout before the corner test of one-point hexahedra (864d876), for
# bench/corners.py (bench/corners.md). OPENRADIOSS: the folder of OpenRadioss's
# starter_linux64_gf and engine_linux64_gf for bench/openradioss_timing.py (the peer shell
# decks in both codes, CPU times; one SKIPPED line without them).
OLD_TREE ?=
PRE_EROSION_TREE ?=
PRE_CORNER_TREE ?=
OPENRADIOSS ?=
bench: venv-0.5
	$(RUN_ENV) OMP_NUM_THREADS=1 OMPI_MCA_btl_vader_single_copy_mechanism=none \
	    $(VENV)/bin/python bench/bench.py --out bench/results.md $(if $(OLD_TREE),--old-tree $(OLD_TREE))
	$(RUN_ENV) OMP_NUM_THREADS=1 $(VENV)/bin/python bench/effects.py
	$(RUN_ENV) OMP_NUM_THREADS=1 $(VENV)/bin/python bench/erosion.py \
	    $(if $(PRE_EROSION_TREE),--main-tree $(PRE_EROSION_TREE))
	$(if $(PRE_CORNER_TREE),$(RUN_ENV) OMP_NUM_THREADS=1 $(VENV)/bin/python bench/corners.py \
	    --before-tree $(PRE_CORNER_TREE))
	$(RUN_ENV) OMP_NUM_THREADS=1 $(VENV)/bin/python bench/openradioss_timing.py \
	    $(if $(OPENRADIOSS),--openradioss $(OPENRADIOSS))
	$(RUN_ENV) OMP_NUM_THREADS=1 $(VENV)/bin/python bench/shell_kernels.py \
	    --out bench/shell_kernels.md
	$(RUN_ENV) OMP_NUM_THREADS=1 $(MPIRUN_0.5) -n 2 $(VENV)/bin/python bench/shell_kernels.py \
	    --out bench/shell_kernels.md
	$(RUN_ENV) OMP_NUM_THREADS=1 $(VENV)/bin/python bench/contact.py --out bench/contact.md
	$(RUN_ENV) OMP_NUM_THREADS=1 $(MPIRUN_0.5) -n 2 $(VENV)/bin/python bench/contact.py \
	    --tube-only --tube-cells 10000 --out bench/contact.md

clean:
	rm -rf $(VENV) $(VENV011) .pytest_cache *.egg-info docs/_build docs/tutorials
	find . -path ./.git -prune -o -type d -name __pycache__ -prune -exec rm -rf {} +

# The wheelhouses live outside the clone and are shared by all clones: not part of `clean`.
clean-wheels:
	rm -rf '$(WHEELHOUSE)'
