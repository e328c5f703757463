"""Why each branch make test leaves uncovered is uncovered (tests/tools/coverage_map.py,
docs/coverage.md's per-branch list).

:data:`REASONS`: ``(file, text of the branch's line, text of its target line or None,
class, why)``, the texts stripped as in the source (``"exit"``: the branch leaves the
function). Matched on the file and the texts, never on line numbers, so a reason holds
while the code moves; the first entry that matches is the branch's. A target is named
only where one line has branches of two reasons. An entry that matches no uncovered
branch is reported as stale by the next run (its branch is covered now, or the line
changed): delete or mend it then.
"""

# class -> what it means (the order of docs/coverage.md's count)
CLASSES = {
    "make board": "the real board flow: Verilator's build and run of the ULX3S top, the "
                  "bitstream tools; `make board` runs it (make test stands the tools in)",
    "make fpga": "placement with the real Yosys and nextpnr; `make fpga` runs it",
    "make formal": "the proofs beyond make test's quick subset; `make formal` runs them",
    "make regress": "the long or sharded runs; `make regress` runs them",
    "simulator": "a path a simulator run reaches only when it goes wrong (a timeout, X on a "
                 "pin, a failing bench), or a bench option no built-in test selects",
    "tool failure": "an external tool (Verilator, Icarus, Yosys, sby, a compiler) failing or "
                    "answering in an unexpected form",
    "by hand": "an entry point or option run by hand, not by a test (`python -m ...`, "
               "a page's regeneration)",
    "defensive": "cannot happen with the code as it is (a registry or a caller that never "
                 "gives it); the check guards a future change",
    "never empty": "a loop that never runs empty (or never runs out), or a condition that "
                   "goes one way under every input make test and the code give; the other "
                   "way is covered",
    "not measurable": "taken under make test, but coverage.py cannot record it (the process "
                      "is replaced by exec before it writes its data)",
    "covered since": "a test added after the measured run reaches it (named); the next "
                     "make coverage drops it from this list",
    "no test yet": "a test could reach it, none is written yet (each says what it would "
                   "take: most need an emission or a simulation of seconds)",
}

CLI = "tests/gen/cli/test_refusals_reached.py"
FLOW = "tests/gen/flow/test_refusals_reached.py"
RTL = "tests/rtl/test_refusals_reached.py"
SIM = "tests/sim/test_refusals_reached.py"
RENDER = "tests/gen/render/test_refusals_reached.py"
FORMAL_SUBSET = ("make test's quick formal subset (tests/sim/formal) never builds this contract "
                 "path; the whole table of gen/formal/run.py (the scene and AXI pipelines, the "
                 "palette bank) is where it is built: read from the code, not confirmed by a "
                 "coverage run of make formal")

EDGE_FIFO = ("every CreditEdge of rtl/ holds a CreditFIFO whose banks elaborate to memories; "
             "the SyncFIFOBuffered form and a FIFO without a memory are for an edge built "
             "otherwise, which none is")


def since(test, what):
    return "covered since", f"{test} ({what})"


REASONS = [
    # gen/bench
    ("gen/bench/memory.py", "if r.size == size and r.cache == next(iter(CACHES)):", None,
     "by hand", "the plot of several map sizes or caches: docs/memory.md's default run; make "
     "test plots one size and one cache"),
    ("gen/bench/palette.py", "if curve:", None,
     "never empty", "a curve has a point for every palette size and the bench takes at least one"),
    ("gen/bench/sweep.py", 'if "palette" in opts.methods:', None,
     "never empty", "every sweep make test runs includes palette (its default method list)"),
    ("gen/bench/sweep.py", "if front:", None,
     "never empty", "a Pareto front of at least one point: every plot has points"),
    # gen/cli
    ("gen/cli/emit.py", "for line in problems:", None,
     "simulator", "`emit --lint` (Verilator) printing its findings"),
    # gen/flow
    ("gen/flow/axis.py", "if not images:", None,
     "defensive", "build_axis of a scene unit is always given its memory images (gen/cli/emit.py "
     "makes them before)"),
    ("gen/flow/board.py", "if tests == 0 or failures:", None,
     "simulator", "a failing cocotb run of tb_board"),
    ("gen/flow/emit.py", "if component not in _FRAGMENTS:", None,
     "never empty", "every component is elaborated once per process in make test (the cache "
     "serves a second call on the same object, which no caller makes today)"),
    ("gen/flow/emit.py", "if out.returncode != 0 and not lines:", None,
     "tool failure", "Verilator's lint failing without a %-line"),
    ("gen/flow/memories.py", "if set(DEVICE_BRAM) != set(DEVICES):", None,
     "defensive", "import-time check that two tables in the source list the same devices"),
    ("gen/flow/memories.py", "if en not in meta.ports:", None,
     "defensive", "a sidecar whose image names a port the unit lacks: the sidecar is written "
     "from the same unit"),
    ("gen/flow/named.py", 'if "i__payload" not in ports or "o__payload" not in ports:', None,
     "defensive", "gen/cli/emit.py refuses `--ports named` with `--interface axis` before"),
    ("gen/flow/named.py", "if name in out:", None,
     "defensive", "two fields or a port that map to one port name: no unit's layout has one"),
    ("gen/flow/named.py", "if unused:", None,
     "never empty", "every unit's output fields cover its payload (no unused bit to waive)"),
    ("gen/flow/named.py", "if lo > pos:", None,
     "never empty", "input fields are contiguous from bit 0 in every layout (no gap to fill)"),
    ("gen/flow/named.py", "if pos < width:", None,
     "never empty", "as above: no gap after the last input field"),
    ("gen/flow/quiet.py", "while not stop.wait(1.0 if tty else 3600):", None,
     "by hand", "the ticker writes each second only on a terminal; tests run on pipes"),
    ("gen/flow/resources.py", "if ca is not None and cb is not None:", None,
     "defensive", "Yosys folds a product of two constants before the netlist is read"),
    ("gen/flow/resources.py", "if enable >> port & 1:", None,
     "never empty", "every memory read port of the emitted units is clocked"),
    ("gen/flow/resources.py", "elif kind in _DIV_TYPES:", None,
     "never empty", "no netlist make test counts (Table 1's designs at 10-bit widths) has a "
     "divider cell"),
    ("gen/flow/vectors.py", 'if kind not in ("coord", "level", "phi", "theta"):', None,
     "defensive", "every scene pipeline's input fields are of those kinds"),
    ("gen/flow/vectors.py", "if own not in codes:", None,
     "defensive", "the pixel file's columns are the polar methods' only (pixel_columns)"),
    ("gen/flow/vectors.py", "if set(inputs) != set(fields):", None,
     "defensive", "internal check that the stimulus and the pipeline agree"),
    ("gen/flow/vectors.py", "if missing:", None,
     "defensive", "internal check that the golden model gives every output field"),
    ("gen/flow/vectors.py", "if device is not None:", None,
     "no test yet", "write_vectors without a device (the CLI always passes its default)"),
    # gen/formal
    ("gen/formal/run.py", 'if not getattr(dut, "_front", False):', None,
     "make formal", "a pipeline with a texel cache in front (the axi scenes)"),
    ("gen/formal/run.py", 'if res.status == "ERROR" and not detail:', None,
     "tool failure", "sby ending in ERROR"),
    ("gen/formal/run.py", "if row.trace:", None, "make formal", "a counterexample trace kept"),
    ("gen/formal/run.py", 'if __name__ == "__main__":', None,
     "make formal", "`python -m bumprtl.gen.formal.run`"),
    # gen/render
    ("gen/render/demo.py", "if t <= 16:", None,
     "defensive", "a 16 x 16 map fits every device: the demo's smallest map is never refused"),
    ("gen/render/demo.py", "if verbose:", None,
     "simulator", "`demo --verbose` renders through the simulator (minutes)"),
    ("gen/render/demo.py", "if rtl:", None,
     "simulator", "`bumprtl demo` with the RTL render (make demo); make test's demo runs "
     "without it"),
    ("gen/render/demo.py", "if error is not None:", None,
     "simulator", "the RTL image differing from the golden one"),
    ("gen/render/rtl.py", 'if __name__ == "__main__":    # python -m bumprtl.gen.render.rtl [--doc docs/scenes.md]',
     None, "by hand", "docs/scenes.md's table (`make docs`: Yosys on every built-in scene)"),
    ("gen/render/rtl.py", "if args.doc:", None, "by hand", "as above"),
    # gen/report
    ("gen/report/fpga.py", 'if row.startswith("primitive:"):   # one registered primitive alone: the ceiling',
     None, "make fpga", "the ECP5 form of each report row"),
    ("gen/report/fpga.py", "if row.startswith(\"edge:\"):        # a scene pipeline's credit edge alone: its cost",
     None, "make fpga", "as above"),
    ("gen/report/fpga.py", "for unit in (pipeline, *pipeline.units.values()):", None,
     "make fpga", "as above"),
    ("gen/report/fpga.py", "if row.startswith(\"scene_axi:\"):  # the same with the map in the user's memory (AXI4)",
     None, "make fpga", "as above"),
    ("gen/report/fpga.py", 'if row.startswith("scene:"):     # the drop-in BumpPipeline of a built-in scene class',
     None, "make fpga", "as above"),
    ("gen/report/fpga.py", 'if row == "pipeline":', None, "make fpga", "as above"),
    ("gen/report/fpga.py", "if ok:", None,
     "tool failure", "a primitive with no placed seed (nextpnr failing on every seed)"),
    ("gen/report/fpga.py", "if skipped:", None,
     "defensive", "NOT_PLACED is empty: no method that cannot be placed today"),
    ("gen/report/integration.py", "for pattern, text in _MEANINGS:", None,
     "never empty", "every field of the pipelines in docs/integration.md has a meaning in the "
     "table"),
    ("gen/report/integration.py", "if main(argv) != 0:", None,
     "defensive", "the emission of a built-in scene does not fail"),
    ("gen/report/integration.py", "if not roms:", None,
     "never empty", "every unit the page describes holds a memory"),
    ("gen/report/integration.py", "if target:", None,
     "never empty", "every host port writes a unit of the pipeline"),
    ("gen/report/integration.py", "if missing:", None,
     "defensive", "the worked example gives every field of the built-in scenes"),
    ("gen/report/integration.py", 'if img["load"] != "port" or name == "lut":', None,
     "never empty", "the page emits with `--load port` and no palette scene"),
    ("gen/report/recommend.py", 'if not f or f.get("device") != device:', None,
     "defensive", "its one caller (recommend) passes only the points placed on the device"),
    ("gen/report/recommend.py", 'if "max_lsb" in s:', None,
     "never empty", "every scene row of the sweep has its error"),
    ("gen/report/table1.py", "if scheduler is None:", None,
     "by hand", "the counts on a Dask scheduler (`--scheduler`)"),
    ("gen/report/table1.py", "if all(o.ok for o in got.values()):", None,
     "tool failure", "a count whose Yosys job failed"),
    ("gen/report/timing.py", "if foot:", None,
     "never empty", "every diagram of docs/timing has a footnote"),
    ("gen/report/timing.py", "if doc is not None and doc.is_file():", None,
     "no test yet", "`report timing` without its page (the page is always there in the tree)"),
    # gen/tools
    ("gen/tools/jobs.py", "if job.name in names:", None,
     "defensive", "two jobs with one name: every caller names them by job_name (unique)"),
    ("gen/tools/objcache.py", "if found is None or not cache:", None,
     "not measurable", "every Verilator build compiles the design's own C++ through "
     "$(OBJCACHE) and takes this branch; os.execvp replaces the measured process before "
     "coverage.py saves it"),
    # rtl
    ("rtl/board.py", "if self.scene.texture:", None,
     "no test yet", "the board top of a scene with a colour texture: make test and make board "
     "build the default scene (grey shade)"),
    ("rtl/board.py", "for clki in range(1, DIV_MAX + 1):", None,
     "never empty", "the loop always breaks on the PFD limit before the last divider"),
    ("rtl/ecp5.py", "if rom.depth > words:           # the last word: the address wrapped to word 0",
     None, "never empty", "every ROM make test builds on the ECP5 target here spills into a "
     "last block (the other side)"),
    ("rtl/ecp5.py", "if mode is None:", None,
     "no test yet", "a RAM no DP16KD mode fits, built on the ECP5 target (the generic form)"),
    ("rtl/sdram.py", "if wpb == 1:", None,
     "defensive", "an AXI word of one 16-bit DQ beat: SdramConfig refuses data_bits other "
     "than 32 and 64, two or four beats a word"),
    ("rtl/sidecar.py", 'if hasattr(value, "tolist"):', None,
     "never empty", "the sidecar's facts are plain Python by the time they are written"),
    ("rtl/sidecar.py", 'if hasattr(value, "to_dict"):', None, "never empty", "as above"),
    ("rtl/tables.py", 'if a.dtype.kind not in "iu":', None,
     "never empty", "sine_read is given integer codes by every caller"),
    ("rtl/texture.py", "if x.shape().width <= top.bit_length():          # cannot exceed top (one light)",
     None, "no test yet", "a sum narrow enough that it cannot exceed its top (no saturation "
     "built): no unit make test builds has one"),
    # sim
    ("sim/amaranth_stream.py", "if vcd:", None,
     "by hand", "a waveform asked for while debugging a unit"),
    ("sim/ecp5/__init__.py", "if \"`ifndef NO_INCLUDES\" in rest:        # common_sim.vh already includes cells_ff/cells_io",
     None, "make fpga", "the post-synthesis simulation on the Yosys cell library"),
    ("sim/ecp5/__init__.py", 'if out.returncode != 0 or "FATAL" in out.stdout:', None,
     "tool failure", "Icarus failing on the ECP5 cells (the run itself is make fpga's)"),
    ("sim/formal/axi.py", "if g.misses > 1:", None,
     "no test yet", "the AXI4 contract of a cache with one miss outstanding: none of "
     "FORMAL_GEOMETRIES has misses = 1, so make formal does not build it either"),
    ("sim/formal/contract.py", "if self.read_ports:", None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "if isinstance(self.fifo, CreditFIFO):", None,
     "defensive", EDGE_FIFO),
    ("sim/formal/contract.py", "if all(isinstance(inst, MemoryInstance) for inst in found):", None,
     "defensive", EDGE_FIFO),
    ("sim/formal/contract.py", "elif isinstance(self.fifo, SyncFIFOBuffered):", None,
     "defensive", EDGE_FIFO),
    ("sim/formal/contract.py", "if isinstance(inst, MemoryInstance):", None,
     "defensive", EDGE_FIFO),
    ("sim/formal/contract.py", "if self._slots is None:", None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "if unit is self.dut and len(self._pipes) == 1:", None,
     "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "if lead is None:             # not built on a Pipe: no chain (BMC only)",
     None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "for rec in recs[1:]:", None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "if rec is not None:", None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "for lead, other in lockstep:", None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", 'if getattr(self, "_cache_ghost", None) is not None:', None,
     "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "if self.cache is None:", None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", 'if not isinstance(inst, MemoryInstance) or "tag" not in r.rd_extra:',
     None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "for a in range(g.queue):", None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "if len(stages) != self.latency:", None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "if t is not None:", None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "if edge is None or self.port_latency != self.latency + len(edge.heads) + 1:",
     None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "if lut is None:", None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "if not ports or self._fifo(m) is None:", None, "make formal", FORMAL_SUBSET),
    ("sim/formal/contract.py", "if len(lut_stages) != depth - 1:", None, "make formal", FORMAL_SUBSET),
    ("sim/golden/board.py", "if scene.texture:", None,
     "no test yet", "the golden frame of a scene with a colour texture (as rtl/board.py)"),
    ("sim/golden/common.py", "for _ in range(64):", None,
     "defensive", "64 redraws all below the surface: far too unlikely for any test to see (the "
     "loop ends by its break)"),
    ("sim/golden/methods.py", "if [n for n in MODELS if n not in hardware.METHODS]:", None,
     "defensive", "import-time check of the two registries; tests/rtl/test_methods.py holds them "
     "together"),
    ("sim/golden/stress.py", "if scene.specular:", None,
     "never empty", "make test's stress frames are of specular scenes only"),
    ("sim/scenes/heightfields.py", "if img.ndim == 3:", None,
     "never empty", "the scikit-image pictures make test loads are greyscale (no RGB to "
     "average)"),
    ("sim/scenes/usermap.py", "if h.shape != (hh, w):", None,
     "defensive", "Pillow decodes the size the PNG header says"),
    ("sim/scenes/usermap.py", "if rgb.shape != (hh, w, channels):", None, "defensive", "as above"),
    ("sim/sdram_bench.py", 'if __name__ == "__main__":', None,
     "by hand", "`python -m bumprtl.sim.sdram_bench` (docs/sdram.md's numbers; make test calls its main)"),
    ("sim/sdram_model.py", "if rst:", None,
     "no test yet", "a reset in the middle of a run of the SDRAM model"),
    ("sim/tb/bulk.py", "if inputs is not None:", None,
     "make regress", "the bulk run whose stimulus the bench generates (no arrays): the "
     "regressions of tests/sim/tb/test_bulk.py"),
    ("sim/tb/bulk_build.py", 'elif opts["clock"] == "cxx":', None,
     "defensive", "the clock is verilog or cxx (build_options refuses others)"),
    ("sim/tb/bulk_frame.py", "if words is not None:", None,
     "no test yet", "the coverage frame of a flat-map scene with a colour texture (texels, no "
     "map words): the frame is worth a test only streamed through a simulator, and "
     "tests/sim/tb/test_bulk_scene_frames.py streams the built-in scenes, none of them that"),
    ("sim/tb/bulk_frame.py", "if new_words is not None:", None, "no test yet", "as above"),
    ("sim/tb/bulk_frame.py", "elif len(pick) and words is not None:        # palette: every index the map holds",
     None, "no test yet", "the coverage frame of a palette scene none of whose pixels is picked "
     "for the table (as above)"),
    ("sim/tb/bulk_wrapper.py", "if template.count(HOOK) != 1:", None,
     "defensive", "checks the shipped Verilog template holds its hook once"),
    ("sim/tb/tb_axis.py", 'if scene.shading != "per-pixel" or scene.bump_map != "varying" or \\',
     None, "simulator", "the AXI4-Stream bench given a scene it cannot drive (a bench user's "
     "error)"),
    ("sim/tb/tb_axis.py", 'if unit == "rotation_axis":', None,
     "simulator", "the rotation unit's AXI4-Stream bench (make test runs the illumination "
     "and scene ones)"),
    ("sim/tb/tb_board.py", "if pipe_ps:", None,
     "make board", "frames at the pixel clock alone (make test's run sets a pipe clock)"),
    ("sim/tb/tb_board.py", "if len(px) == ha * va:", None,
     "simulator", "a frame of the wrong size from the DVI sink"),
    ("sim/tb/tb_bulk.py", "if not await _wait_done(dut, n, 0, 0):", None,
     "simulator", "the wrapper timing out on its set-up cycles"),
    ("sim/tb/tb_bulk.py", "while waited < guard:", None,
     "simulator", "the guard expiring (a hung wrapper)"),
    ("sim/tb/tb_bulk.py", "if not await _wait_done(dut, n, gap, stall):", None,
     "simulator", "as above, on a pattern's chunk"),
    ("sim/tb/tb_palette.py", "if cfg.palette_blend:", None,
     "never empty", "make test's palette bench runs the blend stage"),
    ("sim/tb/tb_palette.py", "for _cycle in range(30 * total):", None,
     "simulator", "the bench running out of cycles (a hung unit)"),
    ("sim/tb/tb_pipeline_axi.py", 'if os.environ.get("BUMPRTL_STIMULUS") == "raster":', None,
     "make regress", "the raster stimulus of the AXI pipeline bench"),
    ("sim/tb/tb_sdram.py", "if unknown:", None, "simulator", "X or Z on an SDRAM pin"),
    ("gen/flow/board.py", "if memory is not None:", None,
     "make board", "the bitstream of the top with its map in the SDRAM (Yosys, nextpnr, "
     "ecppack): `bumprtl board ulx3s --map-memory axi`"),
    ("gen/flow/fpga.py", "if out.returncode != 0:", None,
     "make fpga", "a placement nextpnr finishes; make test runs this function only with a "
     "nextpnr that fails (tests/gen/flow/test_fpga.py)"),
    ("sim/formal/contract.py", "if tag is not None:", None,
     "never empty", "every stage of the units make test's formal subset builds records its "
     "tag register (the Pipe carries the tag stage by stage); a stage without one would be "
     "a unit whose pipe drops the tag"),
    ("sim/golden/globe.py", "if m - n <= 1:", None,
     "defensive", "GlobeConfig's fraction bits keep M - n above 1 at every radius from 1 to "
     "2047 (checked radius by radius when this was written): the guard keeps the bound "
     "finite for a narrower datapath"),
    ("sim/golden/globe.py", 'for v in res["violations"]:', None,
     "never empty", "a violation is a model bug: the runs docs/globe.md quotes print none "
     "(tests/docs/test_globe_page.py asserts exit 0)"),
    ("sim/golden/globe.py", 'if __name__ == "__main__":', None,
     "by hand", "`python -m bumprtl.sim.golden.globe`; make test calls its main"),
    ("sim/tb/stream.py", "if setup is not None:", None,
     "make regress", "only the palette scene's AXI bench passes a setup (its colour table "
     "written before the first pixel): tests/sim/tb/test_tb_pipeline_axi.py's palette case"),
    ("sim/tb/tb_pipeline_axi.py", "for addr, word in enumerate(table.tolist()):", None,
     "make regress", "the palette scene's AXI bench (tests/sim/tb/test_tb_pipeline_axi.py's "
     "palette case)"),
    ("sim/tb/tb_pipeline_axi.py", 'if scene.shading == "palette":', None,
     "make regress", "the palette scene's AXI bench (tests/sim/tb/test_tb_pipeline_axi.py's "
     "palette case)"),
    # read after the make coverage run of this session (see docs/coverage.md)
    ('rtl/board.py', 'if preloaded and sdram is None:', None,
     'defensive', 'a preloaded top without an SDRAM: board_core asks for one only with the map in the SDRAM'),
    ('rtl/board.py', 'if not self.preloaded:', None,
     'make regress', "the board top with the map in the SDRAM (the flash loader, or the SDRAM preloaded) runs only in make regress's board benches (tests/board/test_board.py's SDRAM cases); make test builds and runs the top without it"),
    ('rtl/board.py', 'if self.loader is not None:', None,
     'make regress', 'as above (the SDRAM board top)'),
    ('rtl/board.py', 'if not self.scene.texture:', None,
     'make regress', 'as above (the SDRAM board top)'),
    ('rtl/board.py', 'if core.sdram is not None:', None,
     'make regress', 'as above (the SDRAM board top)'),
    ('rtl/board.py', 'if core.spi is not None:', None,
     'make regress', 'as above (the SDRAM board top)'),
    ('rtl/board.py', 'for name in ("cke", "cs_n", "ras_n", "cas_n", "we_n", "ba", "a", "dqm", "dq_o",', None,
     'make regress', 'as above (the SDRAM board top)'),
    ('sim/tb/tb_board.py', 'if preload is None:', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', 'if in_reset:                  # the reset is held once, at the start', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', 'if str(rst.value) != "0":', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', 'if (cmd[0] or cmd[1:] == [1, 1, 1]) and model.n not in model.writes:', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', 'if memories is not None:', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', 'if not preloaded:', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', 'if not (preloaded and r is dut.rst):', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', 'if preloaded:', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', 'while memories.sdram.state != "ready" and not memories.errors and waited < 10**6:', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', "if memories is not None:    # the display's first frame: wait for it (the copy, then a frame)", None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', 'if str(dut.display_shows.value) == "1" or memories.errors or waited > limit:', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', 'if memories.flash is not None:', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/tb/tb_board.py', 'if len(reads) != 1:', None,
     'make regress', "the board bench's SDRAM and flash models: make regress's SDRAM board benches (tests/board/test_board.py)"),
    ('sim/formal/contract.py', 'if qb:', None,
     'make formal', "a lemma of the cached pipeline's order proof or of a scene pipeline's bank proof, which run in make formal (minutes each); make test's quick subset proves PaletteLUT's bank alone and the palette pipeline's order"),
    ('sim/formal/contract.py', 'for valid, tag, name, text in regs:', None,
     'make formal', "a lemma of the cached pipeline's order proof or of a scene pipeline's bank proof, which run in make formal (minutes each); make test's quick subset proves PaletteLUT's bank alone and the palette pipeline's order"),
    ('sim/formal/contract.py', 'if name is not None:', None,
     'make formal', "a lemma of the cached pipeline's order proof or of a scene pipeline's bank proof, which run in make formal (minutes each); make test's quick subset proves PaletteLUT's bank alone and the palette pipeline's order"),
    ('sim/formal/contract.py', 'for valid, held in ((r.q_f0, Mux(r.q_rd, ring[1], ring[0])),', None,
     'make formal', "a lemma of the cached pipeline's order proof or of a scene pipeline's bank proof, which run in make formal (minutes each); make test's quick subset proves PaletteLUT's bank alone and the palette pipeline's order"),
    ('sim/formal/contract.py', 'if not isinstance(xinst, MemoryInstance):', None,
     'make formal', "a lemma of the cached pipeline's order proof or of a scene pipeline's bank proof, which run in make formal (minutes each); make test's quick subset proves PaletteLUT's bank alone and the palette pipeline's order"),
    ('sim/formal/contract.py', 'for a in range(1 << len(r.x_in)):', None,
     'make formal', "a lemma of the cached pipeline's order proof or of a scene pipeline's bank proof, which run in make formal (minutes each); make test's quick subset proves PaletteLUT's bank alone and the palette pipeline's order"),
    ('sim/formal/contract.py', 'for b, pending in enumerate(self._counters[(id(dut), "lut_pending")]):', None,
     'make formal', "a lemma of the cached pipeline's order proof or of a scene pipeline's bank proof, which run in make formal (minutes each); make test's quick subset proves PaletteLUT's bank alone and the palette pipeline's order"),
    ('sim/formal/contract.py', 'for v, bank in reversed(list(zip(valid, banks, strict=False))):', None,
     'make formal', "a lemma of the cached pipeline's order proof or of a scene pipeline's bank proof, which run in make formal (minutes each); make test's quick subset proves PaletteLUT's bank alone and the palette pipeline's order"),
    ('sim/formal/contract.py', 'for v, _ in lut_stages:', None,
     'make formal', "a lemma of the cached pipeline's order proof or of a scene pipeline's bank proof, which run in make formal (minutes each); make test's quick subset proves PaletteLUT's bank alone and the palette pipeline's order"),
    ('gen/flow/board.py', 'if preloaded:', None,
     'make regress', 'the board top with the SDRAM preloaded (above)'),
    ('gen/flow/board.py', 'if memory is not None and preload:     # what the loader would have written, [bank, row, col]', None,
     'make regress', 'check_frames with the map in the SDRAM (above)'),
    ('gen/flow/board.py', "elif memory is not None:      # the flash's array: the image at its offset", None,
     'make regress', 'check_frames with the map in the SDRAM (above)'),
    ('gen/flow/board.py', 'if preload and memory is None:', None,
     'defensive', "a preload without a memory: the board command never asks for one (check_frames' own caller error)"),
    ('gen/flow/board.py', 'if scene.square:', None,
     'no test yet', 'a non-square map refused for the block RAM or the SDRAM: the refusal naming W x H (a board run with --texture-size and a 2:1 map too large)'),
    ('gen/bench/sweep.py', 'if key not in self._adversarial:', None,
     'make regress', "the cache's second ask for one angle width's vectors: make test's sweeps ask each once; make regress's full grid asks again"),
    ('gen/cli/reference.py', 'if help_text:', None,
     'never empty', 'every command and subcommand has its help text (tests/gen/cli/test_help_defaults.py)'),
    ('gen/cli/reference.py', 'if __name__ == "__main__":', None,
     'by hand', '`python -m bumprtl.gen.cli.reference docs/cli.md`; make test calls its main'),
    ('gen/tools/yosys.py', 'if os.environ.get("BUMPRTL_YOSYS_SUBPROCESS") == "1" or proxy is None \\', None,
     'never empty', 'installed once a process in make test (its first conversion); the guard keeps a second call or the subprocess switch harmless'),
    ('sim/formal/sdram.py', 'if gap <= 1:', None,
     'never empty', 'every timer of the SDRAM contract at the formal configurations waits 2 cycles or more'),
    ('sim/scenes/__init__.py', 'if isinstance(tall, bool) or not isinstance(tall, (int, np.integer)) or not 16 <= tall <= tex \\', None,
     'defensive', 'SceneConfig refuses a bad texture_height before a scene is loaded'),
    ('sim/scenes/__init__.py', 'if bump.size == bump.texture_height and tall == tex:', None,
     'defensive', "as above: the scene's texture size and height are checked against its map first"),
    ('sim/sdram_model.py', 'if preload is not None and tuple(preload.shape) != shape:', None,
     'defensive', "sdram_preload makes the array of the chip's shape; no caller gives another"),
    ('sim/tb/bulk_frame.py', 'if scene.addressing == "wrap":                # a map width (height) further, either side', None,
     'never empty', 'every scene whose coverage frame make test streams wraps its addresses'),
    ('sim/tb/runner.py', 'if results is None:', None,
     'simulator', 'a simulator that exits without writing its results file under pytest'),
    ('sim/tb/tb_bulk.py', 'if not await _wait_done(dut, reset_prefix(meta), 0, 0):', None,
     'simulator', 'the wrapper hanging in its reset prefix (a timeout)'),
]
