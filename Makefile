# Two commands set up and check everything: `make generate`, then `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
BENCH_STAMP := $(VENV)/.installed-bench

.PHONY: generate test test-fast test-tools bench-tools constraints check lint typecheck clean demo stress bench bench-c wheel runtime-wheel docs c-check c-coverage

CONSTRAINTS := requirements/constraints.txt

$(STAMP): pyproject.toml $(CONSTRAINTS)
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	@# setuptools' notice that an editable install is one (a warning, printed on every install) is silenced by its
	@# message alone: other warnings and every error still show
	PYTHONWARNINGS='ignore:Editable installation' $(BIN)/pip install --quiet -c $(CONSTRAINTS) -e '.[test]'
	@# generated/ on the path: a package generated after the install imports at once, without a reinstall
	echo "$(CURDIR)/generated" > "$$($(BIN)/python -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")/serialspec-generated.pth"
	touch $(STAMP)

generate: $(STAMP) test-tools
	$(BIN)/serialspec generate

# Programs the tests drive as a user would: tshark (the Wireshark dissectors) and tmux (`serialspec watch` on a
# screen). Installed with apt-get where they are missing and this runs as root; elsewhere the tests that need them
# are skipped, saying why.
# The C target's tests also build with clang, with gcc -m32 (32-bit size_t and long: the 32-bit libc and libgcc,
# without gcc-multilib, which Debian will not install beside a cross gcc) and for big-endian PowerPC (a cross gcc;
# qemu-user runs the programs) and for 8-bit AVR (avr-gcc: a 16-bit int, a 32-bit double; simavr runs them): installed
# the same way, each group on its own, so one that cannot be installed leaves the others. The Arm gcc `make bench-c` measures the C's flash with (gcc-arm-none-eabi, newlib-nano
# included) is installed by `make bench-tools`: no test needs it.
TEST_TOOLS := tshark tmux
# apt-get install of the packages in $$missing (apt-get options in $$options), as root; elsewhere it says which
# tests are skipped
INSTALL_MISSING = if [ -z "$$missing" ]; then exit 0; fi; \
	if [ "$$(id -u)" != 0 ] || ! command -v apt-get >/dev/null; then \
		echo "not installed:$$missing (apt-get as root installs them): the tests that need them are skipped"; exit 0; fi; \
	echo "installing$$missing (apt-get)"; \
	export DEBIAN_FRONTEND=noninteractive; \
	apt-get -o DPkg::Lock::Timeout=300 install -y -q $$options $$missing >/dev/null 2>&1 || { apt-get -o DPkg::Lock::Timeout=300 update -q >/dev/null 2>&1 && \
		apt-get -o DPkg::Lock::Timeout=300 install -y -q $$options $$missing >/dev/null 2>&1; } || \
		echo "could not install$$missing: the tests that need them are skipped"
# the 32-bit libgcc of the host's gcc (lib32gcc-12-dev for gcc 12)
LIB32GCC = lib32gcc-$$(gcc -dumpversion 2>/dev/null | cut -d. -f1)-dev
test-tools:
	@missing=""; for tool in $(TEST_TOOLS); do command -v $$tool >/dev/null || missing="$$missing $$tool"; done; \
	command -v clang >/dev/null || missing="$$missing clang"; \
	$(INSTALL_MISSING)
	@missing=""; command -v powerpc-linux-gnu-gcc >/dev/null || missing="$$missing gcc-powerpc-linux-gnu libc6-dev-powerpc-cross"; \
	command -v qemu-ppc >/dev/null || missing="$$missing qemu-user"; \
	$(INSTALL_MISSING)
	@missing=""; options=--no-install-recommends; \
	printf 'int main(void) { return 0; }\n' | gcc -m32 -x c - -o /dev/null 2>/dev/null || missing=" libc6-dev-i386 $(LIB32GCC)"; \
	$(INSTALL_MISSING)
	@missing=""; command -v avr-gcc >/dev/null || missing=" gcc-avr avr-libc"; \
	command -v simavr >/dev/null || missing="$$missing simavr"; \
	$(INSTALL_MISSING)

bench-tools: test-tools
	@missing=""; command -v arm-none-eabi-gcc >/dev/null || missing="$$missing gcc-arm-none-eabi"; \
	$(INSTALL_MISSING)

check: $(STAMP)
	$(BIN)/serialspec check

lint: $(STAMP)
	$(BIN)/ruff check generator generated tests bench examples packaging tools
	$(BIN)/ruff format --check generator tests bench examples packaging tools

typecheck: $(STAMP)
	$(BIN)/mypy generator/serialspec generated

# The whole suite on every core (pytest-xdist); `make test-fast` leaves out the tests marked slow (wheels, docs site,
# vendors' SDKs over pseudo-terminals) for the inner loop of an edit.
test: $(STAMP) test-tools check lint typecheck
	$(BIN)/pytest -q -n auto --dist worksteal

test-fast: $(STAMP) test-tools check
	$(BIN)/pytest -q -n auto --dist worksteal -m "not slow"

# The C target alone (generated/c/<protocol>/): every spec's C compiled with gcc, clang, gcc -m32 and a PowerPC gcc,
# -std=c99 and the strict warnings as errors at -O0/-Os/-O2, the headers as C++11, then a driver built with
# -fsanitize=address,undefined checked against the Python codec (examples, random messages, mutated frames, noisy
# streams in random pieces), the examples and a noisy stream again on clang, -m32 and big-endian PowerPC (qemu) builds.
# `make test` runs the same tests with the rest of the suite, compiling at -O2 alone, running the shipped vector
# check (test/check_vectors.c) on the gcc build alone and the other-build driver on -m32 and PowerPC only. Needs gcc and g++ (apt-get install gcc g++); the other
# compilers and qemu are installed as root (test-tools), else those builds are skipped, saying why.
c-check: $(STAMP) test-tools check
	SERIALSPEC_C_CHECK=1 $(BIN)/pytest -q -n auto tests/test_c_backend.py tests/test_c_text.py

# Line coverage of the generated C by the tests (c-target.md: >= 95%): the C tests again with their gcc driver builds
# compiled with --coverage, then per protocol the lines of <p>.c and <p>_json.c that some test ran
# (tools/c_coverage.py; `--uncovered` lists the others). Not part of `make test`: several minutes.
C_COVERAGE := build/c-coverage
c-coverage: $(STAMP) test-tools
	rm -rf $(C_COVERAGE)
	SERIALSPEC_C_COVERAGE=$(CURDIR)/$(C_COVERAGE) $(BIN)/pytest -q -n 2 -p no:cacheprovider tests/test_c_backend.py
	$(BIN)/python tools/c_coverage.py $(C_COVERAGE)

# Pin what the development install resolved to (after changing pyproject.toml's extras), for CI and fresh clones.
constraints: $(STAMP)
	{ sed -n '1,2p' $(CONSTRAINTS); $(BIN)/pip freeze --exclude-editable | grep -v '^serialspec'; } > $(CONSTRAINTS).new
	mv $(CONSTRAINTS).new $(CONSTRAINTS)

# The long robustness runs: 100,000 frames per protocol and direction through the stream parsers (with garbage,
# truncated frame starts, corrupt checksums, random read sizes), the fault matrix, and 8 threads x 5,000
# transactions on one bus. `make test` runs the same tests in a short form (5,000 frames, 8 x 1,000 transactions).
# Then every hypothesis fuzzer (CLI, spec front end, codec round trips, framing engine) with FUZZ_EXAMPLES examples
# each and a random seed (tests/conftest.py: `make test` runs them derandomized, in a short form, so CI cannot flake).
# A failure prints its seed and blob: replay with `make stress FUZZ_ARGS=--hypothesis-seed=N`.
STRESS_FRAMES ?= 100000
STRESS_TRANSACTIONS ?= 5000
FUZZ_EXAMPLES ?= 2000
FUZZ_ARGS ?=
# property tests that compile C, feed every split or run every output: a short form in `make test`, this many here
SLOW_FUZZ_EXAMPLES ?= 150
SLOW_FUZZ_TESTS := tests/test_stream_splits.py tests/test_language_matrix.py tests/test_c_backend.py \
	tests/test_c_text.py tests/test_stream_lean.py
FUZZ_TESTS := tests/test_cli_fuzz.py tests/test_spec_fuzz.py tests/test_codec.py tests/test_fast_codec.py \
	tests/test_framing_engine.py tests/test_batch_stream_fuzz.py tests/test_straight_frames.py

stress: $(STAMP)
	@echo "stress: $(STRESS_FRAMES) frames per stream parser, 8 threads x $(STRESS_TRANSACTIONS) transactions"
	SERIALSPEC_STRESS_FRAMES=$(STRESS_FRAMES) SERIALSPEC_STRESS_TRANSACTIONS=$(STRESS_TRANSACTIONS) \
		$(BIN)/pytest -q -s tests/test_stress.py tests/test_faults.py
	@echo "stress: $(FUZZ_EXAMPLES) examples per fuzzer, random seeds"
	SERIALSPEC_FUZZ_EXAMPLES=$(FUZZ_EXAMPLES) $(BIN)/pytest -q -p no:cacheprovider $(FUZZ_TESTS) $(FUZZ_ARGS)
	@echo "stress: $(SLOW_FUZZ_EXAMPLES) examples per slow property test (compiled C, every split, every output)"
	SERIALSPEC_C_CHECK=1 SERIALSPEC_FUZZ_EXAMPLES=$(SLOW_FUZZ_EXAMPLES) $(BIN)/pytest -q -n auto -p no:cacheprovider \
		$(SLOW_FUZZ_TESTS) $(FUZZ_ARGS)

# Benchmarks (bench/README.md): codec, stream parsing, pseudo-terminal latency, generation; about a minute on a
# quiet machine. Prints one table per family and writes them all to bench/results.md.
$(BENCH_STAMP): $(STAMP) pyproject.toml
	PYTHONWARNINGS='ignore:Editable installation' $(BIN)/pip install --quiet -c $(CONSTRAINTS) -e '.[test,bench]'
	touch $(BENCH_STAMP)

bench: $(BENCH_STAMP) bench-tools
	$(BIN)/python -m bench.run

# The C target's tables alone (flash and RAM on Cortex-M0+, function groups, parse throughput, stack and vector
# coverage), replaced in bench/results.md.
bench-c: $(STAMP) bench-tools
	$(BIN)/python -m bench.run c-size c-groups c-speed c-stack

# The documentation site in site/: README, tutorial, language reference and every protocol's reference (mkdocs, strict).
docs: $(STAMP)
	$(BIN)/python tools/docsite.py site

# The two distributions, into dist/: serialspec (generator, CLI, runtime and the shipped protocols) and
# serialspec-runtime (only what generated packages import, for a robot that runs generated code: pyserial only).
wheel: $(STAMP)
	$(BIN)/python -m pip wheel --no-build-isolation --no-deps --quiet -w dist .

runtime-wheel: $(STAMP)
	$(BIN)/python packaging/runtime/build.py dist

clean:
	rm -rf $(VENV) build dist site *.egg-info

# A virtual Fashion Star servo on a pseudo-terminal, driven by the generated client: no hardware needed.
demo: $(STAMP)
	$(BIN)/python examples/demo_fashionstar.py
