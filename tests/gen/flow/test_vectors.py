"""``bumprtl vectors`` (gen/flow/vectors.py, gen/flow/vectors_tb.py): the bench it writes
passes on Icarus against the emitted pipeline, fails naming the first mismatch when one
expected word is changed, fails on a timeout when the design never answers; a user's
pixels in physical units are encoded as docs/integration.md defines the binary angles;
bad input is one line naming the parameter, exit 2, nothing written."""

import csv
import math
import shlex
import shutil
import subprocess
import time

import numpy as np
import pytest

from bumprtl.gen.flow.vectors import MAX_COUNT, pipeline_vectors, pixel_columns
from bumprtl.gen.flow.vectors_tb import run_commands
from bumprtl.gen.tools.toolchain import tool_env
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.scenes.config import load_scene_config

PIXELS = 120
TB = "bumprtl_pipeline_tb"


def _icarus(d, sources, out="tb.vvp"):
    subprocess.run(["iverilog", "-g2005", "-s", TB, "-o", out, *sources], cwd=d, check=True,
                   capture_output=True, text=True)
    return d / out


def _vvp(d, vvp, *plusargs):
    """The bench's output lines (run in ``d``, where its $readmemh files are)."""
    r = subprocess.run(["vvp", "-n", str(vvp), *plusargs], cwd=d, capture_output=True,
                       text=True, timeout=300)
    return r.stdout.splitlines()


def _sources(module="bumprtl_pipeline"):
    return [f"{module}_tb.v", f"{module}_named.v", f"{module}.v"]


@pytest.fixture(scope="module")
def default_bench(tmp_path_factory):
    """The documented command (random pixels of the default scene, map built in), compiled."""
    from bumprtl.gen.cli.main import main
    out = tmp_path_factory.mktemp("vectors_default")
    assert main(["vectors", "--pipeline", "default", "--count", str(PIXELS), "--out", str(out)]) == 0
    return out, _icarus(out, _sources())


def test_default_bench_passes_on_icarus_under_two_seeds(default_bench):
    out, vvp = default_bench
    for plusargs in ((), ("+seed=12345",)):
        lines = _vvp(out, vvp, *plusargs)
        assert lines[-1] == f"PASS {PIXELS}", lines
        assert sum(ln.startswith(("PASS", "FAIL")) for ln in lines) == 1
    assert "seed 12345" in _vvp(out, vvp, "+seed=12345")[-2]


def _copy(src, dst):
    """The bench directory's small files (and the compiled bench) in a fresh directory."""
    dst.mkdir(exist_ok=True)
    for f in src.iterdir():
        if f.suffix in (".hex", ".vvp", ".json"):
            shutil.copy(f, dst / f.name)
    return dst


def test_one_changed_expected_word_fails_naming_pixel_field_and_values(default_bench, tmp_path):
    out, vvp = default_bench
    d = _copy(out, tmp_path / "mutant")
    path = d / "bumprtl_pipeline_out_color.hex"
    words = path.read_text().splitlines()
    k = 37
    good = int(words[k], 16)
    words[k] = f"{good ^ 0x10:02x}"
    path.write_text("\n".join(words) + "\n")
    lines = _vvp(d, d / vvp.name)
    assert lines == [f"FAIL pixel {k} field color: got {good}, expected {good ^ 0x10}"]


def _stub(meta, valid):
    """A module with the named ports of ``meta`` that takes every pixel and never (or always)
    raises out_valid: a hung (or babbling) pipeline."""
    ports = meta.named_ports.ports
    decl = ",\n".join(f"  {'input' if p.dir == 'in' else 'output'} wire "
                      f"{f'[{w - 1}:0] ' if (w := p.width) > 1 else ''}{n}" for n, p in ports.items())
    value = {"in_ready": 1, "out_valid": int(valid)}          # every other output 0
    body = "\n".join(f"  assign {n} = {value.get(n, 0)};" for n, p in ports.items()
                     if p.dir == "out")
    return f"module {meta.named_ports.module} (\n{decl}\n);\n{body}\nendmodule\n"


@pytest.mark.parametrize("valid, verdict", [(False, f"FAIL timeout: 0 of {PIXELS} pixels out"),
                                            (True, "FAIL pixel 0 field ")])
def test_a_hung_or_babbling_design_fails(default_bench, tmp_path, valid, verdict):
    out, _ = default_bench
    d = _copy(out, tmp_path / "stub")
    meta = load_sidecar(d / "bumprtl_pipeline.json")
    (d / "stub.v").write_text(_stub(meta, valid))
    shutil.copy(out / f"{TB}.v", d)
    t0 = time.perf_counter()
    lines = _vvp(d, _icarus(d, [f"{TB}.v", "stub.v"]))
    assert len(lines) == 1 and lines[0].startswith(verdict), lines
    assert time.perf_counter() - t0 < 60


def test_expected_words_are_the_golden_models_of_the_stimulus(default_bench):
    """The files hold what they say: tags pass through, every field file has one word a
    pixel, and the sidecar's named ports all have a file (in_* stimulus, out_* expected)."""
    out, _ = default_bench
    meta = load_sidecar(out / "bumprtl_pipeline.json")
    fields = [n for n, p in meta.named_ports.ports.items() if p.bits is not None]
    for n in fields:
        assert len((out / f"bumprtl_pipeline_{n}.hex").read_text().splitlines()) == PIXELS, n
    assert (out / "bumprtl_pipeline_in_tag.hex").read_text() == \
        (out / "bumprtl_pipeline_out_tag.hex").read_text()
    tb = (out / f"{TB}.v").read_text()
    assert tb.startswith(f"// Generated by: bumprtl vectors --pipeline default --source random "
                         f"--count {PIXELS} --seed 1")
    assert "map_w_en <=" not in tb                # --load initial: the map is built in


def _write_csv(path, cols):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(list(cols))
        w.writerows(zip(*cols.values(), strict=True))


def test_palette_bench_with_the_users_pixels_and_the_table_through_the_port(tmp_path):
    """Another scene class (palette: a colour table written through lut_w_* and swapped in,
    the map through map_w_*) with the user's texel coordinates, negatives included."""
    from bumprtl.gen.cli.main import main
    rng = np.random.default_rng(5)
    n = 80
    _write_csv(tmp_path / "px.csv", {"u": rng.integers(-128, 128, n), "v": rng.integers(-128, 128, n)})
    out = tmp_path / "pal"
    assert main(["vectors", "--pipeline", "palette", "--source", str(tmp_path / "px.csv"),
                 "--load", "port", "--out", str(out)]) == 0
    tb = (out / f"{TB}.v").read_text()
    assert "lut_swap <= 1'b1" in tb and "map_w_en <= 1'b1" in tb
    lines = _vvp(out, _icarus(out, _sources()))
    assert lines[-1] == f"PASS {n}", lines


def test_flat_bench_loads_its_polygon_word_and_fails_with_another(tmp_path):
    """A flat map (its tangent frame from the polygon registers, no map): the bench writes
    ``<module>_poly.hex``, the polygon's fields packed at the sidecar's offsets, loads it
    into ``poly`` and passes; with one bit of that word flipped it fails."""
    from bumprtl.gen.cli.main import main
    out = tmp_path / "flat"
    n = 60
    assert main(["vectors", "--pipeline", "flat", "--count", str(n), "--out", str(out)]) == 0
    meta = load_sidecar(out / "bumprtl_pipeline.json")
    poly = out / "bumprtl_pipeline_poly.hex"
    word = int(poly.read_text(), 16)
    vec = pipeline_vectors(load_scene_config("flat"), "random", n)
    for name, (off, width, _signed) in meta.fields_of("poly").items():
        assert (word >> off) & ((1 << width) - 1) == int(vec.polygon[name]) & ((1 << width) - 1), name
    vvp = _icarus(out, _sources())
    assert _vvp(out, vvp)[-1] == f"PASS {n}"
    bad = _copy(out, tmp_path / "bad")
    off, width, _ = next(iter(meta.fields_of("poly").values()))
    (bad / poly.name).write_text(f"{word ^ (1 << (off + width - 2)):0{len(poly.read_text().strip())}x}\n")
    assert _vvp(bad, bad / vvp.name)[-1].startswith("FAIL")


def _angles(rng, n, hi):
    a = rng.uniform(0, hi, n)
    a[:3] = (0.0, hi, hi / 2)                 # both ends; 2 pi is the full circle, code 0
    return a


def test_users_physical_values_encode_to_the_documented_binary_angles(tmp_path):
    """An angle field of k bits holds round(angle / 2 pi * 2^k) modulo 2^k
    (docs/integration.md), computed here by hand; coordinates and tags as given; the
    .npy forms (structured, 2-D in column order) give the same codes as the CSV."""
    scene = load_scene_config("default")
    k, n = scene.angle_bits, 40
    rng = np.random.default_rng(9)
    cols = {"u": rng.integers(-128, 128, n), "v": rng.integers(-128, 128, n)}
    for name in ("n", "l", "h"):
        cols[f"{name}_phi"] = _angles(rng, n, 2 * math.pi)
        cols[f"{name}_theta"] = _angles(rng, n, math.pi)
    cols["tag"] = rng.integers(0, 1 << 16, n)
    assert list(cols) == list(pixel_columns(scene))
    _write_csv(tmp_path / "px.csv", {c: [repr(float(x)) if "_" in c else int(x) for x in v]
                                     for c, v in cols.items()})
    vec = pipeline_vectors(scene, tmp_path / "px.csv")
    for c, v in cols.items():
        key = c.replace("_", ".")
        want = [int(math.floor(x / (2 * math.pi) * 2 ** k + 0.5)) % 2 ** k for x in v] \
            if "_" in c else [int(x) for x in v]
        assert vec.inputs[key].tolist() == want, c
    assert vec.inputs["n.phi"][1] == 0 and vec.inputs["n.theta"][1] == 2 ** (k - 1)
    table = np.array(list(zip(*cols.values(), strict=True)), float)
    structured = np.zeros(n, [(c, float) for c in cols])
    for c in cols:
        structured[c] = cols[c]
    for i, arr in enumerate((table, table[:, :-1], structured)):
        np.save(tmp_path / f"px{i}.npy", arr)
        got = pipeline_vectors(scene, tmp_path / f"px{i}.npy").inputs
        for key, v in vec.inputs.items():
            if key != "tag" or i != 1:            # without a tag column: the pixel index
                assert got[key].tolist() == v.tolist(), (i, key)
        if i == 1:
            assert got["tag"].tolist() == list(range(n))


def test_rotation_unit_bench_with_the_users_angles(tmp_path):
    """``--unit rotation``: the unit alone behind its named ports, the user's N, L, H and N'
    (``b_*``) in radians encoded as the documented binary angles, PASS on Icarus."""
    from bumprtl.gen.cli.main import main
    rng = np.random.default_rng(11)
    n, k = 60, 10
    cols = {f"{v}_{a}": _angles(rng, n, 2 * math.pi if a == "phi" else math.pi)
            for v in "nlhb" for a in ("phi", "theta")}
    _write_csv(tmp_path / "px.csv", {c: [repr(float(x)) for x in v] for c, v in cols.items()})
    out = tmp_path / "rot"
    assert main(["vectors", "--unit", "rotation", "--angle-bits", str(k), "--frac-bits", "11",
                 "--source", str(tmp_path / "px.csv"), "--out", str(out)]) == 0
    for c, v in cols.items():
        words = (out / f"bumprtl_rotation_in_{c}.hex").read_text().split()
        assert [int(w, 16) for w in words] == \
            [int(math.floor(x / (2 * math.pi) * 2 ** k + 0.5)) % 2 ** k for x in v], c
    tb = "bumprtl_rotation_tb"
    subprocess.run(["iverilog", "-g2005", "-s", tb, "-o", "tb.vvp", f"{tb}.v",
                    "bumprtl_rotation_named.v", "bumprtl_rotation.v"], cwd=out, check=True)
    assert _vvp(out, out / "tb.vvp")[-1] == f"PASS {n}"
    # the bench's first line reproduces every file it wrote, byte for byte
    line = (out / f"{tb}.v").read_text().splitlines()[0]
    assert line.startswith("// Generated by: bumprtl vectors --unit rotation")
    again = tmp_path / "again"
    assert main([*shlex.split(line)[4:], "--out", str(again)]) == 0
    for f in out.glob("bumprtl_rotation*"):
        assert (again / f.name).read_bytes() == f.read_bytes(), f.name


def test_frame_source_is_the_renders_stimulus_and_random_is_seeded():
    from bumprtl.gen.render.rtl import scene_stimulus
    scene = load_scene_config("default")
    frame = pipeline_vectors(scene, "frame", 300)
    whole, *_ = scene_stimulus(scene, 32)                    # the 32 x 32 frame, raster order
    assert all(frame.inputs[k].tolist() == whole[k][:300].tolist() for k in frame.inputs)
    a, b, c = (pipeline_vectors(scene, "random", 50, seed=s).inputs for s in (3, 3, 4))
    assert all(a[k].tolist() == b[k].tolist() for k in a)
    assert any(a[k].tolist() != c[k].tolist() for k in a if k != "tag")


BAD = [
    (["--pipeline", "nosuch"], "--pipeline must be a scene TOML file or one of default"),
    (["--count", "0"], f"--count must be an integer in [1, {MAX_COUNT}], got 0"),
    (["--count", str(MAX_COUNT + 1)], f"--count must be an integer in [1, {MAX_COUNT}]"),
    (["--source", "pixels"], "--source must be one of frame, random or a .csv or .npy file"),
    (["--source", "{dir}/none.csv"], "none.csv: no such file"),
    (["--source", "{dir}/cols.csv"], "columns must be u, v, n_phi, n_theta, l_phi, l_theta, h_phi, "
                                     "h_theta (and optionally tag)"),
    (["--source", "{dir}/angle.csv"], "column l_theta must hold radians in [0, pi], got 3.5 in pixel 1"),
    (["--source", "{dir}/coord.csv"], "column u must hold integers in [-128, 127], got 128 in pixel 0"),
    (["--source", "{dir}/junk.npy"], "junk.npy: cannot read it"),
    (["--source", "{dir}/text.csv"], "line 2, column v: 'x' is not a number"),
    (["--source", "{dir}/cols.csv", "--count", "5"], "columns must be"),
    (["--source", "{dir}/good.csv", "--count", "3"], "--count must be at most the 2 pixels of"),
    (["--name", "9bad"], "--name must be a Verilog identifier"),
    (["--top", "a-b"], "--top must be a Verilog identifier"),
    (["--seed", "-1"], "--seed must be an integer in [0, 2147483647], got -1"),
    (["--unit", "illumination", "--source", "{dir}/good.csv"],
     "--source FILE applies to --pipeline and --unit rotation"),
    (["--unit", "rotation", "--pipeline", "default"], "--unit rotation and --pipeline default"),
    (["--unit", "rotation", "--load", "port"], "--load applies to --pipeline"),
    (["--unit", "rotation", "--source", "{dir}/good.csv"],
     "columns must be n_phi, n_theta, l_phi, l_theta, h_phi, h_theta, b_phi, b_theta"),
    (["--unit", "rotation", "--angle-bits", "99"], "angle_bits"),
    (["--unit", "rotation", "--ka", "0.5"], "--ka does not apply to --unit rotation"),
]


@pytest.mark.parametrize("argv, message", BAD, ids=[" ".join(a) for a, _ in BAD])
def test_bad_input_is_one_line_exit_2_nothing_written(tmp_path, run_cli, argv, message):
    head = "u,v,n_phi,n_theta,l_phi,l_theta,h_phi,h_theta\n"
    (tmp_path / "cols.csv").write_text("u,v,n_phi,n_theta,l_phi,l_theta\n1,2,0,0,0,0\n")
    (tmp_path / "angle.csv").write_text(head + "0,0,0,0,0,0,0,0\n1,2,0,0,0,3.5,0,0\n")
    (tmp_path / "coord.csv").write_text(head + "128,0,0,0,0,0,0,0\n")
    (tmp_path / "text.csv").write_text(head + "1,x,0,0,0,0,0,0\n")
    (tmp_path / "good.csv").write_text(head + "1,2,0,0,0,0,0,0\n3,4,1,1,1,1,1,1\n")
    (tmp_path / "junk.npy").write_bytes(b"\x93NUMPY garbage")
    out = tmp_path / "out"
    r = run_cli(["vectors", *[a.format(dir=tmp_path) for a in argv], "--out", out])
    assert r.returncode == 2, r
    assert len(r.stderr.splitlines()) == 1 and message in r.stderr, r.stderr
    assert not out.exists()


def test_help_has_examples(run_cli):
    r = run_cli(["vectors", "--help"])
    assert r.returncode == 0
    assert "bumprtl vectors --pipeline default --count 1000 --out build/vec" in r.stdout
    assert "--source" in r.stdout and "radians" in r.stdout


@pytest.mark.regress
def test_default_bench_passes_on_verilator(tmp_path):
    """The same bench file, built by the command it prints for Verilator (--binary)."""
    from bumprtl.gen.cli.main import main
    assert main(["vectors", "--pipeline", "default", "--count", "300", "--out", str(tmp_path)]) == 0
    cmd = run_commands("bumprtl_pipeline")["verilator"]
    r = subprocess.run(cmd, shell=True, cwd=tmp_path, capture_output=True, text=True,
                       env=tool_env(), timeout=1800)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.splitlines()[-1] == "PASS 300", r.stdout[-2000:]


def test_unit_vectors_from_the_frame_and_at_random_chain_rotation_into_illumination():
    """A unit's vectors from the default frame or at random: the frame does not depend on
    the seed, random does; illumination's inputs are rotation's expected outputs of the
    same pixels, and every expected tag is its input's."""
    from bumprtl.gen.flow.vectors import unit_vectors
    from bumprtl.rtl.config import Config

    cfg = Config()
    for source in ("frame", "random"):
        rot = unit_vectors("rotation", cfg, source, count=64, seed=1)
        ill = unit_vectors("illumination", cfg, source, count=64, seed=1)
        assert all(len(v) == 64 for v in rot.inputs.values())
        assert np.array_equal(rot.expected["tag"], rot.inputs["tag"])
        for field, values in ill.inputs.items():
            if field != "tag":
                assert np.array_equal(values, rot.expected[field]), (source, field)
        other = unit_vectors("rotation", cfg, source, count=64, seed=2)
        same = all(np.array_equal(other.inputs[k], rot.inputs[k]) for k in rot.inputs)
        assert same == (source == "frame"), source


def test_the_design_vectors_writes_is_emit_pipelines_with_named_ports(default_bench, tmp_path):
    """`bumprtl vectors` writes the pipeline as `bumprtl emit pipeline --scene default
    --ports named --name bumprtl_pipeline` does: the same Verilog, named wrapper, memory
    images and sidecar (the command it records included)."""
    from bumprtl.gen.cli.main import main
    out, _vvp_path = default_bench
    emitted = tmp_path / "emit"
    assert main(["emit", "pipeline", "--scene", "default", "--ports", "named", "--name",
                 "bumprtl_pipeline", "--out", str(emitted)]) == 0
    files = sorted(p.name for p in emitted.iterdir() if p.is_file())
    assert "bumprtl_pipeline.json" in files and "bumprtl_pipeline_named.v" in files
    for name in files:
        assert (out / name).read_bytes() == (emitted / name).read_bytes(), name
