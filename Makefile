# StrideFix — the entry point. `make demo` runs the default SIL walk end to end; `make test` runs
# every test. Both install what is missing first (make deps). Variables can be overridden:
#   make test BUILD=build-dbg CMAKE_BUILD_TYPE=Debug
BUILD ?= build
VENV ?= .venv
CMAKE_BUILD_TYPE ?= RelWithDebInfo
JOBS ?= 2
PY := $(VENV)/bin/python
DEMO_OUT ?= out/demo
STRIDEFIXD := $(BUILD)/firmware/stridefixd

.PHONY: all deps build test test-c test-python demo bench clean help change-indication

all: build

help:
	@echo "make demo   - install what is missing, build, run the default SIL walk, write $(DEMO_OUT)/report.html"
	@echo "make test   - install what is missing, build, run every test (C, Python, end to end)"
	@echo "make bench  - benchmarks (SIL PDR at each pace; real-data PDR distance); writes out/bench/*.json"
	@echo "make change-indication - rewrite tests/change_indication/*.csv (commit them with a behaviour change)"
	@echo "make deps   - install Debian packages and the Python venv ($(VENV)) if missing"
	@echo "make build  - CMake build into $(BUILD)/"
	@echo "make clean  - remove $(BUILD)/ and out/"

deps:
	@BUILD=$(BUILD) VENV=$(VENV) tools/deps.sh

build: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=$(CMAKE_BUILD_TYPE) -DSTRIDEFIX_PYTHON=$(abspath $(PY)) > $(BUILD).cmake.log 2>&1 \
		|| { cat $(BUILD).cmake.log; exit 1; }
	@cmake --build $(BUILD) -j $(JOBS)

test: build
	@$(MAKE) --no-print-directory test-c test-python

test-c:
	cd $(BUILD) && ctest --output-on-failure

test-python:
	STRIDEFIXD=$(abspath $(STRIDEFIXD)) $(PY) -m pytest -q

change-indication: build
	STRIDEFIXD=$(abspath $(STRIDEFIXD)) $(PY) tests/change_indication/replay.py --out tests/change_indication

demo: build
	@bash tools/demo.sh "$(DEMO_OUT)" "$(STRIDEFIXD)" "$(VENV)"

MSINDOOR ?= ../shared/data/msindoor
bench: build
	$(PY) -m stridefix_analyzer.cli bench sil-pdr --stridefixd $(STRIDEFIXD) --out out/bench
	$(PY) -m stridefix_analyzer.cli bench aadr2015 --stridefixd $(STRIDEFIXD) --out out/bench
	$(PY) -m stridefix_analyzer.cli bench office-wifi --stridefixd $(STRIDEFIXD) --out out/bench
	$(PY) -m stridefix_native_reference --n 5000 --out out/bench/native_solver.json
	@for floor in $(MSINDOOR)/site1/F2 $(MSINDOOR)/site2/F3; do \
		if [ -d "$$floor" ]; then \
			$(PY) -m stridefix_analyzer.cli realbench pdr-distance --floor "$$floor" --stridefixd $(STRIDEFIXD) \
				--out out/bench/realbench/$$(basename $$(dirname $$floor))-$$(basename $$floor) || exit 1; \
		else echo "bench: $$floor not found, real-data PDR check skipped"; fi; \
	done

clean:
	rm -rf $(BUILD) $(BUILD).cmake.log out
