# Thin wrapper around CMake. `make demo` and `make test` work on a fresh Debian 12 machine (as root):
# they install missing system packages first (packaging/install-deps.sh).
BUILD      ?= build
ASAN_BUILD ?= build-asan
FUZZ_BUILD ?= build-fuzz
FUZZ_TIME  ?= 60
# `make test` runs each fuzz target this many seconds (CI's bounded run; docs/fuzzing.md).
CI_FUZZ_TIME ?= 10
JOBS       ?= $(shell nproc)
CMAKE_ARGS ?=
# Debug information of the optimised tree: line tables (-g1: a backtrace or perf still names file and
# line) for `make demo`, `make build` and `make test`, which compile the libraries about a fifth
# faster than with full debug information (docs/PERFORMANCE.md, the test suite); `make package`
# builds with -g, the debug information Debian's -dbgsym packages carry.
DEBUG_INFO ?= -g1
RELEASE_FLAGS = -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 $(DEBUG_INFO) -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 $(DEBUG_INFO) -DNDEBUG"

.PHONY: all deps configure build build-app test test-unit test-asan fuzz-build fuzz demo package format clean

all: build

deps:
	@bash packaging/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo $(RELEASE_FLAGS) -DNELF_WERROR=ON -DNELF_BUILD_UNIT_TESTS=ON $(CMAKE_ARGS) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# Only the nelf binary and its module: what the demo runs (not the test suites and benchmarks).
build-app: configure
	@cmake --build $(BUILD) -j $(JOBS) --target nelf nelf_oiio

# All tests: the unit tests under AddressSanitizer + UndefinedBehaviorSanitizer (test-asan), the
# others (cli, gl, window, package, layering) in the optimised tree, which then leaves the unit
# tests out (NELF_BUILD_UNIT_TESTS=OFF: building and running them twice took CI minutes). Then
# each fuzz target for CI_FUZZ_TIME seconds. The sanitizer tree runs each unit suite as 4 gtest
# shards (NELF_UNIT_TEST_SHARDS): a process per test spent most of its time starting up.
# `make build && cd build && ctest` still runs them all. The sanitizer tree keeps line tables (-g1):
# what its reports' stacks name (file and line), and its build a few percent shorter than with -g.
test: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo $(RELEASE_FLAGS) -DNELF_WERROR=ON -DNELF_BUILD_UNIT_TESTS=OFF $(CMAKE_ARGS) >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)
	@$(MAKE) --no-print-directory test-asan
	@$(MAKE) --no-print-directory fuzz FUZZ_TIME=$(CI_FUZZ_TIME)

test-asan: deps
	@cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-g1 -DCMAKE_C_FLAGS_DEBUG=-g1 -DNELF_SANITIZE=ON -DNELF_WERROR=ON -DNELF_UNIT_TEST_SHARDS=4 $(CMAKE_ARGS) >/dev/null
	@cmake --build $(ASAN_BUILD) -j $(JOBS) --target nelf_unit_tests
	@cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --output-on-failure -j $(JOBS) -L unit

# libFuzzer targets (tests/fuzz, docs/fuzzing.md): a clang build of their own, then each target runs
# FUZZ_TIME seconds; fails on a crash, leak, timeout or out-of-memory input (kept in
# $(FUZZ_BUILD)/fuzz-artifacts/).
fuzz-build: deps
	@cmake -S . -B $(FUZZ_BUILD) -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DNELF_FUZZ=ON $(CMAKE_ARGS) >/dev/null
	@cmake --build $(FUZZ_BUILD) -j $(JOBS)

fuzz: fuzz-build
	@bash tests/fuzz/run_fuzzers.sh $(FUZZ_BUILD) $(FUZZ_TIME)

demo: build-app
	@bash packaging/demo.sh $(BUILD)/nelf

package:
	@$(MAKE) --no-print-directory build DEBUG_INFO=-g
	@cd $(BUILD) && cpack

format:
	@clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(FUZZ_BUILD) demo
