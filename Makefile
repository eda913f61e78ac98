# Thin wrapper: the README's two commands. Everything real lives in CMake and deploy/.
PRESET ?= release
BUILD  := build/$(PRESET)
OUT    ?= out
JOBS   ?= $(shell nproc)

.PHONY: all deps configure build run serve test bench fuzz clean

all: build

deps:
	@bash deploy/install-deps.sh

configure: deps
	@cmake --preset $(PRESET) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# Main job on an embedded default: the surface reconstruction from 20000 points sampled on
# the built-in torus knot (no external files); prints the progress and where the outputs went.
run: build
	@$(BUILD)/server/levelsetd run configs/jobs/reconstruct_knot.conf -o $(OUT)

# The daemon on its defaults (127.0.0.1:8080, data in $XDG_STATE_HOME/levelset); Ctrl-C stops it.
serve: build
	@$(BUILD)/server/levelsetd serve

test: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# Benchmarks against OpenVDB (not part of the test suite; prints measured ratios).
bench: build
	@cmake --build $(BUILD) --target bench -j $(JOBS)

# libFuzzer run (clang, ASan + UBSan) of one fuzz target in build/fuzz; fails on any finding.
FUZZ_TARGET  ?= fuzz_formula
FUZZ_SECONDS ?= 60
fuzz: deps
	@bash tests/fuzz/run_libfuzzer.sh $(FUZZ_TARGET) $(FUZZ_SECONDS)

clean:
	rm -rf build $(OUT)
