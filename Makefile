# The two commands of the README: `make demo` and `make test`. Both install what is missing,
# configure with Ninja (and ccache when present) and build; see docs/ARCHITECTURE.md.
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
CCACHE := $(shell command -v ccache 2>/dev/null)
CMAKE_FLAGS := -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) \
  $(if $(CCACHE),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache,)
DEMO_DIR ?= $(BUILD_DIR)/demo

.PHONY: deps configure build install test test-asan fuzz-build fuzz-smoke demo dosimetry clean

deps:
	@bash scripts/install-deps.sh

$(BUILD_DIR)/build.ninja: | deps
	cmake -S . -B $(BUILD_DIR) $(CMAKE_FLAGS)

configure: deps $(BUILD_DIR)/build.ninja

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

# `make install PREFIX=DIR`: repose, ReposeCore, the Python package and the 3D Slicer CLI module
# folder DIR/lib/repose/cli-modules (docs/SLICER.md); the folder can be moved as a whole.
PREFIX ?= /usr/local
install: build
	cmake --install $(BUILD_DIR) --prefix $(PREFIX)

test: build fuzz-build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)
	cd $(FUZZ_DIR) && ctest --output-on-failure -j $(JOBS)

# The readers' libFuzzer targets (clang, ASan + UBSan) in their own build folder; `make test` runs
# each a few seconds (fuzz-smoke), and there the sanitizer gate: the unit tests of the readers,
# writers and the rasterizer's scan under the same sanitizers (ReposeSanitizedCoreTests);
# scripts/fuzz.sh runs long campaigns (docs/RELIABILITY.md).
FUZZ_DIR ?= build-fuzz
$(FUZZ_DIR)/build.ninja: | deps
	cmake -S . -B $(FUZZ_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release \
	  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
	  $(if $(CCACHE),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache,) \
	  -DREPOSE_FUZZ=ON -DREPOSE_BUILD_GUI=OFF -DREPOSE_BUILD_PYTHON=OFF \
	  -DREPOSE_BUILD_BENCH=OFF -DREPOSE_BUILD_TESTING=OFF

fuzz-build: $(FUZZ_DIR)/build.ninja
	cmake --build $(FUZZ_DIR) -j $(JOBS)

fuzz-smoke: fuzz-build
	cd $(FUZZ_DIR) && ctest --output-on-failure -j $(JOBS)

demo: build
	bash scripts/demo.sh $(BUILD_DIR) $(DEMO_DIR)

# Whole-body SAR per posture with openEMS (Python/examples/sar_per_posture.py, docs/DOSIMETRY.md):
# the phantom at rest, arm raised, leg stepped, 900 MHz plane wave, 10 mm cells; about a minute.
DOSIMETRY_DIR ?= $(BUILD_DIR)/dosimetry
dosimetry: build
	PYTHONPATH=$(CURDIR)/$(BUILD_DIR)/python REPOSE_BIN_DIR=$(CURDIR)/$(BUILD_DIR)/bin \
	  /usr/bin/python3 Python/examples/sar_per_posture.py --out $(DOSIMETRY_DIR)

# The whole suite under AddressSanitizer + UndefinedBehaviorSanitizer, in its own build folder
# (Release with line tables only: full -g on the CGAL and VTK templates multiplies build time).
ASAN_DIR ?= build-asan
test-asan: deps
	cmake -S . -B $(ASAN_DIR) $(CMAKE_FLAGS) -DREPOSE_SANITIZE=ON -DREPOSE_BUILD_BENCH=OFF
	cmake --build $(ASAN_DIR) -j $(JOBS)
	cd $(ASAN_DIR) && ASAN_OPTIONS=$(ASAN_OPTIONS_TEST) UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/Testing/Sanitizers/lsan.supp \
	  ctest --output-on-failure -j $(JOBS) -LE no-asan
ASAN_OPTIONS_TEST := detect_leaks=1:abort_on_error=1:strict_string_checks=1:check_initialization_order=1

clean:
	rm -rf $(BUILD_DIR) $(ASAN_DIR) $(FUZZ_DIR)

.PHONY: bench bench-large bench-micro bench-sweep bench-warp-mpi
# Benchmarks: speed is measured here, never in unit tests (docs/PERFORMANCE.md).
# `make bench`: every figure against its baseline at three sizes (< 15 min); results and plot in
# $(BUILD_DIR)/bench. `make bench-large` adds the seed's scales (~120M, ~260M, ~860M out of core)
# and the whole pose job on the reference grid at 1 mm and 0.5 mm, in core and slab by slab.
bench: build
	/usr/bin/python3 bench/run_bench.py --build $(BUILD_DIR) --out $(BUILD_DIR)/bench

bench-large: build
	/usr/bin/python3 bench/run_bench.py --build $(BUILD_DIR) --out $(BUILD_DIR)/bench --large
	/usr/bin/python3 bench/pose_large_bench.py --build $(BUILD_DIR) --out $(BUILD_DIR)/bench-pose-large
	/usr/bin/python3 bench/rig_large_bench.py --build $(BUILD_DIR) --out $(BUILD_DIR)/bench-rig-large

# Posture-sweep throughput in one process and on 2 MPI ranks (docs/PERFORMANCE.md).
bench-sweep: build
	/usr/bin/python3 bench/sweep_bench.py --build $(BUILD_DIR) --out $(BUILD_DIR)/bench-sweep

# `repose warp --mpi`: one ~860M-voxel grid out of core in one process and over 1 and 2 ranks.
bench-warp-mpi: build
	/usr/bin/python3 bench/warp_mpi_bench.py --build $(BUILD_DIR) --out $(BUILD_DIR)/bench-warp-mpi

# The component benchmarks one by one (Google Benchmark tables).
bench-micro: build
	$(BUILD_DIR)/bin/ReposeIOBench --benchmark_min_time=0.2
	$(BUILD_DIR)/bin/ReposeCageBench --benchmark_min_time=0.2
	$(BUILD_DIR)/bin/ReposeTransferMeshBench
	$(BUILD_DIR)/bin/ReposeFrameBench --benchmark_min_time=0.5
	$(BUILD_DIR)/bin/ReposeRasterBench
	$(BUILD_DIR)/bin/ReposeRefinementBench
	$(BUILD_DIR)/bin/ReposeForearmBench

# The soak tests' long runs (Testing/Soak, docs/RELIABILITY.md): 500 cycles of open, live posing,
# 50 edits, export and close through the Logic and through the Python module, a corrupt file
# every tenth cycle; resident memory must grow less than 1 KiB a cycle after 100 cycles of
# warm-up. About 30 minutes (they run side by side); `make test` runs short versions.
.PHONY: soak
SOAK_DIR ?= $(BUILD_DIR)/soak
soak: build
	mkdir -p $(SOAK_DIR)
	$(BUILD_DIR)/bin/ReposeLogicSoak --cycles 500 --warmup 100 --series $(SOAK_DIR)/logic.csv \
	  > $(SOAK_DIR)/logic.json & logic=$$!; \
	PYTHONPATH=$(CURDIR)/$(BUILD_DIR)/python REPOSE_SOURCE_DIR=$(CURDIR) /usr/bin/python3 \
	  Testing/Soak/python_soak.py --cycles 500 --warmup 100 --series $(SOAK_DIR)/python.csv \
	  > $(SOAK_DIR)/python.json; python=$$?; wait $$logic; logic=$$?; \
	cat $(SOAK_DIR)/logic.json $(SOAK_DIR)/python.json; test $$logic = 0 -a $$python = 0
