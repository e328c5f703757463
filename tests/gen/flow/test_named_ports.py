"""``bumprtl emit --name PREFIX`` and ``--ports named``: the top module and every submodule
carry the prefix, and two differently configured pipelines, each behind its named-ports
wrapper, sit side by side in one Verilog design that lints clean and simulates bit-exact
against the golden model on Icarus and on Verilator."""

import json
import re

import numpy as np
import pytest

from bumprtl.gen.cli.main import main
from bumprtl.gen.flow.emit import lint
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed, random_inputs
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb.runner import run_cocotb

# Two pipelines of the default scene class at different widths; a's map is written through
# its host port, b's is built in.
SETUPS = {"a_": ("bm_a", {"texture_size": 16, "angle_bits": 10, "frac_bits": 11}, "port"),
          "b_": ("bm_b", {"texture_size": 16, "angle_bits": 11, "frac_bits": 12}, "initial")}
PIXELS = 120


def _flags(over):
    return [x for k, v in over.items() for x in (f"--{k.replace('_', '-')}", str(v))]


def test_name_prefixes_the_top_and_every_submodule(tmp_path, capsys):
    """Default ``bumprtl_<unit>``; ``--name`` renames the file, the top module, every kept
    submodule (``\\<name>.<path>``) and goes into the reproducing command."""
    base = ["emit", "rotation", "--angle-bits", "8", "--frac-bits", "8"]
    assert main([*base, "--out", str(tmp_path / "d")]) == 0
    text = (tmp_path / "d" / "bumprtl_rotation.v").read_text()
    modules = re.findall(r"^module (\S+)", text, re.M)
    assert modules[0] == "bumprtl_rotation(i__valid," and len(modules) > 1
    assert all(m.startswith("\\bumprtl_rotation.") for m in modules[1:]), modules
    assert "--name" not in text.splitlines()[0]
    assert main([*base, "--name", "my_rot", "--out", str(tmp_path / "n")]) == 0
    named = (tmp_path / "n" / "my_rot.v").read_text()
    assert named.splitlines()[0].endswith("--name my_rot")
    assert all(m.startswith(("my_rot(", "\\my_rot.")) for m in re.findall(r"^module (\S+)", named, re.M))
    body = lambda t: t.split("\n", 2)[2]
    assert body(named) == body(text).replace("bumprtl_rotation", "my_rot")    # only the names
    assert load_sidecar(tmp_path / "n" / "my_rot.json").module == "my_rot"
    capsys.readouterr()
    for bad in ("9lives", "a-b", "x y"):
        assert main([*base, "--name", bad, "--out", str(tmp_path / "bad")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "--name must be a Verilog identifier" in err[0], err
    assert main([*base, "--ports", "named", "--interface", "axis", "--out", str(tmp_path / "x")]) == 2
    assert "--ports named applies to --interface stream" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists() and not (tmp_path / "x").exists()


def _top(wrappers):
    """A design with every wrapper side by side, its ports ``<prefix><port>`` at the top."""
    decl, inst = ["  input wire clk", "  input wire rst"], []
    for prefix, (module, ports) in wrappers.items():
        conns = []
        for n, p in ports.items():
            if n in ("clk", "rst"):
                conns.append(f"    .{n}({n})")
                continue
            vec = f"{'signed ' if p.signed else ''}[{p.width - 1}:0] " if p.width > 1 else ""
            decl.append(f"  {'input' if p.dir == 'in' else 'output'} wire {vec}{prefix}{n}")
            conns.append(f"    .{n}({prefix}{n})")
        inst.append(f"  {module} u_{prefix}pipe (\n" + ",\n".join(conns) + "\n  );")
    return "module two_pipes (\n" + ",\n".join(decl) + "\n);\n" + "\n".join(inst) + "\nendmodule\n"


@pytest.fixture(scope="module")
def side_by_side(tmp_path_factory):
    root = tmp_path_factory.mktemp("named")
    units, sources, wrappers = {}, [], {}
    for prefix, (name, over, load) in SETUPS.items():
        assert main(["emit", "pipeline", "--scene", "default", *_flags(over), "--load", load,
                     "--name", name, "--ports", "named", "--out", str(root / "rtl")]) == 0
        j = root / "rtl" / f"{name}.json"
        meta = load_sidecar(j)
        ports = meta.named_ports.ports
        assert meta.named_ports.module == f"{name}_named" and meta.module == name
        scene = load_scene_config("default", over)
        words = np.array([int(w, 16) for w in (root / "rtl" / f"{name}_map.hex").read_text().split()])
        inputs = random_inputs(scene, PIXELS, np.random.default_rng(len(units)))
        stim = {n: inputs[p.field] for n, p in ports.items() if p.dir == "in" and p.field}
        assert len(stim) == len(inputs)          # every input field has its port
        if load == "port":                       # the map through the host write port
            stim.update({"setup.map_w_en": np.ones(len(words), np.int64),
                         "setup.map_w_addr": np.arange(len(words)), "setup.map_w_data": words})
        np.savez(root / f"{prefix}stim.npz", **stim)
        units[prefix] = {"sidecar": str(j), "stimulus": str(root / f"{prefix}stim.npz"),
                         "result": str(root / f"{prefix}result.npz"),
                         "golden": (pipeline_fixed(inputs, scene, words), inputs["tag"])}
        sources += [root / "rtl" / f"{name}.v", root / "rtl" / f"{name}_named.v"]
        wrappers[prefix] = (f"{name}_named", ports)
    top = root / "two_pipes.v"
    top.write_text(_top(wrappers))
    return top, sources, units


def test_two_named_pipelines_in_one_design_lint_clean(side_by_side):
    top, sources, _ = side_by_side
    assert lint(top, sources=sources) == []
    # the lint can fail: the same design with one wrapper's port narrowed
    broken = top.with_name("broken.v")
    broken.write_text(top.read_text().replace("module two_pipes", "module broken")
                      .replace("a_in_tag", "a_in_tag[3:0]", 1))
    assert lint(broken, sources=sources) != []


@pytest.mark.parametrize("sim", ["icarus", pytest.param("verilator", marks=pytest.mark.regress)])
def test_two_named_pipelines_side_by_side_match_the_golden_model(side_by_side, sim, tmp_path,
                                                                monkeypatch):
    """Both pipelines stream at once (input gaps, output stalls) through their named ports;
    every output field of every pixel equals the fixed-point golden model's. Verilator
    compiles at -O0 (a few hundred cycles: the C++ compile is the cost) and runs in make
    regress (its build of the two pipelines took 36 s to 4 min on 2 busy cores)."""
    top, sources, units = side_by_side
    flags = "OPT_FAST=-O0 OPT_SLOW=-O0 OPT_GLOBAL=-O0 CFG_CXXFLAGS_PCH_I=-include"
    monkeypatch.setenv("MAKEFLAGS", f"{__import__('os').environ.get('MAKEFLAGS', '')} {flags}".strip())
    env = {p: {k: v for k, v in u.items() if k != "golden"} for p, u in units.items()}
    for u in env.values():
        u["result"] = str(tmp_path / ("r_" + u["result"].rsplit("/", 1)[1]))
    run_cocotb(sim, top, "bumprtl.sim.tb.tb_named", tmp_path / sim,
               {"BUMPRTL_NAMED": json.dumps(env)}, sources=sources)
    for prefix, u in units.items():
        got = dict(np.load(env[prefix]["result"]))
        golden, tags = u["golden"]
        assert np.array_equal(got["out_tag"], tags), prefix
        compared = [k for k in golden if f"out_{k}" in got]
        assert {"diffuse", "specular", "color"} <= set(compared), compared
        for k in compared:
            assert np.array_equal(got[f"out_{k}"], golden[k]), (prefix, k)


@pytest.mark.parametrize("flags", [["--ports", "named"], ["--interface", "axis"]])
def test_emit_lint_lints_each_wrapper_with_the_design_it_wraps(tmp_path, run_cli, flags):
    """``bumprtl emit --lint`` with a wrapper (named ports, AXI4-Stream): the design and the
    wrapper, linted with the design's Verilog beside it (alone it names a module Verilator
    cannot find), are clean, and the command says so."""
    r = run_cli(["emit", "sincos", *flags, "--lint", "--out", tmp_path])
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.splitlines()[-1] == "lint: clean"
