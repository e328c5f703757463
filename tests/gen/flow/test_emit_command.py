"""``bumprtl emit``'s sidecar ``command`` reproduces the whole emission, and ``--load``
decides whether the map's host write port exists (gen/cli/emit.py, gen/flow/memories.py).

The recorded command, run again into another directory, writes the same files byte for
byte (every flag that shapes a file is in it: ``--ports named``, ``--interface``,
``--load``, ``--name``, the map flags, ``--fusesoc``). With ``--load initial`` (the
default) no map write port is emitted: not in the module, the named wrapper or the
sidecar; with ``--load port`` it is in all three.
"""

import contextlib
import io
import shlex

import numpy as np
import pytest
from PIL import Image

from bumprtl.gen.cli.main import main
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.rtl.sidecar import loads

SMALL = ["--angle-bits", "6", "--frac-bits", "8", "--texture-size", "16"]


def _emit(argv, out):
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(["emit", *argv, "--out", str(out)]) == 0


def _files(folder):
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def _height_map(path):
    yy, xx = np.mgrid[0:16, 0:16]
    Image.fromarray(((xx * 13 + yy * 7) % 256).astype(np.uint8)).save(path)
    return str(path)


CASES = {
    "named-port-fusesoc": ["pipeline", *SMALL, "--load", "port", "--name", "my_bump",
                           "--ports", "named", "--fusesoc"],
    "axis-height-map-port": ["pipeline", *SMALL, "--height-map", "MAP", "--load", "port",
                             "--interface", "axis", "--name", "ax"],
    "rotation-named": ["rotation", "--method", "lee", "--angle-bits", "6", "--frac-bits", "8",
                       "--name", "rot", "--ports", "named"],
    "rotation-axis-wide-tdata": ["rotation", "--method", "lee", "--angle-bits", "6",
                                 "--frac-bits", "8", "--interface", "axis", "--tdata-width", "128"],
}


@pytest.fixture(scope="module")
def emitted(tmp_path_factory):
    """Each case emitted once into ``<case>/a``."""
    root = tmp_path_factory.mktemp("emit")
    for case, argv in CASES.items():
        argv = [_height_map(root / "h.png") if a == "MAP" else a for a in argv]
        _emit(argv, root / case / "a")
    return root


@pytest.mark.parametrize("case", list(CASES))
def test_the_recorded_command_writes_the_same_files(case, emitted):
    tmp_path = emitted / case
    first = _files(tmp_path / "a")
    sidecar = next(n for n in first if n.endswith(".json"))
    command = loads(first[sidecar]).command
    words = shlex.split(command)
    assert words[:3] == ["bumprtl", "emit", CASES[case][0]] and "--out" not in words, command
    _emit(words[2:], tmp_path / "b")
    again = _files(tmp_path / "b")
    assert sorted(again) == sorted(first), command
    assert [n for n in first if first[n] != again[n]] == [], command


def _host_ports(folder, name):
    meta = load_sidecar(folder / f"{name}.json")
    found = {"module": "map_w_en" in (folder / f"{name}.v").read_text(),
             "ports": "map_w_en" in meta.ports,
             "named": "map_w_en" in meta.named_ports.ports,
             "wrapper": "map_w_en" in (folder / f"{name}_named.v").read_text(),
             "image": "port" in meta.memory_images["map"]}
    return found, meta.memory_images["map"]["load"]


def test_load_initial_emits_no_host_write_port_and_load_port_does(tmp_path, emitted):
    _emit(["pipeline", *SMALL, "--name", "a", "--ports", "named"], tmp_path)
    initial, load = _host_ports(tmp_path, "a")
    assert load == "initial" and not any(initial.values()), initial
    port, load = _host_ports(emitted / "named-port-fusesoc" / "a", "my_bump")
    assert load == "port" and all(port.values()), port


def test_scene_command_gives_a_boolean_key_as_its_flag_or_no_flag():
    """A boolean scene key that differs from the named scene's is ``--key`` or
    ``--no-key``, and the emit parser reads it back to the same value."""
    from bumprtl.gen.cli.main import build_parser
    from bumprtl.gen.flow.memories import scene_command
    from bumprtl.sim.scenes.config import load_scene_config

    base = load_scene_config("default")
    for key in ("specular", "resample"):
        scene = base.replace(**{key: not getattr(base, key)})
        command = scene_command("pipeline", scene)
        args = build_parser().parse_args(command.split()[1:])
        assert getattr(args, key) is (not getattr(base, key)), command


@pytest.mark.parametrize("load", ["initial", "port"])
def test_an_axis_scene_unit_carries_the_maps_the_stream_one_does(tmp_path, load):
    """`--interface axis` wraps the same scene pipeline: its map image (built in, or for the
    host write port) is the stream emission's, byte for byte, and its sidecar records it."""
    base = ["pipeline", *SMALL, "--load", load, "--name", "m"]
    _emit(base, tmp_path / "stream")
    _emit([*base, "--interface", "axis"], tmp_path / "axis")
    stream, axis = _files(tmp_path / "stream"), _files(tmp_path / "axis")
    assert axis["m_axis_map.hex"] == stream["m_map.hex"]
    meta = loads(axis["m_axis.json"])
    assert meta.memory_images["map"]["load"] == load
    assert meta.memory_images["map"]["file"] == "m_axis_map.hex"
    assert ("map_w_en" in axis["m_axis.v"].decode()) == (load == "port")
