# StrideFix — the entry point. `make demo` runs the default SIL walk end to end; `make test` runs
# every test. Both install what is missing first (make deps). Variables can be overridden:
#   make test BUILD=build-dbg CMAKE_BUILD_TYPE=Debug
BUILD ?= build
VENV ?= .venv
CMAKE_BUILD_TYPE ?= RelWithDebInfo
JOBS ?= 2
PY := $(VENV)/bin/python
# the lab (benchmarks, real-data benches, the papers' experiments): stridefix-lab
LAB := $(PY) -m stridefix_lab.cli
DEMO_OUT ?= out/demo
STRIDEFIXD := $(BUILD)/firmware/stridefixd

.PHONY: all deps build install wheel test test-c test-python lint demo bench clean help change-indication \
	gates check-static check-clang check-asan reliability soak check-fuzz fuzz check-arm spy

all: build

help:
	@echo "make demo   - install what is missing, build, run the default SIL walk, write $(DEMO_OUT)/report.html"
	@echo "make test   - install what is missing, build, run every test (C, Python, end to end), lint and gates"
	@echo "make lint   - ruff (lint + format check) on all Python, mypy on the analyzer (strict on io, datasets)"
	@echo "make bench  - benchmarks (SIL PDR at each pace; real-data PDR distance, fusion and crowd-built map; particle cost; controller); writes out/bench/*.json"
	@echo "make reliability - the default SIL walk with each bus/board fault vs clean; out/bench/reliability.json"
	@echo "make soak   - an 8-hour SIL walk with faults through stridefixd: RSS at 1 h and 8 h, events accounted"
	@echo "make change-indication - rewrite tests/change_indication/*.csv (commit them with a behaviour change)"
	@echo "make spy    - lcm-spy with the StrideFix Java types on LCM_URL (e.g. make spy LCM_URL='udpm://239.255.76.67:7667?ttl=0'; default: LCM's)"
	@echo "make deps   - install Debian packages and the Python venv ($(VENV)) if missing"
	@echo "make build  - CMake build into $(BUILD)/"
	@echo "make install PREFIX=P - cmake --install $(BUILD) into P (default $(PREFIX)): stridefixd, unit, man page, configs, core library"
	@echo "make wheel  - dist/stridefix-<version>-*.whl: the Python product with the LCM types, board.dbc and the native solver (no lab)"
	@echo "make gates  - the C/C++ quality gates below, one after the other"
	@echo "make check-static - cppcheck on firmware/ (suppressions: tools/cppcheck.supp); fails on a finding"
	@echo "make check-clang  - the whole tree with clang/clang++ (warnings are errors) into build-clang/, ctest"
	@echo "make check-asan   - firmware + C tests with ASan+UBSan and SF_ASSERT on into build-asan/, ctest"
	@echo "make check-fuzz   - each libFuzzer harness of tests/fuzz for $(FUZZ_CHECK_SECONDS) s (clang, ASan+UBSan) into build-fuzz/"
	@echo "make fuzz   - the same, $(FUZZ_SECONDS) s per harness (FUZZ_SECONDS=...; FUZZ_HARNESSES=\"site config\")"
	@echo "make check-arm    - the core and its tests cross-built for the unit's 32-bit ARM into build-arm/, ctest under qemu, size <= 128 KiB text"
	@echo "make clean  - remove $(BUILD)/, build-clang/, build-asan/, build-fuzz/, build-arm/ and out/"

deps:
	@BUILD=$(BUILD) VENV=$(VENV) tools/deps.sh

# $(call configure,DIR,EXTRA_CMAKE_ARGS): CMake into DIR, its output kept in DIR/cmake.log (shown on failure).
configure = mkdir -p $(1) && cmake -S . -B $(1) -DSTRIDEFIX_PYTHON=$(abspath $(PY)) $(2) > $(1)/cmake.log 2>&1 \
	|| { cat $(1)/cmake.log; exit 1; }

build: deps
	@$(call configure,$(BUILD),-DCMAKE_BUILD_TYPE=$(CMAKE_BUILD_TYPE))
	@cmake --build $(BUILD) -j $(JOBS)

# What goes where: cmake/install.cmake (docs/deployment.md "Install on a logger").
PREFIX ?= /usr/local
install: build
	cmake --install $(BUILD) --prefix $(PREFIX)

# The product wheel, with what $(BUILD) generated for Python (setup.py; docs/deployment.md "The Python product").
wheel: build
	@PY=$(PY) tools/wheel.sh $(BUILD) dist

# Everything CI checks: the C and Python tests, the Python lint/type gates and the C/C++ gates.
test: build
	@$(MAKE) --no-print-directory test-c test-python lint gates

lint: deps
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(VENV)/bin/mypy

# lcm-spy on the live channels (stridefix spy: java -cp lcm.jar:stridefix_lcmtypes.jar lcm.spy.Spy).
spy: build
	STRIDEFIX_LCMTYPES_JAR=$(abspath $(BUILD))/lcmtypes/java/stridefix_lcmtypes.jar \
		$(PY) -m stridefix_analyzer.cli spy $(if $(LCM_URL),--lcm-url '$(LCM_URL)')

test-c:
	cd $(BUILD) && ctest --output-on-failure

test-python:
	STRIDEFIXD=$(abspath $(STRIDEFIXD)) $(PY) -m pytest -q

change-indication: build
	STRIDEFIXD=$(abspath $(STRIDEFIXD)) $(PY) tests/change_indication/replay.py --out tests/change_indication

demo: build
	@bash tools/demo.sh "$(DEMO_OUT)" "$(STRIDEFIXD)" "$(VENV)"

MSINDOOR ?= ../shared/data/msindoor
GSD ?= ../shared/data/gsd
IPIN2023 ?= ../shared/data/ipin2023
# Every bench runs even when one misses its target; the goal fails at the end if any did.
bench: build
	@status=0; \
	$(LAB) bench all --stridefixd $(STRIDEFIXD) --out out/bench || status=1; \
	if [ -d "$(MSINDOOR)" ]; then \
		$(LAB) crowd experiment --msindoor $(MSINDOOR) --check-targets \
			--stridefixd $(STRIDEFIXD) --out out/bench/crowd || status=1; \
	fi; \
	results=""; \
	for floor in $(MSINDOOR)/site1/F2 $(MSINDOOR)/site2/F3; do \
		if [ -d "$$floor" ]; then \
			name=$$(basename $$(dirname $$floor))-$$(basename $$floor); \
			$(LAB) realbench pdr-distance --floor "$$floor" --stridefixd $(STRIDEFIXD) \
				--out out/bench/realbench/$$name || status=1; \
			$(LAB) realbench --format msindoor "$$floor" --true-start --quiet \
				--stridefixd $(STRIDEFIXD) --out out/bench/realbench/$$name-fusion/results.json || status=1; \
			results="$$results out/bench/realbench/$$name-fusion/results.json"; \
			$(LAB) realbench crowd-map --format msindoor "$$floor" --quiet \
				--stridefixd $(STRIDEFIXD) --cache out/bench/realbench/$$name-fusion/cache \
				--out out/bench/realbench/$$name-crowd-map/results.json || status=1; \
			results="$$results out/bench/realbench/$$name-crowd-map/results.json"; \
		else echo "bench: $$floor not found, real-data PDR check skipped"; fi; \
	done; \
	if [ -d "$(IPIN2023)" ]; then \
		$(LAB) realbench --format gsd "$(IPIN2023)" --true-start --quiet \
			--stridefixd $(STRIDEFIXD) --out out/bench/realbench/ipin2023-fusion/results.json || status=1; \
		results="$$results out/bench/realbench/ipin2023-fusion/results.json"; \
	fi; \
	if [ -d "$(GSD)" ]; then \
		$(LAB) realbench --format gsd "$(GSD)" --true-start --quiet \
			--stridefixd $(STRIDEFIXD) --out out/bench/realbench/gsd-fusion/results.json || status=1; \
		results="$$results out/bench/realbench/gsd-fusion/results.json"; \
	fi; \
	$(LAB) bench real-targets --stridefixd $(STRIDEFIXD) --results $$results || status=1; \
	if [ $$status -ne 0 ]; then echo "bench: FAILED: a target was missed or a bench failed (TARGET MISSED lines above)"; fi; \
	exit $$status

# Bus and board faults (exit 1 when a fault is not recovered) and the 8-hour soak; not in make test.
reliability: build
	$(LAB) bench reliability --stridefixd $(STRIDEFIXD) --out out/bench

soak: build
	$(LAB) bench soak --stridefixd $(STRIDEFIXD) --out out/bench

# Quality gates (CI runs them next to make test). check-static reads the generated CAN and LCM headers,
# so it needs the build; the others are separate build trees with their own compiler, flags or target.
gates: check-static check-clang check-asan check-fuzz check-arm

check-static: build
	cppcheck --std=c11 --enable=warning,style,performance,portability --error-exitcode=1 --quiet \
		--inline-suppr --suppressions-list=tools/cppcheck.supp \
		-Ifirmware/core -Ifirmware/board -I$(BUILD)/gen/can -I$(BUILD)/gen/schemes -I$(BUILD)/gen/site_ranges -I$(BUILD)/lcmtypes/c \
		firmware/core firmware/board firmware/app

check-clang: deps
	@$(call configure,build-clang,-DCMAKE_BUILD_TYPE=$(CMAKE_BUILD_TYPE) -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++)
	@cmake --build build-clang -j $(JOBS)
	cd build-clang && ctest --output-on-failure

# Debug: no NDEBUG, so SF_ASSERT is live. No native module (a sanitized one cannot load into Python).
check-asan: deps
	@$(call configure,build-asan,-DCMAKE_BUILD_TYPE=Debug -DSF_SANITIZE=ON -DSF_NATIVE=OFF)
	@cmake --build build-asan -j $(JOBS)
	cd build-asan && ctest --output-on-failure

# The unit's processor: the estimator core, the CAN codec and the core tests cross-compiled
# for 32-bit ARM (Debian armhf, cmake/toolchain-armhf.cmake; SF_CORE_ONLY leaves out what needs LCM,
# inih or Ceres), the tests run by ctest under qemu-arm, then the core's size against its text budget
# (tools/core_size.sh, written to build-arm/core_size.json).
ARM_BUILD ?= build-arm
ARM_SIZE ?= arm-linux-gnueabihf-size
CORE_TEXT_BUDGET_B ?= 131072
check-arm: deps
	@$(call configure,$(ARM_BUILD),-DCMAKE_BUILD_TYPE=$(CMAKE_BUILD_TYPE) -DSF_CORE_ONLY=ON \
		-DCMAKE_TOOLCHAIN_FILE=$(abspath cmake/toolchain-armhf.cmake))
	@cmake --build $(ARM_BUILD) -j $(JOBS)
	cd $(ARM_BUILD) && ctest --output-on-failure
	@tools/core_size.sh $(ARM_SIZE) $(ARM_BUILD)/firmware/libsf_core.a $(ARM_BUILD)/core_size.json $(CORE_TEXT_BUDGET_B)

# libFuzzer (docs/reliability.md "Fuzzing"): clang with ASan+UBSan, SF_ASSERT live, -O1. Each harness starts from
# tests/fuzz/corpus/<h> and crashers/<h> (read only) and grows build-fuzz/corpus/<h>; a finding is
# written to build-fuzz/artifacts/<h>/ and fails the goal (keep it in tests/fuzz/crashers/<h>/).
FUZZ_HARNESSES ?= candump board_rx lcm_input site config
FUZZ_CHECK_SECONDS ?= 28
FUZZ_SECONDS ?= 600
FUZZ_FLAGS ?= -timeout=10 -rss_limit_mb=2048 -print_final_stats=1
define run_fuzzers
	@$(call configure,build-fuzz,-DCMAKE_BUILD_TYPE=Debug -DCMAKE_C_FLAGS=-O1 -DSF_SANITIZE=ON -DSF_FUZZ=ON \
		-DSF_NATIVE=OFF -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++)
	@cmake --build build-fuzz -j $(JOBS) --target $(addprefix fuzz_,$(FUZZ_HARNESSES)) > build-fuzz/build.log 2>&1 \
		|| { cat build-fuzz/build.log; exit 1; }
	@for h in $(FUZZ_HARNESSES); do \
		mkdir -p build-fuzz/corpus/$$h build-fuzz/artifacts/$$h; \
		echo "fuzz: $$h for $(1) s"; \
		crashers=$$(test -d tests/fuzz/crashers/$$h && echo tests/fuzz/crashers/$$h); \
		build-fuzz/tests/fuzz/fuzz_$$h -max_total_time=$(1) $(FUZZ_FLAGS) -artifact_prefix=build-fuzz/artifacts/$$h/ \
			build-fuzz/corpus/$$h tests/fuzz/corpus/$$h $$crashers > build-fuzz/fuzz_$$h.log 2>&1 \
			|| { tail -60 build-fuzz/fuzz_$$h.log; echo "fuzz: $$h FAILED (input in build-fuzz/artifacts/$$h/)"; exit 1; }; \
		grep -E "stat::(number_of_executed_units|peak_rss_mb)" build-fuzz/fuzz_$$h.log | tr -s ' \n' ' '; \
		grep -o "cov: [0-9]* ft: [0-9]* corp: [0-9/]*[a-zA-Z]*" build-fuzz/fuzz_$$h.log | tail -1; \
	done
endef

# The Python importers' property tests (hypothesis, tests/python/realdata/test_importer_properties.py):
# about 50 examples a second, so FUZZ_SECONDS per property; prints the examples each one ran.
define fuzz_importers
	@STRIDEFIX_HYPOTHESIS_EXAMPLES=$$(( $(1) * 50 )) $(PY) -m pytest -q -p no:cacheprovider \
		--hypothesis-show-statistics tests/python/realdata/test_importer_properties.py > build-fuzz/fuzz_importers.log 2>&1 \
		|| { tail -60 build-fuzz/fuzz_importers.log; echo "fuzz: importers FAILED"; exit 1; }
	@awk '/::test_/ { sub(/:$$/, ""); sub(/.*::/, ""); t = $$0 } /passing,/ { print "fuzz: " t ": " $$2 " examples passed" }' \
		build-fuzz/fuzz_importers.log
endef

check-fuzz: deps
	$(call run_fuzzers,$(FUZZ_CHECK_SECONDS))

fuzz: deps
	$(call run_fuzzers,$(FUZZ_SECONDS))
	STRIDEFIX_LIVE_FUZZ_SECONDS=$(FUZZ_SECONDS) $(PY) -m pytest -q -s -p no:cacheprovider tests/python/live/test_live_fuzz.py -k budget
	$(call fuzz_importers,$(FUZZ_SECONDS))

clean:
	rm -rf $(BUILD) build-clang build-asan build-fuzz $(ARM_BUILD) out
