"""``bumprtl board BOARD``: the scene's pipeline in a real frame (docs/board.md).

``bumprtl board ulx3s`` builds the ULX3S bitstream (``--out``/``ulx3s_85f.bit`` and
``.svf``), prints the resources and each clock domain's Fmax from nextpnr, and, with
``--check-frames N``, simulates the top for N whole frames under Verilator, captures them
with cocotbext-dvi's DVISink, compares each with the golden frame byte for byte and writes
the first as ``frame0.png``. ``--mode test`` checks the reduced 32 x 24 mode only (no
bitstream: it is no monitor mode). Bad input (board, mode, scene, a map that does not fit
beside the video logic) prints one line and exits 2 before anything is written.
"""

import json
import math
from pathlib import Path

from bumprtl.gen.cli.flags import add_map_flags, scene_from_args
from bumprtl.gen.flow.board import (
    BOARDS,
    board_data,
    build_bitstream,
    check_board,
    check_frames,
    part_costs,
)
from bumprtl.rtl.board import cdc_depth, pll_pipe_divider
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.video import MODES
from bumprtl.sim.scenes.imaging import save_png

__all__ = ["add_parser", "run"]


def run(args):
    scene = scene_from_args(args, args.scene)
    platform, device, mode = check_board(args.board, args.mode, scene)
    seeds = _seeds(args.seeds)
    if args.check_frames < 0:
        raise BumpError(f"--check-frames must be >= 0, got {args.check_frames}", "check_frames")
    pipe_hz = None
    bitstream = mode.name != "test" and not args.no_bitstream
    if args.pipe_mhz is not None:      # refused below the pixel clock, one line
        pipe_hz = args.pipe_mhz * 1e6
        if not math.isfinite(pipe_hz):
            raise BumpError(f"--pipe-mhz must be a finite clock rate, got {args.pipe_mhz}", "pipe_hz")
        cdc_depth(mode.pixel_hz, pipe_hz)
        if bitstream:
            pll_pipe_divider(mode.pixel_hz, pipe_hz)
        elif not args.check_frames:
            raise BumpError("--pipe-mhz has no effect without a bitstream or --check-frames",
                            "pipe_hz")
    out = Path(args.out)
    summary = {"board": args.board, "device": device, "mode": mode.name, "scene": scene.name,
               "pipe_mhz": args.pipe_mhz}
    if bitstream:
        rows = build_bitstream(scene, mode, out, args.board, seeds, pipe_hz=pipe_hz)
        for r in rows:
            res = ", ".join(f"{k} {u}/{a}" for k, (u, a) in r["resources"].items())
            fmax = ", ".join(f"{d} {a:.1f} MHz (constraint {c:.1f})" for d, (a, c) in
                             sorted(r["fmax"].items()))
            print(f"seed {r['seed']}: {res}; Fmax {fmax}; {r['seconds']:.0f} s")
        print(f"wrote {out / 'ulx3s_85f.bit'}")
        print(f"wrote {out / 'ulx3s_85f.svf'}")
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
            parts = part_costs(scene, mode, out / "parts")
            summary["parts"] = parts
            for part, row in parts.items():
                print(f"{part}: " + ", ".join(f"{k} {v}" for k, v in row.items()))
    status = 0
    if args.check_frames:
        r = check_frames(scene, mode, out / f"sim_{mode.name}", args.check_frames,
                         board_data(scene), pipe_hz=pipe_hz)
        for k, same in enumerate(r["same"]):
            print(f"frame {k} (light step {k}): {'identical to the golden frame' if same else 'DIFFERS from the golden frame'}")
        for e in r["timing_errors"]:
            print(f"timing: {e}")
        print(f"sync/blanking: {'as the VESA table' if not r['timing_errors'] else 'WRONG'}"
              f"; underflow {r['underflow']}, order error {r['order_error']}; "
              f"Verilator build {r['build_s']:.1f} s, simulation {r['run_s']:.1f} s")
        png = save_png(out / f"frame0_{mode.name}.png", r["captured"][0])
        print(f"wrote {png}")
        summary["frames"] = {"same": r["same"], "timing_errors": r["timing_errors"],
                             "underflow": r["underflow"], "order_error": r["order_error"],
                             "build_s": r["build_s"], "run_s": r["run_s"]}
        if not all(r["same"]) or r["timing_errors"] or r["underflow"] or r["order_error"]:
            status = 1
    out.mkdir(parents=True, exist_ok=True)
    (out / f"summary_{mode.name}.json").write_text(json.dumps(summary, indent=1) + "\n")
    return status


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
                        "behind an asynchronous FIFO (default: the pixel clock, one domain)")
    p.set_defaults(func=run)
