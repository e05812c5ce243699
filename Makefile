# Two entry points (see README): `make run` opens the TUI on the default
# scenario, `make test` runs the checks (`lint`: ruff and mypy) and then the
# whole suite. Both set up what they need once.
PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed
# uv installs exactly the set locked in uv.lock; it is itself installed from the
# registry into its own small venv, so a machine needs only Python and make.
UV_VERSION := 0.13.8
UV_HOME := .uv
UV := $(UV_HOME)/bin/uv
export PYTHONDONTWRITEBYTECODE := 1

.PHONY: run test test-all lint lint-imports bench setup system-deps lock

run: setup
	$(VENV)/bin/ladartui

# The suite runs in one process per core (pytest-xdist; at most four), a test file's
# tests together in one of them: on two cores it took 4 min 14 s against 7 min 42 s.
TEST_PROCESSES ?= -n auto --maxprocesses 4 --dist loadfile

# While the import, style and type checks run, two background processes fill
# numba's cache with the tracing kernels (tests/warm_kernels.py): a fresh clone's
# suite would otherwise compile them one at a time, about 2.5 minutes on two cores.
test: setup
	@echo "compiling the tracing kernels in the background (tests/warm_kernels.py)"
	@timeout 900 $(VENV)/bin/python tests/warm_kernels.py object >/dev/null 2>&1 & \
	timeout 900 $(VENV)/bin/python tests/warm_kernels.py ray >/dev/null 2>&1 & \
	$(VENV)/bin/lint-imports --no-cache --no-logo && $(MAKE) --no-print-directory lint; \
	checks=$$?; wait; exit $$checks
	$(VENV)/bin/python -m pytest -q $(TEST_PROCESSES)

# The suite on every supported Python (interpreters found on PATH or under
# pyenv); one venv per version, .venv-3.X, installed once like .venv.
PYTHONS ?= 3.11 3.12 3.13
test-all: system-deps
	@set -e; for v in $(PYTHONS); do \
	  py=$$(ls -d $$HOME/.pyenv/versions/$$v.*/bin/python 2>/dev/null | tail -1); \
	  if [ -z "$$py" ] && python$$v -c "" 2>/dev/null; then py=$$(command -v python$$v); fi; \
	  if [ -z "$$py" ]; then echo "python$$v: not found, skipped"; continue; fi; \
	  $(MAKE) --no-print-directory VENV=.venv-$$v PYTHON=$$py .venv-$$v/.installed; \
	  echo "== Python $$v"; .venv-$$v/bin/python -m pytest -q -p no:randomly; \
	done

# Style and types (configured in pyproject.toml), run by `make test` before the
# suite: any finding fails it. mypy keeps its cache in .mypy_cache (about 13 s
# cold, under a second warm; see README, "Checks").
lint: setup
	$(VENV)/bin/ruff check src tests
	$(VENV)/bin/ruff format --check src tests
	$(VENV)/bin/mypy

# The import contracts in pyproject.toml (layers, no cycles, core below the shells).
# --no-cache: the check takes well under a second and leaves nothing in the tree.
lint-imports: setup
	$(VENV)/bin/lint-imports --no-cache --no-logo

bench: setup
	$(VENV)/bin/ladartui bench

# Python reads compiled modules but, under PYTHONDONTWRITEBYTECODE (exported above,
# and set on some machines), never writes them: every start compiled the ~450
# modules it imports, 1.2 s of a 2.4 s `ladartui validate`. So the packages are
# compiled when installed (uv's --compile-bytecode) and ladartui's own modules
# here, which redoes only those changed since (0.06 s when none). A module that
# does not compile is left to the checks (ruff names it) and to the run.
setup: system-deps $(STAMP)
	@$(VENV)/bin/python -m compileall -q src >/dev/null || true

# The wgpu backend runs on Mesa's lavapipe where there is no GPU.
system-deps:
	@if ! dpkg -s mesa-vulkan-drivers >/dev/null 2>&1; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "installing mesa-vulkan-drivers (lavapipe) ..."; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mesa-vulkan-drivers >/dev/null; \
	  else \
	    echo "note: mesa-vulkan-drivers is missing; run 'sudo apt-get install mesa-vulkan-drivers' for the wgpu backend"; \
	  fi; \
	fi

$(UV):
	$(PYTHON) -m venv $(UV_HOME)
	$(UV_HOME)/bin/python -m pip install -q --disable-pip-version-check "uv==$(UV_VERSION)"

# --locked: fail (rather than re-resolve) when pyproject.toml and uv.lock disagree.
# The venv keeps pip (seeded by `python -m venv`) for ad-hoc tools; uv removes
# any other package the lock does not name.
$(STAMP): pyproject.toml uv.lock Makefile | $(UV)
	test -x $(VENV)/bin/python || $(PYTHON) -m venv $(VENV)
	UV_PROJECT_ENVIRONMENT=$(VENV) UV_PYTHON_DOWNLOADS=never \
	  $(UV) sync --locked --extra test --compile-bytecode --python $(VENV)/bin/python
	touch $(STAMP)

# After changing a pin in pyproject.toml: re-resolve and re-install.
lock: $(UV)
	$(UV) lock
	$(MAKE) --no-print-directory $(STAMP)
