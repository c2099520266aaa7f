# graspsim: the two commands a newcomer needs are `make demo` and `make test`.
# Everything is installed by deploy/install-deps.sh (Debian packages) and pip (into build/venv).
# A second run of either is quick and quiet: every step skips what is already done.

SHELL := /bin/bash
.SHELLFLAGS := -o pipefail -c
BUILD := build
VENV := $(BUILD)/venv
PYTHON := $(VENV)/bin/python
SERVER := $(BUILD)/bin/graspsim-server
PROTOS := $(wildcard proto/graspsim/v1/*.proto)
CLIENT_FILES := clients/python/pyproject.toml clients/python/setup.py

.PHONY: all deps build python demo test test-cpp test-python test-matlab clean
all: build python

deps:
	@deploy/install-deps.sh

$(BUILD)/build.ninja: CMakeLists.txt | deps
	@mkdir -p $(BUILD)
	@cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo > $(BUILD)/cmake-configure.log 2>&1 \
	  || (cat $(BUILD)/cmake-configure.log; exit 1)

build: deps $(BUILD)/build.ninja
	@ninja -C $(BUILD) --quiet | sed '/^ninja: no work to do\.$$/d' 

$(VENV)/.installed: $(PROTOS) $(CLIENT_FILES) | deps
	@test -x $(PYTHON) || python3 -m venv $(VENV)
	@$(PYTHON) -m pip install -q -e 'clients/python[test,plot]'
	@touch $@

python: $(VENV)/.installed

demo: build python
	@deploy/run-demo.sh $(SERVER) $(PYTHON)

test-cpp: build
	@ctest --test-dir $(BUILD) --output-on-failure --progress -j2 | tail -n 3

test-python: build python
	@GRASPSIM_SERVER=$(abspath $(SERVER)) $(PYTHON) -m pytest -q tests/python

test-matlab: build
	@GRASPSIM_SERVER=$(abspath $(SERVER)) tests/matlab/run.sh

test: test-cpp test-python test-matlab

clean:
	rm -rf $(BUILD)
