# Two entry points (see README): `make run` opens the TUI on the default
# scenario, `make test` runs the whole suite. Both set up what they need once.
PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed
export PYTHONDONTWRITEBYTECODE := 1

.PHONY: run test test-all lint bench setup system-deps

run: setup
	$(VENV)/bin/ladartui

test: setup
	$(VENV)/bin/python -m pytest -q

# The suite on every supported Python (interpreters found on PATH or under
# pyenv); one venv per version, .venv-3.X, installed once like .venv.
PYTHONS ?= 3.11 3.12 3.13
test-all: system-deps
	@set -e; for v in $(PYTHONS); do \
	  py=$$(command -v python$$v || ls -d $$HOME/.pyenv/versions/$$v.*/bin/python 2>/dev/null | tail -1); \
	  if [ -z "$$py" ]; then echo "python$$v: not found, skipped"; continue; fi; \
	  $(MAKE) --no-print-directory VENV=.venv-$$v PYTHON=$$py .venv-$$v/.installed; \
	  echo "== Python $$v"; .venv-$$v/bin/python -m pytest -q -p no:randomly; \
	done

# Style and types (configured in pyproject.toml). Not yet part of `make test`:
# the tree needs one `ruff format` / `ruff check --fix` pass and the mypy
# findings fixed first (see README, "Checks").
lint: setup
	$(VENV)/bin/ruff check src tests
	$(VENV)/bin/ruff format --check src tests
	$(VENV)/bin/mypy

bench: setup
	$(VENV)/bin/ladartui bench

setup: system-deps $(STAMP)

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

$(STAMP): pyproject.toml
	test -x $(VENV)/bin/python || $(PYTHON) -m venv $(VENV)
	$(VENV)/bin/python -m pip install -q --disable-pip-version-check "pip==25.3" "setuptools==80.9.0"
	$(VENV)/bin/python -m pip install -q --disable-pip-version-check -e ".[test]"
	touch $(STAMP)
