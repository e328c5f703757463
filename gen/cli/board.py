"""``bumprtl board BOARD``: the scene's pipeline in a real frame (docs/board.md).

``bumprtl board ulx3s`` builds the ULX3S bitstream (``--out``/``ulx3s_85f.bit`` and
``.svf``), prints the resources and each clock domain's Fmax from nextpnr, and, with
``--check-frames N``, simulates the top for N whole frames under Verilator, captures them
with cocotbext-dvi's DVISink, compares each with the golden frame byte for byte and writes
the first as ``frame0.png`` (with the map in the SDRAM the testbench runs the SDRAM's and
the flash's models, and the frames start at the display's second; ``--preload-sdram``
skips the simulated flash copy, the SDRAM's model holding the image from the start). ``--mode test`` checks the reduced 32 x 24 mode only (no
bitstream: it is no monitor mode). With the map in the SDRAM (``--map-memory axi`` or a
scene with ``map_memory = "axi"``) it also writes the map's flash image
(``ulx3s_85f_map.bin``, the bytes the flash loader copies into the SDRAM) and prints the
openFPGALoader commands that program the bitstream and the image (``--flash-offset``,
``--sdram``), and sizes the display buffer (a FIFO ahead of the clock crossing) from the
texel cache's predicted misses (a warning when no size keeps the display fed). Bad input (board, mode, scene, a map that does not fit beside the video logic
or in the SDRAM, a flash offset inside the bitstream) prints one line and exits 2 before
anything is written.
"""

import json
import math
import sys
from dataclasses import replace
from pathlib import Path

from bumprtl.gen.cli.flags import add_map_flags, scene_from_args
from bumprtl.gen.flow.board import (
    BOARDS,
    DEFAULT_FLASH_OFFSET,
    DEFAULT_PIPE_MHZ,
    DEFAULT_SDRAM,
    MAP_FILE,
    board_data,
    board_memory,
    build_bitstream,
    check_board,
    check_frames,
    display_buffer,
    flash_commands,
    part_costs,
)
from bumprtl.rtl.board import cdc_depth, pll_pipe_divider
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.scene import MAP_MEMORIES
from bumprtl.rtl.sdram import CHIPS
from bumprtl.rtl.video import MODES
from bumprtl.sim.scenes.imaging import save_png

__all__ = ["add_parser", "run"]


def _with_display_buffer(args, scene, mode, variant, offset, memory):
    """``memory`` with the FIFO ahead of the clock crossing the prediction derives
    (gen/flow/board.display_buffer), checked against the block-RAM budget; a warning when
    no depth keeps the display fed."""
    print("predicting the texel cache's misses and the display's buffer ...", flush=True)
    entries, budgets = display_buffer(scene, mode, memory.pipe_hz)
    slack = " / ".join(f"{b.slack:,.1f}" for b in budgets)
    misses = " / ".join(f"{int(b.misses.sum()):,}" for b in budgets)
    print(f"display buffer: {entries or 'none'}{' entries' if entries else ''} (ahead of "
          f"the clock crossing; frames 0 / 1: {misses} texel cache misses, least slack "
          f"{slack} pipe clocks)")
    if not all(b.holds for b in budgets):
        late = next(b for b in budgets if not b.holds)
        print(f"bumprtl: warning: the display is predicted to starve even with {entries} "
              f"entries ahead of the clock crossing (first late pixel at line {late.worst[0]}, column {late.worst[1]}): "
              f"the map misses faster than the SDRAM reads it (docs/board.md, What holds at "
              f"1280 x 720)", file=sys.stderr)
    if entries is None:
        return memory
    check_board(args.board, args.mode, scene, variant, offset, entries)
    return replace(memory, display_buffer=entries)


def run(args):
    scene = scene_from_args(args, args.scene, extra={"map_memory": args.map_memory})
    axi = scene.map_memory == "axi"
    offset = _flash_offset(args.flash_offset)
    if not axi and (args.sdram is not None or args.flash_offset is not None):
        flag = "--sdram" if args.sdram is not None else "--flash-offset"
        raise BumpError(f"{flag} applies to a map in the SDRAM (--map-memory axi), the scene's "
                        f"map_memory is {scene.map_memory!r}", "map_memory")
    variant = DEFAULT_SDRAM if args.sdram is None else args.sdram
    platform, device, mode = check_board(args.board, args.mode, scene, variant, offset)
    seeds = _seeds(args.seeds)
    if args.check_frames < 0:
        raise BumpError(f"--check-frames must be >= 0, got {args.check_frames}", "check_frames")
    if args.preload_sdram and not axi:
        raise BumpError(f"--preload-sdram applies to a map in the SDRAM (--map-memory axi), the "
                        f"scene's map_memory is {scene.map_memory!r}", "preload_sdram")
    if args.preload_sdram and not args.check_frames:
        raise BumpError("--preload-sdram applies to the simulation: it needs --check-frames N "
                        "(N >= 1)", "preload_sdram")
    pipe_hz = None
    bitstream = mode.name != "test" and not args.no_bitstream
    if args.pipe_mhz is not None:      # refused below the pixel clock, one line
        pipe_hz = args.pipe_mhz * 1e6
        if not math.isfinite(pipe_hz):
            raise BumpError(f"--pipe-mhz must be a finite clock rate, got {args.pipe_mhz}", "pipe_hz")
        cdc_depth(mode.pixel_hz, pipe_hz)
        if not bitstream and not args.check_frames:
            raise BumpError("--pipe-mhz has no effect without a bitstream or --check-frames",
                            "pipe_hz")
        if bitstream and not axi:      # with the SDRAM: board_memory, at or below it
            pll_pipe_divider(mode.pixel_hz, pipe_hz)
    memory = board_memory(scene, mode, variant, offset, pipe_hz) if axi else None
    if memory is not None and (bitstream or args.check_frames):
        memory = _with_display_buffer(args, scene, mode, variant, offset, memory)
    out = Path(args.out)
    status = 0
    summary = {"board": args.board, "device": device, "mode": mode.name, "scene": scene.name,
               "pipe_mhz": args.pipe_mhz, "map_memory": scene.map_memory}
    if memory is not None:
        out.mkdir(parents=True, exist_ok=True)
        image = out / MAP_FILE.format(name="ulx3s_85f")
        image.write_bytes(memory.image)
        print(f"wrote {image} ({len(memory.image):,} bytes: the map's tiled image, for flash "
              f"byte 0x{offset:x}; SDRAM {variant} at {memory.pipe_hz / 1e6:.4f} MHz, CL "
              f"{memory.sdram.cas_latency})")
        summary.update(sdram=variant, flash_offset=offset, map_bytes=len(memory.image),
                       pipe_mhz=memory.pipe_hz / 1e6)
    if bitstream:
        rows = build_bitstream(scene, mode, out, args.board, seeds, pipe_hz=pipe_hz,
                               memory=memory)
        for r in rows:
            res = ", ".join(f"{k} {u}/{a}" for k, (u, a) in r["resources"].items())
            fmax = ", ".join(f"{d} {a:.1f} MHz (constraint {c:.1f})" for d, (a, c) in
                             sorted(r["fmax"].items()))
            print(f"seed {r['seed']}: {res}; Fmax {fmax}; {r['seconds']:.0f} s")
        print(f"wrote {out / 'ulx3s_85f.bit'}")
        print(f"wrote {out / 'ulx3s_85f.svf'}")
        bit = out / "ulx3s_85f.bit"
        if memory is not None and bit.is_file() and bit.stat().st_size > offset:
            print(f"bumprtl: error: the bitstream's {bit.stat().st_size:,} bytes reach past the "
                  f"map's flash offset 0x{offset:x}: a larger --flash-offset", file=sys.stderr)
            status = 1
        summary["builds"] = rows
        worst = {}
        for r in rows:
            for d, (a, c) in r["fmax"].items():
                worst[d] = min(worst.get(d, (a, c)), (a, c))
        summary["fmax_min"] = worst
        for d, (a, c) in sorted(worst.items()):
            print(f"{d}: minimum Fmax over seeds {','.join(map(str, seeds))}: {a:.1f} MHz, "
                  f"constraint {c:.1f} MHz: {'met' if a >= c else 'NOT MET'}")
        if args.parts:
            parts = part_costs(scene, mode, out / "parts", memory=memory)
            summary["parts"] = parts
            for part, row in parts.items():
                print(f"{part}: " + ", ".join(f"{k} {v}" for k, v in row.items()))
    if args.check_frames:
        r = check_frames(scene, mode, out / f"sim_{mode.name}", args.check_frames,
                         board_data(scene), pipe_hz=pipe_hz, memory=memory,
                         # the keyword only when asked: stand-ins for check_frames need not know it
                         **({"preload": True} if args.preload_sdram else {}))
        for k, same in enumerate(r["same"]):
            step = r["first"] + k
            print(f"frame {step} (light step {step}): {'identical to the golden frame' if same else 'DIFFERS from the golden frame'}")
        for e in r["timing_errors"]:
            print(f"timing: {e}")
        at = r.get("underflow_at", [-1, -1, -1])
        first = (f" (first in the display's frame {at[0]}, line {at[1]}, column {at[2]})"
                 if r["underflow"] and at[0] >= 0 else "")
        print(f"sync/blanking: {'as the VESA table' if not r['timing_errors'] else 'WRONG'}"
              f"; underflow {r['underflow']}{first}, order error {r['order_error']}; "
              f"Verilator build {r['build_s']:.1f} s, simulation {r['run_s']:.1f} s")
        png = save_png(out / f"frame0_{mode.name}.png", r["captured"][0])
        print(f"wrote {png}")
        summary["frames"] = {"same": r["same"], "timing_errors": r["timing_errors"],
                             "underflow": r["underflow"], "order_error": r["order_error"],
                             "build_s": r["build_s"], "run_s": r["run_s"]}
        if not all(r["same"]) or r["timing_errors"] or r["underflow"] or r["order_error"]:
            status = 1
    if memory is not None:
        print("program the board's flash (the bitstream at 0, the map after it):")
        for command in flash_commands(out, offset):
            print(f"  {command}")
    out.mkdir(parents=True, exist_ok=True)
    (out / f"summary_{mode.name}.json").write_text(json.dumps(summary, indent=1) + "\n")
    return status


def _flash_offset(text):
    """--flash-offset: an integer in decimal or 0x hexadecimal (None: the default)."""
    if text is None:
        return DEFAULT_FLASH_OFFSET
    try:
        return int(str(text), 0)
    except ValueError:
        raise BumpError(f"--flash-offset must be an integer byte offset (decimal or 0x hex), got "
                        f"{text!r}", "flash_offset") from None


def _seeds(text):
    try:
        seeds = [int(s) for s in str(text).split(",")]
    except ValueError:
        seeds = []
    if not seeds or any(s < 1 for s in seeds):
        raise BumpError(f"--seeds must be a comma-separated list of positive integers, got "
                        f"{text!r}", "seeds")
    return seeds


def add_parser(sub):
    p = sub.add_parser("board", help="the scene's pipeline rendering to HDMI on an FPGA board",
                       description=__doc__.split("\n\n")[0])
    p.add_argument("board", metavar="BOARD", help=f"board ({', '.join(BOARDS)})")
    p.add_argument("--mode", default="640x480", metavar="MODE",
                   help=f"video mode ({', '.join(MODES)}; default 640x480)")
    p.add_argument("--scene", default="default", metavar="FILE|NAME",
                   help="a scene TOML file or built-in scene (default: default)")
    add_map_flags(p)
    p.add_argument("--out", default="build/board", metavar="DIR", help="output directory")
    p.add_argument("--seeds", default="1", metavar="LIST",
                   help="nextpnr seeds, e.g. 1,2,3 (default 1); the Fmax reported is the minimum")
    p.add_argument("--check-frames", type=int, default=0, metavar="N",
                   help="simulate N whole frames, capture them with cocotbext-dvi's DVISink and "
                        "compare them with the golden frames (default 0: no simulation)")
    p.add_argument("--parts", action="store_true",
                   help="also synthesize the core without flattening: LUT4/FF/DSP/BRAM per part")
    p.add_argument("--no-bitstream", action="store_true", help="skip the bitstream")
    p.add_argument("--pipe-mhz", type=float, default=None, metavar="MHZ",
                   help="run the source and pipeline in their own clock domain at MHZ (at least "
                        "the pixel clock; the PLL's CLKOS2 gives the nearest rate from above), "
                        "behind an asynchronous FIFO (default: the pixel clock, one domain); with "
                        f"--map-memory axi the SDRAM's clock too: the PLL's nearest at or below "
                        f"MHZ, at most 100 (default: {DEFAULT_PIPE_MHZ})")
    g = p.add_argument_group("the map in the SDRAM, loaded from the SPI flash (docs/board.md)")
    g.add_argument("--map-memory", default=None, choices=MAP_MEMORIES,
                   help="where the map lives: bram (block RAM) or axi (the board's SDRAM "
                        "behind the texel cache, copied there from the flash at power-up; the "
                        "map's flash image is written beside the bitstream) (default: the "
                        "scene's, bram for the built-in scenes)")
    g.add_argument("--sdram", default=None, metavar="VARIANT",
                   help=f"the board's SDRAM chip: {', '.join(f'{k} ({c.part})' for k, c in CHIPS.items())} "
                        f"(default {DEFAULT_SDRAM})")
    g.add_argument("--flash-offset", default=None, metavar="OFFSET",
                   help=f"flash byte of the map's image, a 64 KiB sector after the bitstream's, "
                        f"decimal or 0x hex (default 0x{DEFAULT_FLASH_OFFSET:x})")
    g.add_argument("--preload-sdram", action="store_true",
                   help="--check-frames without the flash copy: the simulated SDRAM starts "
                        "holding the map's image as the loader would have written it, the "
                        "simulated top has no flash loader (the bitstream keeps it); for maps "
                        "whose simulated copy is too long (8 MiB: ~537 M pipe clocks)")
    p.set_defaults(func=run)
