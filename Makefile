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

.PHONY: all deps build python node-tests go-tools demo test check-includes test-cpp test-python test-matlab clean build-fuzz test-sanitize fuzz-smoke mbm-data
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
	@$(PYTHON) -m pip install -q -e 'clients/python[test,plot,batch]'
	@touch $@

python: $(VENV)/.installed

# Node tools the Python tests run to check recordings and the live endpoint with Foxglove's own libraries
# (issue 25): tests/node/read_mcap.mjs FILE.mcap (@mcap/core's indexed reader, protobufjs decoding of every
# message) and tests/node/foxglove_live.mjs WS_URL TOPIC COUNT [TIMEOUT_S] (@foxglove/ws-protocol's client).
# Their packages are installed with `npm ci` at the versions tests/node/package-lock.json pins, into
# $(NODE_TESTS) (never the source tree), beside copies of the scripts so that their imports resolve there:
# the tests run `node $(NODE_TESTS)/read_mcap.mjs ...`. npm runs again only when package.json or the lock file
# changes (the stamp in node_modules), a script is copied again when it changes. No package needs an install
# script (--ignore-scripts).
NODE_TESTS := $(BUILD)/node-tests
NODE_TEST_SCRIPTS := $(patsubst tests/node/%,$(NODE_TESTS)/%,$(wildcard tests/node/*.mjs))

$(NODE_TESTS)/node_modules/.graspsim-installed: tests/node/package.json tests/node/package-lock.json | deps
	@mkdir -p $(NODE_TESTS)
	@cp tests/node/package.json tests/node/package-lock.json $(NODE_TESTS)/
	@npm ci --prefix $(NODE_TESTS) --ignore-scripts --no-audit --no-fund --loglevel=error > /dev/null
	@touch $@

$(NODE_TESTS)/%.mjs: tests/node/%.mjs
	@mkdir -p $(NODE_TESTS)
	@cp $< $@

node-tests: $(NODE_TESTS)/node_modules/.graspsim-installed $(NODE_TEST_SCRIPTS)

demo: build python
	@deploy/run-demo.sh $(SERVER) $(PYTHON)

# The summary line ("100% tests passed, 0 tests failed out of N") and the tests that did not run; on a failure,
# the failing tests' output.
# The MotionBenchMaker problems the motion tests run on (tests/cpp/motion/mbm_scenes_test.cpp): vamp-planner's
# sdist from PyPI, fetched once into build/bench-data (tests/data/mbm.py).
mbm-data: python
	@$(PYTHON) tests/data/mbm.py fetch > /dev/null

test-cpp: build mbm-data
	@ctest --test-dir $(BUILD) --output-on-failure --progress -j2 > $(BUILD)/test-cpp.log 2>&1 \
	  || { grep -E -A40 '\[  FAILED  \]|\*\*\*Failed|\*\*\*Exception' $(BUILD)/test-cpp.log | head -n 150; tail -n 20 $(BUILD)/test-cpp.log; exit 1; }
	@sed -n '/tests passed/,$$p' $(BUILD)/test-cpp.log

# Go tools the Python tests run (issue 23), from the Go module proxy into $(TOOLS)/bin: grpc-health-probe (the
# fleet's HAProxy health check, tests/python/test_fleet.py) and kustomize (renders deploy/k8s for
# tests/python/test_deploy_files.py). Each is installed once; a version change here installs it again.
TOOLS := $(BUILD)/tools
GO_TOOLS := github.com/grpc-ecosystem/grpc-health-probe@v0.4.62 sigs.k8s.io/kustomize/kustomize/v5@v5.5.0
GO := $(shell command -v go || echo /usr/local/go/bin/go)

$(TOOLS)/.installed-%: | deps
	@mkdir -p $(TOOLS)
	@GOBIN=$(abspath $(TOOLS))/bin GOPATH=$(abspath $(TOOLS))/go GOFLAGS=-modcacherw $(GO) install $(subst +,/,$*) 2>&1 | grep -v '^go: downloading' || true
	@module=$(firstword $(subst @, ,$(subst +,/,$*))); name=$${module##*/}; \
	  if [[ $$name =~ ^v[0-9]+$$ ]]; then module=$${module%/*}; name=$${module##*/}; fi; \
	  test -x $(TOOLS)/bin/$$name && touch $@

go-tools: $(foreach t,$(GO_TOOLS),$(TOOLS)/.installed-$(subst /,+,$(t)))

test-python: build python node-tests go-tools
	@GRASPSIM_SERVER=$(abspath $(SERVER)) $(PYTHON) -m pytest -q tests/python

test-matlab: build
	@GRASPSIM_SERVER=$(abspath $(SERVER)) tests/matlab/run.sh

# The folder map of docs/architecture.md (issue 24): every #include of server/src and drivers/ against the folders
# it may include, and gRPC/protobuf headers nowhere below rpc/. Python 3's standard library only: runs first, in
# about a second, with no build.
check-includes:
	@python3 scripts/check_includes.py

test: check-includes test-cpp test-python test-matlab test-sanitize fuzz-smoke

# Bad input (issue 11, docs/fuzzing.md): one clang build in $(FUZZ_BUILD) holds the ASan + UBSan build of the C++
# tests and the libFuzzer targets of tests/fuzz.
FUZZ_BUILD := build-fuzz
FUZZ_TARGETS := urdf mjcf sdf mesh perception upload http_json modbus smp device_spec
# A fixed number of runs (not seconds) with a fixed seed: the same inputs on every machine and load, so CI is
# reproducible; about 10-20 s per target here. mesh starts a child process per input, upload a gRPC stream.
FUZZ_RUNS := 50000
FUZZ_RUNS_mesh := 60
FUZZ_RUNS_upload := 2000
# libsdformat copies its SDF schema for every text that gets past the XML check (50-100 ms under ASan): 10000 runs
# take about 20 s.
FUZZ_RUNS_sdf := 10000
# Targets run over their seed corpus only (no mutation) while a crash they find is open (docs/fuzzing.md, "Found").
# assimp_fuzz (Assimp in-process, whose crashes the server's mesh child process contains) is not run here.
FUZZ_SEEDS_ONLY :=
# An input may take 25 s; mesh's slowest are those its child process gives up on after its 10 s deadline.
SANITIZER_ENV := ASAN_OPTIONS=detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:hard_rss_limit_mb=3072:max_allocation_size_mb=2048 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:suppressions=$(abspath tests/fuzz/ubsan.supp) \
  LSAN_OPTIONS=suppressions=$(abspath tests/fuzz/lsan.supp):print_suppressions=0

$(FUZZ_BUILD)/build.ninja: CMakeLists.txt | deps
	@mkdir -p $(FUZZ_BUILD)
	@cmake -S . -B $(FUZZ_BUILD) -G Ninja -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo '-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG' \
	  '-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG' -DGRASPSIM_SANITIZE=ON -DGRASPSIM_FUZZ=ON \
	  > $(FUZZ_BUILD)/cmake-configure.log 2>&1 || (cat $(FUZZ_BUILD)/cmake-configure.log; exit 1)

build-fuzz: deps $(FUZZ_BUILD)/build.ninja
	@ninja -C $(FUZZ_BUILD) --quiet graspsim_tests fuzz_targets | sed '/^ninja: no work to do\.$$/d'

# Left out for time: the tests that took 45 s or more each under ASan + UBSan on these 2 cores (together 22 of
# the suite's 36 minutes of test time there), and since 2026-12-02 those of 60 s or more that test no bad input
# (9.5 of the 43.6 minutes of test time the rest took then: 21.8 min on the 2 cores). They run in test-cpp as
# usual. `make test-sanitize SANITIZE_SLOW=` runs them too.
SANITIZE_SLOW := ^(ScenePickPlace\.ASuccessfulRunCommitsUnlessTheSceneChangedMeanwhile|ArmPathRequestTest\.APathRunsFromTheStartToTheGoalAndItsTipPathWithIt|ArmPathRequestTest\.AGoalPoseIsReachedByTheTip|GraspQualityTest\.BoxJawGraspsMatchTheReference|GraspQualityTest\.EpsilonMatchesBruteForceReference|MotionPlannerTest\.PathsBetweenRandomConfigurationsNeverCollide|PickPlace\.MovesTheCubeToTheGoalOnCollisionFreePaths|GraspSimulateTest\.PlannedGraspsDoNotPenetrateTheObject|MotionCollisionCheckerTest\.NeverFreeWhereTheExactGeometryCollides|TactileContactTest\.DraggedObjectTracesTheStribeckCurveOfThePadLaw|PickPlace\.CancelStopsTheRun|MotionPlannerTest\.ReachesAGoalPoseAcrossThePost|WorkCycleTest\.MoreCoverageRisesFasterToTheSetPoint|MotionCollisionCheckerTest\.ExplainsWhatTouchesWhat|MotionCheckerMotionTest\.AcceptedSegmentsTouchNothingAlongTheirLength|MotionMbmTest\.SampledConfigurationsTheCheckerCallsFreeTouchNothing|MotionSphereKernelTest\.IsValidAgreesWithDoublePrecisionSpheres)$$
test-sanitize: build-fuzz mbm-data
	@if [[ -n '$(SANITIZE_SLOW)' ]]; then echo "test-sanitize: left out for time (run with SANITIZE_SLOW= to include): $(SANITIZE_SLOW)"; fi
	@$(SANITIZER_ENV) ctest --test-dir $(FUZZ_BUILD) --output-on-failure --progress -j2 \
	  $(if $(SANITIZE_SLOW),-E '$(SANITIZE_SLOW)') > $(FUZZ_BUILD)/test-sanitize.log 2>&1 \
	  || { grep -E -B2 -A40 'ERROR: (Address|Leak)Sanitizer|runtime error|\[  FAILED  \]' $(FUZZ_BUILD)/test-sanitize.log | head -n 150; \
	       tail -n 20 $(FUZZ_BUILD)/test-sanitize.log; echo "test-sanitize failed (log: $(FUZZ_BUILD)/test-sanitize.log)"; exit 1; }
	@grep -E '^[0-9]+% tests passed|^Total Test time' $(FUZZ_BUILD)/test-sanitize.log

# Each target for its FUZZ_RUNS over its seed corpus, with a fixed seed; new inputs go to a scratch corpus in the
# build tree (emptied first, so every run starts alike), crashes to $(FUZZ_BUILD)/fuzz-artifacts/.
fuzz-smoke: build-fuzz
	@mkdir -p $(FUZZ_BUILD)/fuzz-artifacts
	@for t in $(FUZZ_TARGETS); do \
	  rm -rf $(FUZZ_BUILD)/fuzz-corpus/$$t && mkdir -p $(FUZZ_BUILD)/fuzz-corpus/$$t && \
	  if [[ " $(FUZZ_SEEDS_ONLY) " == *" $$t "* ]]; then budget="-runs=0"; else case $$t in mesh) budget=-runs=$(FUZZ_RUNS_mesh);; upload) budget=-runs=$(FUZZ_RUNS_upload);; sdf) budget=-runs=$(FUZZ_RUNS_sdf);; *) budget=-runs=$(FUZZ_RUNS);; esac; fi; \
	  $(SANITIZER_ENV) $(FUZZ_BUILD)/bin/$${t}_fuzz -seed=1 $$budget -timeout=25 \
	    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix=$(FUZZ_BUILD)/fuzz-artifacts/$$t- \
	    $(FUZZ_BUILD)/fuzz-corpus/$$t tests/fuzz/corpus/$$t > $(FUZZ_BUILD)/fuzz-artifacts/$$t.log 2>&1 \
	  || { tail -n 60 $(FUZZ_BUILD)/fuzz-artifacts/$$t.log; echo "fuzz-smoke: $$t failed (log: $(FUZZ_BUILD)/fuzz-artifacts/$$t.log)"; exit 1; }; \
	  runs=$$(grep -o 'stat::number_of_executed_units: [0-9]*' $(FUZZ_BUILD)/fuzz-artifacts/$$t.log | grep -o '[0-9]*$$'); \
	  if [[ $$budget == -runs=0 ]]; then echo "fuzz-smoke: $$t: seed corpus only ($$runs inputs, no crash; mutation off while its known crashes are open, docs/fuzzing.md)"; \
	  else echo "fuzz-smoke: $$t: $$runs runs, no crash"; fi; \
	done

clean:
	rm -rf $(BUILD) $(FUZZ_BUILD)
