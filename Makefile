# The two entry points of the README. Both install dependencies (Debian packages), configure and build.
#   make demo   the standard suite (one repetition per cell), rendered, with the report: out/demo/report/index.html
#   make test   run the test suite
#   make demo-full   the standard suite with its own five repetitions: out/demo-full/report/index.html
PRESET ?= release
BUILD := build/$(PRESET)
GROWBENCH := $(BUILD)/harness/growbench
JOBS ?= $(shell nproc)
# Repetitions per cell in `make demo` (a number, or "suite" for the standard suite's own).
DEMO_REPETITIONS ?= 1

.PHONY: all deps configure build cli test demo demo-full peers bench plugin-bench gate baseline schema readme-params plugin-sdk fuzz sanitize format clean

all: build

deps:
	bash scripts/install-deps

configure: deps
	cmake --preset $(PRESET)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

# Only the growbench binary: what the demos need (no tests, no micro-benchmarks).
cli: configure
	cmake --build $(BUILD) -j $(JOBS) --target growbench

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

demo: cli
	bash scripts/demo $(GROWBENCH) out/demo $(DEMO_REPETITIONS)

demo-full: cli
	bash scripts/demo $(GROWBENCH) out/demo-full suite

# growbench against its peers (bench/peers/README.md): npm lindenmayer (pinned by bench/peers/package-lock.json),
# Blender's IvyGen add-on (Debian's blender, scripts/peers-packages) and a nanoflann reference, each on the same
# input as growbench, alternating, PEERS_REPETITIONS times; writes out/peers/peers.json and its report page
# out/peers/report/index.html. Not part of `make test`: Blender is a large install.
PEERS_REPETITIONS ?= 5
peers: cli
	bash scripts/install-deps --peers
	cd bench/peers && npm ci --no-audit --no-fund
	cmake --build $(BUILD) -j $(JOBS) --target spacecol_reference
	/usr/bin/python3 scripts/peers --growbench $(GROWBENCH) --reference $(BUILD)/bench/peers/spacecol_reference \
	  --repetitions $(PEERS_REPETITIONS) --out out/peers
	/usr/bin/python3 reports/report.py --peers out/peers/peers.json --out out/peers/report

# The deterministic regression gate (CI runs it after the tests): the quick suite once, single-threaded,
# one trial per core at a time (instruction counts do not depend on what runs beside them),
# under callgrind, its files checked against the generated schema, compared with the committed baseline.
# Instruction counts depend on the compiler flags: the baseline is made with the CI preset (make baseline PRESET=ci).
GATE := $(BUILD)/gate
gate: build
	rm -rf $(GATE)
	$(GROWBENCH) suite bench/suites/quick.json --instructions --out $(GATE) -q > $(BUILD)/gate.log
	/usr/bin/python3 scripts/check-schema $(GATE)/results.json $(GATE)/journal.jsonl reports/baselines/quick.json
	$(GROWBENCH) compare reports/baselines/quick.json $(GATE)/results.json

# Accept an intended change: rewrite reports/baselines/quick.json from a fresh gate run (commit it).
baseline: build
	rm -rf $(GATE)
	$(GROWBENCH) suite bench/suites/quick.json --instructions --out $(GATE) -q > $(BUILD)/gate.log
	$(GROWBENCH) baseline update $(GATE)/results.json --baseline reports/baselines/quick.json

# Rewrite harness/record/results.schema.json from the record declarations (commit it; the test
# Record.SchemaFileIsGenerated fails while the committed file differs from the binary's).
schema: cli
	$(GROWBENCH) schema > harness/record/results.schema.json

# Fill the parameter tables in algorithms/*/README.md from `growbench list --markdown NAME` (commit them;
# the ctest readme.params fails while a committed table differs from the binary's).
readme-params: cli
	/usr/bin/python3 scripts/readme-params $(GROWBENCH)

# The plugin SDK as a user meets it: install into a temporary prefix, build examples/plugin against it,
# run it in a suite beside a built-in and report it (scripts/test-plugin-sdk).
plugin-sdk: cli
	bash scripts/test-plugin-sdk $(BUILD)

bench: build
	$(BUILD)/bench/growbench_bench

# What the plugin ABI costs: the built-in spacecol against the same source built as a plugin, side by
# side in one suite (bench/suites/plugin-boundary.json), then their growth medians.
plugin-bench: build
	$(GROWBENCH) suite bench/suites/plugin-boundary.json --plugin $(BUILD)/plugins/spacecol_plugin.so \
	  --out out/plugin-boundary -q
	$(GROWBENCH) summary out/plugin-boundary/results.json

# The libFuzzer targets (fuzz/README.md), built by the asan preset (clang) in build/asan, JOBS at a time,
# each for FUZZ_SECONDS on its seed corpus; fails on any finding (CI runs it).
FUZZ_SECONDS ?= 60
fuzz: deps
	cmake --preset asan
	cmake --build build/asan -j $(JOBS) --target fuzz
	bash scripts/fuzz --build build/asan --seconds $(FUZZ_SECONDS) --jobs $(JOBS)

# The test suite under ASan and UBSan, then the parallel algorithm tests under TSan (scripts/sanitize; CI
# runs both).
sanitize: deps
	JOBS=$(JOBS) bash scripts/sanitize asan
	JOBS=$(JOBS) bash scripts/sanitize tsan

# Reformat every C and C++ file with the committed .clang-format (CI checks it: scripts/check-format).
format:
	bash scripts/check-format --fix

clean:
	rm -rf build out
