# The workspace's one entry point. Every target is idempotent: a second run with nothing changed
# installs nothing, builds nothing and returns in seconds.
#
#   make tutorial   set up, then play the tutorial headless into output/ (the main job)
#   make test       set up, then run every test (unit, gtest, end-to-end)
#   make test-under-load   the same tests with 8 CPU spinners beside them (a busy machine)
#   make bench      set up, then run the side-by-side benchmarks into output/bench/
#   make setup      Debian packages + venv + catkin build only
#
# ROS Python must run under Debian's /usr/bin/python3: the `python3` on PATH may be another one
# (pyenv) that cannot import rospy, and catkin_make would pick it. Everything here names it.

SHELL := /bin/bash
.SHELLFLAGS := -eo pipefail -c
.DEFAULT_GOAL := setup

WS := $(abspath $(dir $(lastword $(MAKEFILE_LIST))))
SYSTEM_PYTHON := /usr/bin/python3
VENV := $(WS)/.venv
VENV_PYTHON := $(VENV)/bin/python
# BUILD and DEVEL let several builds of one source tree live side by side (build, build_x, ...).
BUILD ?= build
DEVEL ?= devel
STAMPS := $(WS)/.make/$(BUILD)
OUTPUT ?= $(WS)/output
# The engine of `make tutorial`; empty: the simulator's default (the first of its --list-physics).
PHYSICS ?=
PYTEST_ARGS ?=

# Every command the targets and tests run, with its Debian package (or requirements.txt).
REQUIRED_COMMANDS := $(WS)/scripts/required-commands
COMMAND_PACKAGES := $(shell awk '!/^\#/ && NF && $$2 !~ /^(requirements.txt|workspace)$$/ {print $$2}' $(REQUIRED_COMMANDS) | sort -u)
# What the book's packages build against or run beside the simulator, each with the book's packages
# that need it.
BOOK_PACKAGES := $(shell awk '!/^\#/ && NF {print $$1}' $(WS)/scripts/book-packages)
# The libraries, headers and Python modules the build and the nodes use, and those commands' packages.
# The camera renderer: OpenGL and EGL through libglvnd (libegl-dev, libopengl-dev, libgl-dev's
# headers), Mesa's EGL driver and its software rasteriser (libegl-mesa0, libgl1-mesa-dri).
# The Gazebo panel of rviz (src/gazebo_ros_panels) builds against librviz-dev (Qt 5, pluginlib).
# The view's model handles (gazebo_ros.model_handles) serve rviz's interactive markers
# (python3-interactive-markers).
APT_PACKAGES := \
  ca-certificates build-essential cmake \
  ros-core-dev python3-rospy python3-rostest python3-rosbag python3-std-srvs libstd-srvs-dev ros-robot-state-publisher rviz \
  python3-geometry-msgs python3-sensor-msgs libsensor-msgs-dev python3-nav-msgs libnav-msgs-dev libtf2-msgs-dev python3-trajectory-msgs libtrajectory-msgs-dev python3-dynamic-reconfigure libdynamic-reconfigure-config-init-mutex-dev python3-visualization-msgs python3-std-msgs python3-tf2-msgs python3-actionlib-msgs libactionlib-msgs-dev \
  libode-dev libbullet-dev libdart-dev libdart-collision-ode-dev libassimp-dev liburdfdom-dev libsdformat-dev libeigen3-dev libgtest-dev \
  libmujoco-dev \
  libegl-dev libopengl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri \
  librviz-dev python3-interactive-markers \
  python3-matplotlib python3-numpy python3-venv python3-pip python3-psutil \
  python3-pytest python3-pytest-forked python3-pytest-xdist python3-pytest-timeout \
  procps python3-tk \
  $(COMMAND_PACKAGES) $(BOOK_PACKAGES)

# Set-up steps print one line each (what, how long); their full output goes to SETUP_LOG, and a
# failing step prints its own in full (scripts/step).
SETUP_LOG := $(WS)/.make/setup.log
STEP := $(WS)/scripts/step $(SETUP_LOG)
# The suite, as `make test` and `make test-under-load` run it. Six workers on two cores: much of a
# test's wall time is spent waiting (nodes starting, sim time passing, replies), not computing;
# with four, a quiet machine's cores stood idle a quarter of the run. Every minute a line says how
# far the suite is (onedof_harness/suite_progress.py). A test still running after 900 s (a hang)
# fails and the suite goes on to its summary (onedof_harness/forked_timeout.py): pytest-timeout's
# signal method would raise in the worker, outside the forked test, and end the whole session with
# an internal error and no summary of the tests that ran. The summary names each skipped test
# with its reason (-rs: the two-hosts test where network namespaces cannot be entered), and the 25
# slowest tests with their times (where a long run's time went). The default distribution (load):
# xdist's loadgroup, which would keep tests of one xdist_group on one worker, fails the session
# with an internal error when a worker it replaces (a test past its timeout) joins.
PYTEST_SUITE = $(VENV_PYTHON) -m pytest -p no:cacheprovider -p onedof_harness.suite_progress \
  -p onedof_harness.forked_timeout -n 6 --forked --timeout=900 --timeout-method=thread -rs \
  --durations=25 \
  $(PYTEST_ARGS) tests src
# test-under-load: this many CPU spinners beside the suite, stopped after it (bounded anyway).
LOAD_PROCESSES ?= 8
LOAD_MAX_SECONDS ?= 3600

# Rebuild when any source file changes (generated and cached files excluded).
SOURCES := $(shell find $(WS)/src -type f -not -name '*.pyc' -not -path '*/__pycache__/*' 2>/dev/null)

.PHONY: setup deps venv build commands host tutorial test test-under-load bench lint clean

setup: deps venv build commands host

# Says, without failing set-up, when this machine's host name does not resolve (no /etc/hosts line
# for it, as a minimal system or container may have): roslaunch and catkin look it up and fail,
# with errors that do not say why.
host:
	@name=$$(hostname); \
	if ! getent hosts "$$name" >/dev/null; then \
	  echo "set-up: warning: this machine's host name '$$name' does not resolve: roslaunch and" \
	       "catkin overlays (the tutorial's launch files, some tests) will fail. Add the line" \
	       "'127.0.1.1 $$name' to /etc/hosts, as Debian's installer writes it."; \
	fi

# Fails set-up, naming the package to install, when a command the targets or tests run is missing.
# A PACKAGE/EXECUTABLE entry is one `rosrun PACKAGE EXECUTABLE` runs: its manifest and executable
# are looked up as rosrun does (the package's libexec folder, then the package's own folder).
commands: | deps venv build
	@source $(WS)/$(DEVEL)/setup.bash; \
	missing=$$(awk '!/^#/ && NF {print $$1 " (" $$2 ")"}' $(REQUIRED_COMMANDS) | while read command from; do \
	  case "$$command" in \
	    */*) package=$${command%/*} executable=$${command#*/}; \
	         { dir=$$(rospack find $$package) && { catkin_find --libexec $$package $$executable; \
	           find -L "$$dir" -type f -name $$executable -perm /111; } | grep -q .; } >/dev/null 2>&1 \
	           || echo "  rosrun $$package $$executable $$from";; \
	    *) PATH=$(VENV)/bin:$(WS)/$(DEVEL)/bin:$$PATH command -v "$$command" >/dev/null || echo "  $$command $$from";; \
	  esac; done); \
	if [ -n "$$missing" ]; then \
	  echo "set-up: these commands are missing (from $(REQUIRED_COMMANDS)):"; echo "$$missing"; exit 1; fi

# Installs the Debian packages only when one is missing (dpkg-query answers in well under a second;
# a package named twice, as a command's and as the book's, is one).
# The step says how many packages apt installs (a simulated install counts them: those named here
# and what they depend on, which depends on what the machine has); the names go to the log.
deps:
	@missing=$$( { dpkg-query -W -f='$${Package} $${db:Status-Status}\n' $(APT_PACKAGES) 2>/dev/null || true; } \
	  | awk '$$2 == "installed" {print $$1}' | sort | comm -13 - <(tr ' ' '\n' <<< "$(APT_PACKAGES)" | grep . | sort -u)); \
	if [ -n "$$missing" ]; then \
	  sudo=""; [ "$$(id -u)" -eq 0 ] || sudo=sudo; \
	  $(STEP) "deps: apt-get update" $$sudo apt-get update; \
	  named=$$(wc -w <<< "$$missing"); \
	  total=$$(apt-get install -s --no-install-recommends $$missing 2>/dev/null | grep -c '^Inst ') \
	    || total=""; \
	  what="$${total:-the} Debian packages (the workspace's $$named and what they depend on"; \
	  $(STEP) "deps: installing $$what, the names in $(SETUP_LOG:$(WS)/%=%))" \
	    $$sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends $$missing; \
	fi

venv: $(WS)/.make/venv

$(WS)/.make/venv: $(WS)/requirements.txt | deps
	@[ -x $(VENV_PYTHON) ] || $(STEP) "venv: creating $(VENV)" \
	  $(SYSTEM_PYTHON) -m venv --system-site-packages $(VENV)
	@$(STEP) "venv: pip install -r requirements.txt" \
	  $(VENV_PYTHON) -m pip install --disable-pip-version-check -r $(WS)/requirements.txt
	@mkdir -p $(STAMPS) && touch $@

build: $(STAMPS)/build

$(STAMPS)/build: $(SOURCES) $(WS)/Makefile | deps venv
	@$(STEP) "build: catkin_make (the nodes, messages and gtests, into $(BUILD)/ and $(DEVEL)/)" \
	  env -u PYTHONPATH -C $(WS) catkin_make -j2 --build $(BUILD) -DCATKIN_DEVEL_PREFIX=$(WS)/$(DEVEL) \
	  -DPYTHON_EXECUTABLE=$(SYSTEM_PYTHON) -DCMAKE_BUILD_TYPE=Release -DCATKIN_ENABLE_TESTING=ON
	@mkdir -p $(STAMPS) && touch $@

# The main job: the whole tutorial, headless, into $(OUTPUT).
tutorial: setup
	source $(WS)/$(DEVEL)/setup.bash && rosrun onedof_sim play_tutorial --output $(OUTPUT) $(if $(PHYSICS),--physics $(PHYSICS))

# Every test: Python unit tests in the packages, the gtests (collected by tests/test_gtest.py) and
# the end-to-end tests over real nodes, on private roscores (README, Testing).
test: setup
	source $(WS)/$(DEVEL)/setup.bash && cd $(WS) && $(PYTEST_SUITE)

# The same suite with $(LOAD_PROCESSES) CPU spinners beside it (tests/busy_machine.py): a machine
# as busy as a shared runner. The spinners stop when the suite ends, fails or is interrupted; the
# exit status is the suite's.
test-under-load: setup
	source $(WS)/$(DEVEL)/setup.bash && cd $(WS) && $(VENV_PYTHON) tests/busy_machine.py \
	  --processes $(LOAD_PROCESSES) --max-seconds $(LOAD_MAX_SECONDS) -- $(PYTEST_SUITE)

bench: setup
	source $(WS)/$(DEVEL)/setup.bash && rosrun onedof_sim benchmark --output $(OUTPUT)/bench

lint:
	catkin_lint -W1 --strict $(WS)/src

clean:
	rm -rf $(WS)/$(BUILD) $(WS)/$(DEVEL) $(STAMPS)
