# Quick start: `make demo` and `make test`. Both install what is missing (apt), configure and build.
BUILD ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
JELLY = $(BUILD)/cli/jelly

.PHONY: all deps configure build test test-sanitize demo docs bench format clean

all: build

# `make test` also installs what only tests need (ParaView for jelly_paraview).
deps:
	bash scripts/install-deps.sh $(DEPS_FLAGS)
test: DEPS_FLAGS = --tests
docs: DEPS_FLAGS = --docs

# ccache, when installed (install-deps does), makes rebuilds after a checkout cheap.
LAUNCHER := $(if $(shell command -v ccache),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)

configure: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) $(LAUNCHER)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

# Tests run two at a time (JOBS) with OpenMP's default wait policy, as users run: the teams jelly
# sizes itself no longer spin against the other test (docs/CONTRIBUTING.md, "Build times").

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

# AddressSanitizer + UndefinedBehaviorSanitizer over the whole test suite, built with clang in
# its own directory (-O1, no debug information, no Python module: cmake/JellySanitize.cmake);
# there the fuzz targets are libFuzzer programs and ctest fuzzes each for JELLY_FUZZ_SECONDS
# (docs/fuzzing.md). Any sanitizer report fails the test that caused it. CI (.ci/run) passes
# SANITIZE_CMAKE_FLAGS and SANITIZE_CTEST_FLAGS to leave out what adds build time and no coverage.
SANITIZE_BUILD ?= build-sanitize
SANITIZE_CMAKE_FLAGS ?=
SANITIZE_CTEST_FLAGS ?=
SANITIZE_ENV = ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1 \
	LSAN_OPTIONS=suppressions=$(CURDIR)/tests/fuzz/lsan.supp:print_suppressions=0 \
	UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

test-sanitize: DEPS_FLAGS = --tests
test-sanitize: deps
	CC=clang CXX=clang++ cmake -S . -B $(SANITIZE_BUILD) -DCMAKE_BUILD_TYPE=Release \
	  -DJELLY_SANITIZE=ON -DJELLY_FUZZ=ON $(SANITIZE_CMAKE_FLAGS) $(LAUNCHER)
	cmake --build $(SANITIZE_BUILD) -j $(JOBS)
	$(SANITIZE_ENV) ctest --test-dir $(SANITIZE_BUILD) --output-on-failure -j $(JOBS) \
	  $(SANITIZE_CTEST_FLAGS)

# 3 s of the seed slope with RK4 (a few seconds of wall time), then the plots when
# scripts/plot.py is there, and the video (jelly render; exit 2 = built without the viewer).
demo: build
	@mkdir -p out
	$(JELLY) run scenes/seed_slope.json --duration 3 -o out/demo.h5 --overwrite
	@if [ -f scripts/plot.py ]; then /usr/bin/python3 scripts/plot.py out/demo.h5 -o out/demo.png; \
	else echo "demo: scripts/plot.py is not in this tree: no plots"; fi
	@status=0; $(JELLY) render out/demo.h5 -o out/demo.mp4 --overwrite || status=$$?; \
	if [ $$status -eq 2 ]; then echo "demo: no out/demo.mp4 (see above)"; \
	elif [ $$status -ne 0 ]; then exit $$status; fi
	@echo "demo: written:"; for f in out/demo.h5 out/demo.xdmf out/demo.png out/demo.mp4; do \
	  if [ -e $$f ]; then echo "  $(CURDIR)/$$f"; fi; done

# The documentation site, offline: build/site/index.html (scripts/build_docs.py; search works
# when served, e.g. `python3 -m http.server -d build/site`). The reference pages come from the
# programs, the Python module and the public headers: those targets are built first. mkdocs runs
# with --strict, and a reference page that cannot be generated is an error too.
docs: configure
	targets="jelly_cli jelly_bench"; \
	if cmake --build $(BUILD) --target help | grep -q jelly_python; then targets="$$targets jelly_python"; fi; \
	cmake --build $(BUILD) -j $(JOBS) --target $$targets
	/usr/bin/python3 scripts/build_docs.py --build $(BUILD) --require-all

format:
	clang-format -i $$(git ls-files '*.hpp' '*.cpp')

clean:
	rm -rf $(BUILD)
