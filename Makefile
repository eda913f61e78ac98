# Thin wrapper: the README's two commands. Everything real lives in CMake and deploy/.
PRESET ?= release
BUILD  := build/$(PRESET)
OUT    ?= out
JOBS   ?= $(shell nproc)

RUN_BUILD := build/$(PRESET)-run

.PHONY: all deps deps-run configure build build-run run serve test bench fuzz container-test fresh-run-time clean

all: build

# Everything: build, runtime, and what tests, fuzzing and benchmarks use.
deps:
	@bash deploy/install-deps.sh

# What building and running levelsetd needs, nothing more (make run, make serve).
deps-run:
	@bash deploy/install-deps.sh build runtime

configure: deps
	@cmake --preset $(PRESET) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# levelsetd alone, in its own build folder without tests or benchmarks (issue 18: make run
# built the unit tests, fuzz replays and OpenVDB benchmarks it never ran).
build-run: deps-run
	@cmake --preset $(PRESET) -B $(RUN_BUILD) -DLEVELSET_BUILD_TESTS=OFF -DLEVELSET_BUILD_BENCH=OFF -DLEVELSET_BUILD_GUI=OFF >/dev/null
	@cmake --build $(RUN_BUILD) --target levelsetd -j $(JOBS)

# Main job on an embedded default: the surface reconstruction from 20000 points sampled on
# the built-in torus knot (no external files); prints the progress and where the outputs went.
run: build-run
	@$(RUN_BUILD)/server/levelsetd run configs/jobs/reconstruct_knot.conf -o $(OUT)

# The daemon on its defaults (127.0.0.1:8080, data in $XDG_STATE_HOME/levelset); Ctrl-C stops it.
serve: build-run
	@$(RUN_BUILD)/server/levelsetd serve

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

# The container image built from deploy/Dockerfile and run here (issue 18): dockerd on its own
# socket, a debootstrap base from the apt mirror, health, upload, job, frames, mesh, SIGTERM,
# restart on the volume; prints the phase timings, image size and time to ready.
container-test:
	@bash deploy/install-deps.sh container
	@/usr/bin/python3 tests/container/container_test.py

# `make run` timed on a fresh machine: the debootstrap base as a container with the repository
# copied in (not part of CI).
fresh-run-time:
	@bash deploy/install-deps.sh container
	@/usr/bin/python3 tests/container/fresh_run_time.py

clean:
	rm -rf build $(OUT)
