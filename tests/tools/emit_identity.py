"""Byte-identity check of the emitted Verilog across a refactoring (not part of make test).

Emits every unit (sincos, palette, rotation and illumination of every method) and the
pipeline and fetch units of every built-in scene, through ``bumprtl emit`` in-process, at
explicit widths (angle_bits 13 / frac_bits 16 and a small 10 / 11), plus the ECP5 form
(``target=ECP5()``, Verilog text of the unit) of every unit and scene pipeline, and writes
the sha256 of every file to ``OUT/sha256.txt``::

    .venv/bin/python tests/tools/emit_identity.py build/identity/before
    .venv/bin/python tests/tools/emit_identity.py build/identity/after --compare build/identity/before

``--compare DIR`` exits 1 naming each Verilog, RTLIL or memory-image file whose hash
differs from ``DIR/sha256.txt`` (or is missing on one side); differing ``.json`` sidecars
are listed but do not fail (their error bounds follow the golden models, not the hardware).
A full run takes about 6 minutes on one core. The widths are passed explicitly so that a change of the
Config defaults does not show up as a difference.
"""

import argparse
import contextlib
import hashlib
import io
import json
import sys
from pathlib import Path

WIDTHS = ((13, 16), (10, 11))
METHODS = ("exact", "lee", "peercy", "ernst", "kim")
PLAIN = ("sincos", "palette")


def _cli(argv):
    from bumprtl.gen.cli.main import main
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(argv)
    return rc, err.getvalue().strip()


def _ecp5_text(name, cfg_or_scene):
    from amaranth.back import rtlil

    from bumprtl.gen.flow.units import build_unit
    from bumprtl.rtl.pipe import ECP5
    dut = build_unit(name, cfg_or_scene, ECP5())[0]
    return rtlil.convert(dut, name=name, emit_src=False)


def emit_all(out):
    from bumprtl.rtl.config import BumpError, Config
    from bumprtl.sim.scenes.config import BUILTIN, load_scene_config
    out.mkdir(parents=True, exist_ok=True)
    notes = []
    for a, f in WIDTHS:
        widths = ["--angle-bits", str(a), "--frac-bits", str(f)]
        jobs = [(u, [u]) for u in PLAIN]
        jobs += [(f"{u}-{m}", [u, "--method", m]) for u in ("rotation", "illumination")
                 for m in METHODS]
        scenes = out / "scenes"
        scenes.mkdir(parents=True, exist_ok=True)
        for s in BUILTIN:       # the built-in scene's keys with these widths over its own
            keys = {**BUILTIN[s], "angle_bits": a, "frac_bits": f}
            (scenes / f"{s}-a{a}f{f}.toml").write_text(
                "".join(f"{k} = {json.dumps(v)}\n" for k, v in keys.items()))
        jobs += [(f"{u}-{s}", [u, "--scene", str(scenes / f"{s}-a{a}f{f}.toml")])
                 for u in ("pipeline", "fetch") for s in BUILTIN]
        for label, argv in jobs:
            d = out / f"a{a}f{f}" / label
            rc, err = _cli(["emit", *argv, *([] if "--scene" in argv or argv[0] == "palette" else widths),
                            "--out", str(d)])
            notes.append(f"{label} a{a}f{f}: rc {rc} {err}")
            print(f"{label} a{a}f{f}: rc {rc}", flush=True)
        ecp = out / f"a{a}f{f}" / "ecp5"
        ecp.mkdir(parents=True, exist_ok=True)
        for u in PLAIN:
            (ecp / f"{u}.il").write_text(_ecp5_text(u, Config(angle_bits=a, frac_bits=f)))
        for u in ("rotation", "illumination"):
            for m in METHODS:
                try:
                    text = _ecp5_text(u, Config(angle_bits=a, frac_bits=f, method=m))
                except BumpError as e:
                    text = f"error: {e}\n"
                (ecp / f"{u}-{m}.il").write_text(text)
        for s in BUILTIN:
            scene = load_scene_config({**BUILTIN[s], "angle_bits": a, "frac_bits": f})
            (ecp / f"pipeline-{s}.il").write_text(_ecp5_text("pipeline", scene))
        print(f"ecp5 a{a}f{f}: done", flush=True)
    (out / "notes.txt").write_text("\n".join(notes) + "\n")
    lines = []
    for p in sorted(out.rglob("*")):
        if p.is_file() and p.name not in ("sha256.txt", "notes.txt"):
            lines.append(f"{hashlib.sha256(_normal(p.read_bytes())).hexdigest()}  "
                         f"{_normal(str(p.relative_to(out)).encode()).decode()}")
    (out / "sha256.txt").write_text("\n".join(lines) + "\n")
    return len(lines)


def _normal(data):
    """The emitted names without the ``bumprtl_`` prefix of ``bumprtl emit``'s default
    ``--name``, so that the hashes compare the hardware across that naming change."""
    return data.replace(b"bumprtl_", b"")


def _table(path):
    return dict(reversed(line.split("  ", 1)) for line in path.read_text().splitlines() if line)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", type=Path, help="output directory (e.g. build/identity/after)")
    p.add_argument("--compare", type=Path, default=None, metavar="DIR",
                   help="a previous output directory: exit 1 if any file's sha256 differs")
    args = p.parse_args(argv)
    n = emit_all(args.out)
    print(f"{n} files hashed into {args.out / 'sha256.txt'}")
    if args.compare is None:
        return 0
    before, after = _table(args.compare / "sha256.txt"), _table(args.out / "sha256.txt")
    diff = sorted(k for k in set(before) | set(after) if before.get(k) != after.get(k))
    bad = [k for k in diff if not k.endswith(".json")]
    for k in diff:
        print(f"differs: {k}{'' if k in bad else ' (sidecar: config and bounds, not hardware)'}")
    hw = sum(not k.endswith(".json") for k in before)
    print(f"identity: {hw} hardware files (.v, .il, .hex) before, "
          f"{sum(not k.endswith('.json') for k in after)} after, {len(bad)} differ; "
          f"{len(diff) - len(bad)} sidecars differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
