# Thin wrapper: the README's two commands. Everything real lives in CMake and deploy/.
PRESET ?= release
BUILD  := build/$(PRESET)
OUT    ?= out
JOBS   ?= $(shell nproc)

.PHONY: all deps configure build run test bench fuzz clean

all: build

deps:
	@bash deploy/install-deps.sh

configure: deps
	@cmake --preset $(PRESET) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# Main job on an embedded default: built-in torus knot -> narrow band -> .lsg -> info.
run: build
	@mkdir -p $(OUT)
	@$(BUILD)/server/levelsetd primitive knot --resolution 256 --band 3 -o $(OUT)/knot.lsg
	@$(BUILD)/server/levelsetd info $(OUT)/knot.lsg
	@echo "outputs: $(abspath $(OUT))/knot.lsg"

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
