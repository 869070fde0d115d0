# Boticelli: thin wrapper over CMake presets (like PX4's Makefile). `make help` lists targets.
.DEFAULT_GOAL := help
SHELL := /bin/bash
MAKEFLAGS += --no-print-directory
JOBS ?= $(shell nproc)
WORLD ?= boards/sim/worlds/thesis_room.sdf
ARGS ?=
SUITE ?= all
FUZZ_SECONDS ?= 60

.PHONY: help deps deps-cross deps-armhf deps-bench deps-analyze deps-kernel deps-box deps-test test-kernel \
        test-robot run test check \
        bench bench-build format format-check sim asan rpi4 armhf fuzz-build test-sim test-asan \
        test-rpi4 test-fuzz fuzz bench-aarch64 \
        analyze mutants mutation-score clean

help:
	@echo "make run       install deps, build the sim preset, run the firmware on the sim board"
	@echo "make test      install deps, build and test the sim, asan and rpi4 (qemu) presets"
	@echo "make test-sim  build and test the sim preset only (fast iteration)"
	@echo "make test-kernel  the drivers against the kernel's virtual devices under qemu"
	@echo "make check     format-check, analyze and build the bench (about 15 min on two cores)"
	@echo "make bench     build the sim preset and run boticelli-bench \$$SUITE (default all)"
	@echo "make bench-aarch64  the realtime suite on the sim board built for aarch64, under"
	@echo "               qemu-aarch64: an emulated upper bound, not Pi figures (not in make test)"
	@echo "make armhf     cross build for 32-bit ARM (arm-linux-gnueabihf)"
	@echo "make package-rpi4 / make deploy HOST=user@robot   build the arm64 .deb / install it over ssh"
	@echo "make test-robot  the .deb as a service on a virtual robot computer under qemu (not in make test)"
	@echo "make format    clang-format every C++ file; make format-check only reports"
	@echo "make fuzz      run every libFuzzer target for FUZZ_SECONDS (default 60) each"
	@echo "make analyze   clang-tidy and cppcheck over the tree (zero findings expected)"
	@echo "make mutants   apply each tools/mutants patch to a scratch copy; all must be caught"
	@echo "make mutation-score FILES=... N=30 SEED=1   machine-made mutants: caught / survived per file"

deps:
	@toolchain/install-deps.sh
deps-cross:
	@toolchain/install-deps.sh --cross
deps-armhf:
	@toolchain/install-deps.sh --armhf
deps-bench:
	@toolchain/install-deps.sh --bench
deps-analyze:
	@toolchain/install-deps.sh --analyze
deps-kernel:
	@toolchain/install-deps.sh --kernel
deps-box:
	@toolchain/install-deps.sh --box

# configure+build one preset: $(call build,PRESET)
define build
	cmake --preset $(1) >/dev/null
	cmake --build --preset $(1) -j $(JOBS)
endef

sim: deps
	$(call build,sim)
asan: deps
	$(call build,asan)
rpi4: deps-cross
	$(call build,rpi4)
armhf: deps-armhf
	$(call build,armhf)
fuzz-build: deps
	$(call build,fuzz)

SNAPSHOTS ?= build/run-snapshots
run: sim
	@echo "snapshots of each cycle go to $(SNAPSHOTS)/"
	build/sim/bin/boticelli --world $(WORLD) --snapshots $(SNAPSHOTS) --max-cycles 60 $(ARGS)

# The sim preset's ctest includes kernel_in_the_loop (tests/kernel), which needs --kernel.
test-sim: sim deps-kernel
	ctest --preset sim -j $(JOBS)
# The kernel-in-the-loop test alone (about a minute; docs/testing.md).
test-kernel: deps-kernel
	cmake --preset sim >/dev/null
	cmake --build --preset sim --target kernel_tests -j $(JOBS)
	ctest --preset sim -R kernel_in_the_loop --output-on-failure
test-asan: asan
	ctest --preset asan -j $(JOBS)
test-rpi4: rpi4
	ctest --preset rpi4 -j $(JOBS)
	@file -L build/rpi4/bin/boticelli | grep -q 'ARM aarch64' \
	  || { echo "build/rpi4/bin/boticelli is not an aarch64 binary" >&2; exit 1; }

# The fuzz preset's ctest: every fuzzer replays its corpus and fuzzes a few seconds
# (FUZZ_TEST_SECONDS in tests/fuzz/CMakeLists.txt), and the ThreadSanitizer test runs.
test-fuzz: fuzz-build
	ctest --preset fuzz -j $(JOBS)

# Everything make test needs in one apt transaction (one 'apt-get update' instead of three).
deps-test:
	@toolchain/install-deps.sh --cross --kernel
# make test: the host packages first; then the cross and kernel ones (the cross compiler, qemu,
# the :arm64 libraries, the kernel cache: downloads and unpacking, a minute or two on a fresh
# machine) install in the background while the sim preset compiles, which needs none of them.
# Nothing else calls apt meanwhile (the build there does not go through the deps targets);
# afterwards each preset's own deps target finds everything installed.
DEPS_TEST_LOG := build/deps-test.log
test: deps
	@mkdir -p build; \
	  toolchain/install-deps.sh --cross --kernel >$(DEPS_TEST_LOG) 2>&1 & deps=$$!; \
	  cmake --preset sim >/dev/null && cmake --build --preset sim -j $(JOBS); built=$$?; \
	  wait $$deps; installed=$$?; cat $(DEPS_TEST_LOG); \
	  if [ $$installed != 0 ]; then echo "make test: toolchain/install-deps.sh --cross --kernel failed" >&2; exit 1; fi; \
	  exit $$built
	$(MAKE) test-sim test-asan test-rpi4 test-fuzz
	@echo "make test: sim, asan, rpi4 (qemu-aarch64) and fuzz presets passed"

# Each fuzzer for FUZZ_SECONDS from its corpus and dictionary; new inputs are kept in
# build/fuzz/tests/fuzz/new/NAME (copy the worth-keeping ones to tests/fuzz/corpus/NAME).
fuzz: fuzz-build
	@set -e; for f in build/fuzz/bin/fuzz_*; do \
	  n=$$(basename $$f); mkdir -p build/fuzz/tests/fuzz/new/$$n; \
	  echo "== $$n ($(FUZZ_SECONDS) s)"; \
	  $$f -max_total_time=$(FUZZ_SECONDS) -max_len=4096 -dict=tests/fuzz/dict/$$n.dict \
	    -print_final_stats=1 build/fuzz/tests/fuzz/new/$$n tests/fuzz/corpus/$$n; \
	done

# clang-tidy (.clang-tidy) over the sim and rpi4 presets' compile commands (configured, not
# built) and cppcheck over the sources; both must report nothing (docs/testing.md). Not part
# of make test: it takes long.
analyze: deps-analyze deps-cross
	cmake --preset sim >/dev/null
	cmake --preset rpi4 >/dev/null
	JOBS=$(JOBS) tools/analyze.sh

mutants: deps
	JOBS=$(JOBS) tools/mutants/run.sh

# Mutation score (docs/testing.md): N machine-made mutants per file of FILES, sampled with SEED,
# each built and tested in a scratch copy against the binaries tools/mutation_map.txt names.
# Not part of make test. JSON=1 prints JSON instead of the table.
FILES ?= firmware/safety/safety.cpp
N ?= 30
SEED ?= 1
mutation-score: deps
	JOBS=$(JOBS) python3 tools/mutation_score.py --n $(N) --seed $(SEED) $(if $(JSON),--json) $(FILES)

# The checks that read the code instead of running it (docs/testing.md).
check: deps
	$(MAKE) format-check
	$(MAKE) analyze
	$(MAKE) bench-build

# Builds boticelli-bench (warnings are errors) without running it: make check's guard that the
# bench still compiles, since make test does not build it.
bench-build: deps-bench
	$(call build,sim)
	cmake --build --preset sim --target boticelli-bench -j $(JOBS)

# The bench is not in the sim preset's default build (make test does not need it).
bench: deps-bench
	$(call build,sim)
	cmake --build --preset sim --target boticelli-bench -j $(JOBS)
	build/sim/bin/boticelli-bench $(SUITE) --json

# The realtime suite (docs/benchmarks.md) on the sim board's firmware cross built for aarch64
# (preset sim-aarch64: the firmware only), each mission run through qemu-aarch64 by the host's
# bench; every output line says "emulated":"qemu-aarch64". Only this suite runs the firmware
# through the emulator, so SUITE may only be realtime. The paced run is skipped unless
# BOTICELLI_REALTIME_PACED_S is set: under emulation it would measure the emulator falling
# behind the wall clock, on a core held with SCHED_FIFO. Not part of make test or make check.
# No -L /usr/aarch64-linux-gnu: that prefix puts the cross package's loader (libc6-arm64-cross)
# in front of the :arm64 libc.so.6 of another glibc build, and with that pair pthread_create
# and fork hang; without it loader and libraries are the :arm64 packages' (libc6:arm64 comes
# with deps-cross's libraries), as on a Debian arm64 system.
AARCH64_EMULATOR := qemu-aarch64
bench-aarch64: deps-bench deps-cross
	@test "$(SUITE)" = realtime || test "$(SUITE)" = all \
	  || { echo "make bench-aarch64: only SUITE=realtime runs under the emulator" >&2; exit 2; }
	cmake --preset sim-aarch64 >/dev/null
	cmake --build --preset sim-aarch64 --target boticelli -j $(JOBS)
	cmake --preset sim >/dev/null
	cmake --build --preset sim --target boticelli-bench -j $(JOBS)
	BOTICELLI_REALTIME_FIRMWARE=build/sim-aarch64/bin/boticelli \
	  BOTICELLI_REALTIME_EMULATOR="$(AARCH64_EMULATOR)" \
	  BOTICELLI_REALTIME_PACED_S=$${BOTICELLI_REALTIME_PACED_S:-0} \
	  build/sim/bin/boticelli-bench realtime --json

format:
	@git ls-files '*.h' '*.hpp' '*.cpp' | xargs clang-format -i
format-check:
	@git ls-files '*.h' '*.hpp' '*.cpp' | xargs clang-format --dry-run --Werror

# The rpi4 .deb (CPack, arm64) and its installation on the robot over ssh (docs/flashing.md).
# PACKAGE=linux-amd64 installs the same board built natively instead (the robot computer in
# a box, docs/testing.md), DEB=FILE installs that file without building; SSHFLAGS go to both
# scp and ssh (e.g. -F FILE). Over ssh there is nobody to answer dpkg's question about a
# locally changed /etc/boticelli/boticelli.conf that the new version changes too (dpkg then
# fails with "end of file on stdin at conffile prompt" and leaves the package unconfigured):
# the local file is kept, the new one goes beside it as boticelli.conf.dpkg-dist.
PACKAGE ?= rpi4
DEB ?=
SSHFLAGS ?=
CONFOLD := -o Dpkg::Options::=--force-confdef -o Dpkg::Options::=--force-confold
.PHONY: package-rpi4 package-linux-amd64 deploy
package-rpi4: rpi4
	cd build/rpi4 && cpack -G DEB
package-linux-amd64: deps
	$(call build,linux-amd64)
	cd build/linux-amd64 && cpack -G DEB
deploy:
	@test -n "$(HOST)" || { echo "usage: make deploy HOST=user@robot [PACKAGE=rpi4|linux-amd64] [DEB=file]" >&2; exit 2; }
	@$(if $(DEB),test -f "$(DEB)",$(MAKE) package-$(PACKAGE))
	deb=$(if $(DEB),"$(DEB)",$$(ls -t build/$(PACKAGE)/boticelli_*.deb | head -n1)) && \
	  scp $(SSHFLAGS) "$$deb" $(HOST):/tmp/ && \
	  ssh $(SSHFLAGS) $(HOST) "sudo apt-get install -y --allow-downgrades $(CONFOLD) /tmp/$$(basename $$deb)"

# The robot computer in a box (tests/box/run.sh, docs/testing.md): boots a Debian 12 amd64
# box under qemu, deploys the linux-amd64 .deb with make deploy and checks it as an operator
# would. Not part of make test (over six minutes cached, docs/testing.md).
test-robot: deps-box package-linux-amd64
	tests/box/run.sh build/linux-amd64 build/box

clean:
	rm -rf build
