# The two entry points of the README. Both install dependencies (Debian packages), configure and build.
#   make demo   grow plants on standard scenes and write them under out/demo
#   make test   run the test suite
PRESET ?= release
BUILD := build/$(PRESET)
GROWBENCH := $(BUILD)/harness/growbench
JOBS ?= $(shell nproc)

.PHONY: all deps configure build test demo bench clean

all: build

deps:
	bash scripts/install-deps

configure: deps
	cmake --preset $(PRESET)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

demo: build
	bash scripts/demo $(GROWBENCH) out/demo

bench: build
	$(BUILD)/bench/growbench_bench

clean:
	rm -rf build out
