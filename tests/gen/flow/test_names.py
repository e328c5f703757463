"""Two designs emitted under different ``--name`` into one directory share nothing: no file
and no Verilog module, under every ``--interface``, ``--ports``, ``--load`` and ``--fusesoc``
combination (the sidecar, the named-ports wrapper, the memory images and the FuseSoC core
all follow ``--name``), and every file a design names ($readmemh, its core's filesets, its
sidecar's memory images) is one of its own.

The design is the scene pipeline with the most auxiliary files (palette shading with a
colour texture: bump map, texture and colour-table images) at tiny widths."""

import itertools
import re

import pytest

from bumprtl.gen.cli.main import main
from bumprtl.rtl.sidecar import loads

SCENE = """name = "names"
shading = "palette"
texture = true
texture_size = 16
palette_size = 16
"""

COMBOS = [c for c in itertools.product(("stream", "axis"), ("payload", "named"),
                                       ("initial", "port"), (True, False))
          if not (c[0] == "axis" and c[1] == "named")]       # named ports: stream only


def _emit(out, scene, name, interface, ports, load, fusesoc):
    """Run ``bumprtl emit pipeline``; returns the files it wrote or rewrote (by name)."""
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    argv = ["emit", "pipeline", "--scene", str(scene), "--out", str(out), "--name", name,
            "--interface", interface, "--ports", ports, "--load", load]
    assert main(argv + (["--fusesoc"] if fusesoc else [])) == 0
    return {p.name for p in out.iterdir() if before.get(p.name) != p.read_bytes()}


def _modules(path):
    return set(re.findall(r"^\s*module\s+(\S+?)\s*[(#;]", path.read_text(), re.M))


def _named_files(path):
    """The file names a file of the design refers to."""
    text = path.read_text()
    if path.suffix == ".v":
        return set(re.findall(r'\$readmem[hb]\s*\(\s*"([^"]+)"', text))
    if path.suffix == ".core":
        return set(re.findall(r"^\s*-\s*([\w.]+\.(?:v|hex|json))", text, re.M))
    if path.suffix == ".json":
        return {img["file"] for img in (loads(text).memory_images or {}).values()}
    return set()


def _check(tmp_path, combo):
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE)
    out = tmp_path / "out"
    out.mkdir()
    wrote = {name: _emit(out, scene, name, *combo) for name in ("alpha", "beta")}
    assert wrote["alpha"] and not wrote["alpha"] & wrote["beta"], \
        f"{combo}: both designs wrote {sorted(wrote['alpha'] & wrote['beta'])}"
    for name, files in wrote.items():
        other = "beta" if name == "alpha" else "alpha"
        assert all(f.startswith(name) for f in files), f"{combo}: {name} wrote {sorted(files)}"
        for f in files:
            refs = _named_files(out / f)
            assert refs <= files, f"{combo}: {f} names {sorted(refs - files)}, not {name}'s"
            assert not any(r.startswith(other) for r in refs)
    modules = {n: set().union(*(_modules(out / f) for f in fs if f.endswith(".v")))
               for n, fs in wrote.items()}
    assert modules["alpha"] and modules["beta"]
    assert not modules["alpha"] & modules["beta"], \
        f"{combo}: module names in both designs: {sorted(modules['alpha'] & modules['beta'])}"


@pytest.mark.parametrize("combo", [c for c in COMBOS if c[3]], ids=lambda c: "-".join(c[:3]))
def test_two_names_share_no_file_and_no_module(tmp_path, combo):
    """With ``--fusesoc`` (the core lists every other file, so its combinations cover those
    without it): every interface, ports and load."""
    _check(tmp_path, combo)


@pytest.mark.regress
@pytest.mark.parametrize("combo", [c for c in COMBOS if not c[3]], ids=lambda c: "-".join(c[:3]))
def test_two_names_share_no_file_and_no_module_without_a_core(tmp_path, combo):
    _check(tmp_path, combo)
