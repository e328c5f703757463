"""Every flag of the CLI, walked from its own parsers (gen/cli/main.build_parser), either
changes what the command writes or is refused: exit 2 and exactly one line on stderr naming
the flag. A flag accepted where it changes nothing is a bug.

The tables below classify every flag of every subparser: ``VALUES`` holds the non-default
value each cheap command (``emit`` of every unit, ``render --model fixed`` and ``float64``,
``recommend``; ``vectors`` under make regress) is run with, ``SKIP`` the few flags of those commands not run here and why,
``NOT_RUN`` the commands too costly for make test (synthesis, simulation, proofs,
benchmarks) with their flags. A flag no table lists fails
:func:`test_every_flag_is_classified`, so a new flag must be classified.

"Changes what it writes": the files under the output directory differ once the lines and
sidecar keys that merely record the command line (``bumprtl emit ...`` lines, the
sidecar's ``command``, ``config`` and ``scene``) are set aside: a flag recorded but without
effect on the hardware is no change.
"""

import contextlib
import io
import json

import numpy as np
import pytest
from PIL import Image

from bumprtl.gen.cli.main import build_parser, main
from bumprtl.gen.cli.reference import options

# Commands another change owns: classified when it lands.
EXCLUDED = set()

NOT_RUN = {   # command -> (why not run here, its flags)
    ("demo",): ("renders every method and the RTL (make demo, tests/gen/render/test_demo.py)",
                ("--out", "--size", "--no-rtl", "--simulator", "--verbose")),
    ("doctor",): ("reports the tools found; writes nothing", ()),
    ("bench", "float64"): ("benchmark", ("--samples", "--seed", "--verbose")),
    ("bench", "golden"): ("benchmark", ("--pixels", "--sim-samples", "--methods", "--verbose")),
    ("bench", "accuracy"): ("benchmark", ("--method", "--samples", "--angle-bits", "--frac-bits",
                                          "--spec-exponent", "--spec-index-bits", "--faithful-widths",
                                          "--scene-size", "--scene-widths", "--verbose")),
    ("bench", "specular"): ("benchmark", ("--samples", "--spec-exponent", "--work", "--verbose")),
    ("bench", "lee-widths"): ("benchmark", ("--samples", "--seed", "--verbose")),
    ("bench", "palette"): ("benchmark", ("--what", "--sizes", "--palettes", "--scenes", "--size",
                                         "--plot", "--images-dir", "--verbose")),
    ("bench", "memory"): ("benchmark", ("--scenes", "--sizes", "--caches", "--methods",
                                        "--latencies", "--rows", "--doc", "--plot", "--verbose")),
    ("bench", "sweep"): ("benchmark (placements, simulations)",
                         ("--quick", "--methods", "--maps", "--fpga", "--device", "--fpga-points",
                          "--sim", "--jobs", "--scheduler", "--out", "--work", "--docs",
                          "--data-copy", "--no-progress", "--verbose")),
    ("bench", "stress"): ("benchmark", ("--samples", "--seed", "--out", "--verbose")),
    ("bench", "skip"): ("benchmark (placements)", ("--size", "--scenes", "--work", "--docs", "--verbose")),
    ("bench", "rtl-sim"): ("benchmark (simulator builds)",
                           ("--size", "--scene", "--simulators", "--quick", "--repeat", "--work",
                            "--docs", "--verbose")),
    ("report", "table1"): ("Yosys netlists", ("--out", "--work", "--samples", "--jobs", "--scheduler",
                                              "--angle-bits", "--frac-bits", "--specular", "--verbose")),
    ("report", "fpga"): ("nextpnr placements", ("--device", "--unit", "--out", "--work", "--samples",
                                                "--seeds", "--scene-seeds", "--jobs", "--job-timeout",
                                                "--scheduler", "--angle-bits", "--frac-bits",
                                                "--specular", "--verbose")),
    ("report", "timing"): ("simulator waveforms", ("--out", "--doc", "--verbose")),
    ("report", "integration"): ("Verilator builds", ("--scene", "--out", "--doc", "--name", "--verbose")),
    ("formal",): ("SymbiYosys proofs", ("units", "--prop", "--no-mutants", "--quick", "-j",
                                        "--job-timeout", "--scheduler", "--out", "--merge",
                                        "--from-results", "--doc")),
    ("board",): ("bitstreams", ("board", "--mode", "--scene", "--height-map", "--normal-map",
                                "--normal-convention", "--geometry", "--height-scale", "--resample",
                                "--texture-size", "--out", "--seeds", "--check-frames", "--parts",
                                "--no-bitstream", "--pipe-mhz", "--map-memory", "--sdram",
                                "--flash-offset", "--preload-sdram")),
}

# --spec-index-bits is a cap (rtl/config.py: at most frac_bits are used), so its value lies
# below the tiny bases' frac_bits: at or above it, it changes nothing, as documented.
# Placeholders filled per run: OUT2 another output directory, HMAP / NMAP a 16 x 16 height /
# normal map, SCENE2 a second tiny scene file, SWEEP2 a second sweep file.
CONFIG_VALUES = {"--angle-bits": "7", "--frac-bits": "7", "--method": "lee", "--tag-bits": "12",
                 "--out-bits": "9", "--spec-exponent": "8", "--spec-index-bits": "4",
                 "--ka": "0.2", "--kd": "0.6", "--ks": "0.3", "--lights": "2",
                 "--specular": "--no-specular", "--palette-size": "32", "--color-bits": "6",
                 "--palette-blend": "--palette-blend"}
MAP_VALUES = {"--height-map": "HMAP", "--normal-map": "NMAP", "--normal-convention": "directx",
              "--geometry": "sphere", "--height-scale": "2.0", "--resample": "--resample",
              "--texture-size": "32"}
VALUES = {
    ("emit",): {"unit": None, "--out": "OUT2", "--name": "other_name", "--ports": "named",
                "--scene": "SCENE2", "--interface": "axis", "--tdata-width": "64",
                "--fusesoc": "--fusesoc", "--load": "port", "--device": "LFE5U-25F",
                "--map-memory": "axi", "--cache-sets": "16", "--cache-ways": "4",
                "--cache-block": "8", "--axi-data-bits": "64", "--cache-queue": "16",
                "--cache-outstanding": "4", **MAP_VALUES, **CONFIG_VALUES},
    ("render",): {"--scene": "wood", "--method": "lee_corrected", "--model": None,
                  "--size": "32", "--texture-size": "32", "--light-elevation": "30",
                  "--light-azimuth": "60", "--light": "point", "--out": "OUT2",
                  "--compare": "--compare", "--quantizer": "kmeans", "--lighting": "phong",
                  "--pipeline": "two-lights", "--height-map": "HMAP", "--normal-map": "NMAP",
                  "--normal-convention": "directx", "--geometry": "sphere",
                  "--height-scale": "2.0", "--resample": "--resample",
                  "--spec-exponent": "8", "--ka": "0.2", "--kd": "0.6", "--ks": "0.3",
                  "--specular": "--no-specular", "--palette-size": "32",
                  "--simulator": "icarus", "--verbose": "--verbose", "--per-cycle": "--per-cycle",
                  "--load": "port", "--device": "LFE5U-25F"},
    ("recommend",): {"--max-error-lsb": "4", "--device": "LFE5U-25F", "--sweep": "SWEEP2"},
    ("vectors",): {"--pipeline": "SCENE2", "--unit": "rotation", "--source": "frame",
                   "--count": "24", "--seed": "2", "--out": "OUT2", "--name": "other_name",
                   "--load": "port", "--top": "my_top", "--device": "LFE5U-25F",
                   **MAP_VALUES, **CONFIG_VALUES},
}
SKIP = {   # (command, flag) -> why it is not run here
    ("emit", "--lint"): "runs Verilator: every emission test lints (tests/rtl/*, test_named_ports)",
    ("render", "--rtl"): "builds the pipeline in Verilator: tests/sim/tb/test_tb_pipeline.py",
}

UNITS = ("sincos", "rotation", "illumination", "palette", "pipeline", "fetch")
# Tiny emissions: a scene of 16 x 16 texels at 6-bit angles (pipeline, fetch), 5-bit angles
# for the datapaths.
SCENE = 'name = "tiny"\ntexture_size = 16\nangle_bits = 6\nfrac_bits = 6\n'
SCENE2 = 'name = "tiny2"\ntexture_size = 16\nangle_bits = 6\nfrac_bits = 6\naddressing = "clamp"\n'
EMIT_BASE = {"sincos": ["--angle-bits", "5"], "rotation": ["--angle-bits", "5", "--frac-bits", "5"],
             "illumination": ["--angle-bits", "5", "--frac-bits", "5"], "palette": ["--palette-size", "16"],
             "pipeline": ["--scene", "SCENE"], "fetch": ["--scene", "SCENE"]}
RENDER_BASE = ["--size", "16", "--texture-size", "16"]


def _walk(parser):
    """Every option of every command (the top level's --version left out)."""
    return ((path, a) for path, a in options(parser) if path)


def _flag(action):
    return action.option_strings[0] if action.option_strings else action.dest


FLAGS, DEST = {}, {}
for _path, _action in _walk(build_parser()):
    FLAGS.setdefault(_path, []).append(_flag(_action))
    DEST[_path, _flag(_action)] = _action.dest


def test_every_flag_is_classified():
    """A flag of any subparser that no table lists fails here: give it a value in VALUES
    (and see it change the output or be refused) or a reason in SKIP / NOT_RUN."""
    missing = []
    for path, flags in FLAGS.items():
        if path in EXCLUDED:
            continue
        listed = set(NOT_RUN[path][1]) if path in NOT_RUN else set(VALUES.get(path, ()))
        listed |= {f for (c, f) in SKIP if (c,) == path}
        missing += [f"{' '.join(path)} {f}" for f in flags if f not in listed]
    assert not missing, f"flags with no entry in test_every_flag.py's tables: {missing}"
    stale = [(p, f) for p, table in VALUES.items() for f in table if f not in FLAGS.get(p, ())]
    stale += [(p, f) for p, (_why, fs) in NOT_RUN.items() for f in fs if f not in FLAGS.get(p, ())]
    assert not stale, f"table entries for flags the parsers no longer have: {stale}"


# ------------------------------------------------------------------ running and comparing

@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """The inputs the placeholders name."""
    d = tmp_path_factory.mktemp("inputs")
    rng = np.random.default_rng(1)
    Image.fromarray(rng.integers(0, 256, (16, 16), dtype=np.uint8), "L").save(d / "h.png")
    normals = rng.integers(64, 192, (16, 16, 3), dtype=np.uint8)
    normals[..., 2] = 255                                   # every normal out of the surface
    Image.fromarray(normals, "RGB").save(d / "n.png")
    (d / "scene.toml").write_text(SCENE)
    (d / "scene2.toml").write_text(SCENE2)
    return {"HMAP": d / "h.png", "NMAP": d / "n.png", "SCENE": d / "scene.toml",
            "SCENE2": d / "scene2.toml", "dir": d}


def _normal(path):
    """A written file with what records the command line set aside."""
    if path.suffix == ".json":
        def strip(x):
            if isinstance(x, dict):
                return {k: strip(v) for k, v in x.items() if k not in ("command", "config", "scene")}
            return [strip(v) for v in x] if isinstance(x, list) else x
        return json.dumps(strip(json.loads(path.read_text())), sort_keys=True)
    data = path.read_bytes()
    if path.suffix in (".png", ".npy", ".npz"):
        return data
    return b"\n".join(ln for ln in data.splitlines() if b"bumprtl emit" not in ln)


def _run(argv, root):
    """``(status, stderr lines, {relative file: normalised content})`` of one in-process run
    writing under ``root``."""
    root.mkdir(parents=True, exist_ok=True)
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            status = main([str(a) for a in argv])
        except SystemExit as e:                     # argparse refusals
            status = e.code
    lines = [ln for ln in err.getvalue().splitlines() if ln.strip()]
    out = {str(p.relative_to(root)): _normal(p) for p in sorted(root.rglob("*")) if p.is_file()}
    return status, lines, out


_BASE = {}


def _names(flag, action_dest):
    return (flag, action_dest, action_dest.replace("_", "-"), flag.lstrip("-").replace("-", "_"))


def _check(path, flag, value, base, tmp_path, subst, out_flag="--out", out_file="o"):
    """Run ``base`` and ``base`` + the flag; the flag changes the files written or is
    refused (exit 2, one stderr line naming it)."""
    dest = DEST[path, flag]
    fill = lambda v: subst.get(v, v)
    extra = [fill(value)] if value.startswith("--") else [flag, fill(value)]
    a, b = tmp_path / "a", tmp_path / "b"
    argv = lambda root: [*path, *[fill(x) for x in base], out_flag, root / out_file]
    key = (path, tuple(base), out_file)
    if key not in _BASE:                        # one base run per command and base flags
        _BASE[key] = _run(argv(a), a)
    status0, err0, before = _BASE[key]
    assert status0 == 0, f"the base run {argv(a)} failed: {err0}"
    if flag == out_flag:        # the base run is given a non-default --out: what it wrote
        assert before, f"{' '.join(path)}: the base run wrote nothing under its {flag}"
        return                  # is there (a second directory would test it again)
    status, err, after = _run([*argv(b), *extra], b)
    if status == 2:
        assert len(err) == 1 and any(n in err[0] for n in _names(flag, dest)), \
            f"{' '.join(path)} {flag}: refused, but stderr is not one line naming it: {err}"
        assert not after, f"{' '.join(path)} {flag}: refused, yet wrote {sorted(after)}"
        return
    assert status == 0, f"{' '.join(path)} {flag} {value}: exit {status}: {err}"
    assert after != before, (f"{' '.join(path)} {' '.join(map(str, extra))} is accepted and "
                             f"changes nothing written: refuse it (one line, exit 2) or "
                             f"classify it in SKIP with the reason")


def _case(ident, *values, slow=False):
    return pytest.param(*values, id=ident, marks=[pytest.mark.regress] if slow else [])


# make test runs every flag of every unit but the pipeline's Config and map flags, which
# the illumination and fetch units' cases cover at a fraction of the cost (make regress
# runs them on the pipeline too).
SHARED = set(CONFIG_VALUES) | set(MAP_VALUES)
EMIT_CASES = [_case(f"{u}{f}", u, f, slow=u == "pipeline" and f in SHARED)
              for u in UNITS for f in VALUES[("emit",)] if f != "unit"]


@pytest.mark.parametrize("unit,flag", EMIT_CASES)
def test_emit_flag_changes_the_output_or_is_refused(unit, flag, files, tmp_path):
    base = [unit, *EMIT_BASE[unit]]
    _check(("emit",), flag, VALUES[("emit",)][flag], base, tmp_path,
           {k: str(v) for k, v in files.items()}, out_file="")


# make test: --model fixed (the hardware's picture); make regress: float64 as well.
RENDER_CASES = [_case(f"{m}{f}", m, f, slow=m == "float64")
                for m in ("fixed", "float64") for f in VALUES[("render",)] if f != "--model"]


@pytest.mark.parametrize("model,flag", RENDER_CASES)
def test_render_flag_changes_the_output_or_is_refused(model, flag, files, tmp_path):
    _check(("render",), flag, VALUES[("render",)][flag], ["--model", model, *RENDER_BASE],
           tmp_path, {k: str(v) for k, v in files.items()}, out_file="r.png")


def test_render_model_changes_the_output(tmp_path):
    _check(("render",), "--model", "fixed", RENDER_BASE, tmp_path, {}, out_file="r.png")


# vectors emits a pipeline and its golden outputs every run: make regress.
VECTORS_CASES = [pytest.param(f, id=f, marks=pytest.mark.regress) for f in VALUES[("vectors",)]]


@pytest.mark.parametrize("flag", VECTORS_CASES)
def test_vectors_flag_changes_the_output_or_is_refused(flag, files, tmp_path):
    _check(("vectors",), flag, VALUES[("vectors",)][flag],
           ["--pipeline", "SCENE", "--count", "16"], tmp_path,
           {k: str(v) for k, v in files.items()}, out_file="")


def _sweep_point(angle_bits, err, mult):
    return {"method": "exact", "angle_bits": angle_bits, "frac_bits": 13, "status": "ok",
            "config": {"method": "exact", "angle_bits": angle_bits, "frac_bits": 13},
            "error": {"random": {"max": err, "mean": 0.1, "n": 10}},
            "cost": {"multipliers": mult, "adders": 30, "table_bits": 1000, "ram_bits": 0,
                     "map_bits_per_texel": 24,
                     "fpga": {"device": "LFE5U-25F", "LUT4": 10 * mult, "DSP": 20 - mult, "BRAM": 2,
                              "fmax_mhz": 100.0, "available": {"LUT4": 24000, "DSP": 28, "BRAM": 56}}},
            "speed": {"golden_mpix_s": 1.0}}


@pytest.mark.parametrize("flag", [f for f in VALUES[("recommend",)] if f != "--max-error-lsb"]
                         + ["--max-error-lsb"])
def test_recommend_flag_changes_the_answer(flag, tmp_path, capsys):
    """recommend writes to stdout: each flag changes the configuration it names."""
    sweeps = {"SWEEP": [_sweep_point(12, 1, 6), _sweep_point(11, 1, 5), _sweep_point(10, 4, 4)],
              "SWEEP2": [_sweep_point(12, 1, 6), _sweep_point(13, 0, 7)]}
    for name, points in sweeps.items():
        (tmp_path / name).write_text(json.dumps({"command": "toy", "points": points}))
    base = ["recommend", "--max-error-lsb", "1", "--sweep", tmp_path / "SWEEP"]
    value = VALUES[("recommend",)][flag]
    extra = [flag, tmp_path / value if value.startswith("SWEEP") else value]
    answers = []
    for argv in (base, base + extra):
        assert main([str(a) for a in argv]) == 0
        answers.append([ln for ln in capsys.readouterr().out.splitlines() if "--angle-bits" in ln][0])
    assert answers[0] != answers[1], f"recommend {flag} {value} changed nothing"
