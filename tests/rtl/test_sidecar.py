"""rtl/sidecar.py: the typed, versioned sidecar.

Every unit's and every built-in scene's Sidecar survives dump/load unchanged (built without
emitting Verilog: ``build_unit`` elaborates for the memory records only); ``load`` refuses
another schema version, an untyped version-1 file, a missing and an unknown key with one
line naming the key and the supported version; the payload fields of an emitted design sit
at the bits the Verilog itself slices them from.
"""

import json
import re

import pytest

from bumprtl.gen.flow.emit import port_table
from bumprtl.gen.flow.units import SCENE_UNITS, UNITS, build_unit, emit_unit
from bumprtl.rtl.bumpfetch import BumpMapFetch
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.sidecar import (
    CHANGES_FROM_1,
    CHANGES_FROM_2,
    SCHEMA_VERSION,
    Field,
    Memory,
    from_facts,
    load,
    loads,
)
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config

SMALL = Config(angle_bits=8, frac_bits=10)        # the facts, not the widths, are under test


def _fetches(scene):
    """Whether the scene has a fetch unit of its own (a flat map without texture has none:
    ``bumprtl emit fetch`` refuses it)."""
    try:
        BumpMapFetch(scene.hardware)._MustUse__silence = True
    except BumpError:
        return False
    return True


def _sidecars():
    for name in UNITS:
        if name not in SCENE_UNITS:
            yield name, name, SMALL
    for scene in BUILTIN:
        cfg = load_scene_config(scene)
        yield f"pipeline-{scene}", "pipeline", cfg
        if _fetches(cfg):
            yield f"fetch-{scene}", "fetch", cfg


@pytest.mark.parametrize(("unit", "cfg"), [pytest.param(u, c, id=label)
                                            for label, u, c in _sidecars()])
def test_round_trip_of_every_unit_and_scene(unit, cfg):
    side = build_unit(unit, cfg)[1]
    assert side.schema_version == SCHEMA_VERSION and side.unit == unit
    assert loads(side.dumps()) == side
    again = json.loads(side.dumps())
    assert again["schema_version"] == SCHEMA_VERSION
    assert set(side.input_fields) and set(side.output_fields)
    for port in ("i__payload", "o__payload"):          # fields tile inside the port
        fields = sorted(side.fields_of(port).values(), key=lambda f: f.offset)
        assert all(a.msb < b.offset for a, b in zip(fields, fields[1:], strict=False))
        assert fields[-1].msb < side.port(port).width


def test_memories_keep_roms_and_rams_apart():
    """The palette's colour table is written by the host: a RAM; sincos' quarter sine a ROM;
    a scene's map with host write ports a RAM, built in without them a ROM."""
    palette = build_unit("palette", SMALL)[1]
    assert set(palette.rams) == {"table"} and not palette.roms
    assert palette.memories["table"] == Memory("ram", 2 * SMALL.palette_size, 32,
                                               2 * SMALL.palette_size * 32)
    sincos = build_unit("sincos", SMALL)[1]
    assert set(sincos.roms) == {"quarter_sine"} and not sincos.rams
    scene = load_scene_config("palette")
    kinds = {n: m.kind for n, m in build_unit("pipeline", scene)[1].memories.items()}
    assert kinds == {"fetch.map": "ram", "palette.table": "ram"}      # host write ports
    assert _port_less(scene).memories["fetch.map"].kind == "rom"


def _port_less(scene):
    """The pipeline's Sidecar without the map's host write port (``--load initial``)."""
    dut = BumpPipeline(scene.hardware, write_port=False)
    facts = {"config": scene.config.to_dict(), **UNITS["pipeline"].sidecar(scene, dut)}
    return from_facts("pipeline", "bumprtl emit pipeline", port_table(dut), facts)


def _text(**changes):
    d = json.loads(build_unit("sincos", SMALL)[1].dumps())
    for key, value in changes.items():
        if value is None:
            del d[key]
        else:
            d[key] = value
    return json.dumps(d)


@pytest.mark.parametrize("version", [0, 1, 2, 99, "3", 3.0, True])
def test_another_version_is_refused_in_one_line(version):
    with pytest.raises(BumpError) as e:
        loads(_text(schema_version=version), "x.json")
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("x.json: sidecar schema_version must be 3")
    assert (CHANGES_FROM_1 in msg) == (version == 1 and version is not True)
    assert (CHANGES_FROM_2 in msg) == (version in (1, 2) and version is not True)


def test_untyped_version_1_is_refused_saying_what_changed():
    old = {"unit": "sincos", "command": "bumprtl emit sincos", "latency": 5,
           "roms": {"quarter_sine": {"depth": 65, "width": 9, "bits": 585}},
           "ports": {"i__payload": {"dir": "in", "width": 24,
                                    "fields": {"angle": [0, 8, False], "tag": [8, 16, False]}}}}
    with pytest.raises(BumpError, match=r"^old.json: sidecar schema_version missing: a "
                       r"version-1 \(untyped\) sidecar; this bumprtl reads schema_version 3 "
                       r"only \(version 1 had no schema_version; .*roms became memories"):
        loads(json.dumps(old), "old.json")


@pytest.mark.parametrize("key", ["latency", "ports", "memories", "error_bounds", "command",
                                 "named_ports"])
def test_a_missing_key_is_refused(key):
    with pytest.raises(BumpError, match=rf"^sidecar: sidecar lacks key {key} \(schema_version "
                                        rf"3\)$"):
        loads(_text(**{key: None}))


def test_a_missing_or_unknown_nested_key_is_refused(tmp_path):
    d = json.loads(_text())
    del d["ports"]["i__payload"]["fields"]["angle"]["signed"]
    with pytest.raises(BumpError, match=r"lacks key ports.i__payload.fields.angle.signed"):
        loads(json.dumps(d))
    d = json.loads(_text())
    d["roms"] = {}
    with pytest.raises(BumpError, match=r"key roms is unknown to schema_version 3"):
        loads(json.dumps(d))
    d = json.loads(_text())
    d["memories"]["quarter_sine"]["kind"] = "flash"
    path = tmp_path / "s.json"
    path.write_text(json.dumps(d))
    with pytest.raises(BumpError, match=r"^s.json: sidecar memories.quarter_sine.kind must be "
                                        r"one of rom, ram, got 'flash'$"):
        load(path)


def test_dump_and_load_of_a_file(tmp_path):
    side = build_unit("rotation", SMALL)[1]
    assert load(side.dump(tmp_path / "r.json")) == side
    with pytest.raises(BumpError, match="has no port 'nope'"):
        side.port("nope")
    assert isinstance(side.input_fields["tag"], Field)
    off, width, signed = side.input_fields["tag"]
    assert (off, width, signed) == tuple(side.input_fields["tag"])


def _verilog_slices(text, port):
    """``{field: (lsb, width)}`` from the Verilog's ``assign \\port.field = port[msb:lsb];``
    and the port's declared width from ``input|output [msb:0] port;``."""
    width = int(re.search(rf"^\s*(?:input|output) \[(\d+):0\] {port};", text, re.M)[1]) + 1
    found = {}
    for m in re.finditer(rf"assign \\{port}\.(\S+)\s+= {port}\[(\d+):(\d+)\];", text):
        found[m[1]] = (int(m[3]), int(m[2]) - int(m[3]) + 1)
    return width, found


def test_fields_are_the_verilog_bit_layout(tmp_path):
    v, j = emit_unit("rotation", SMALL, tmp_path)
    side, text = load(j), v.read_text()
    width, slices = _verilog_slices(text, "i__payload")
    assert side.port("i__payload").width == width
    fields = {n: (f.offset, f.width) for n, f in side.input_fields.items()}
    assert fields == {n: s for n, s in slices.items() if n in fields}
    assert set(fields) <= set(slices)
    out_width = int(re.search(r"^\s*output \[(\d+):0\] o__payload;", text, re.M)[1]) + 1
    assert side.port("o__payload").width == out_width
    for name, f in side.output_fields.items():           # each output field's wire width
        w = re.search(rf"wire \[(\d+):0\] \\o__payload\.{re.escape(name)} ;", text)
        assert w and int(w[1]) + 1 == f.width, name


def _corrupt(d, path, value):
    *keys, last = path
    for k in keys:
        d = d[k]
    d[last] = value


@pytest.mark.parametrize("path, value, key, kind", [
    (("ports",), [], "ports", "an object"),
    (("memories",), [1], "memories", "an object"),
    (("ports", "i__payload", "fields"), ["x"], "ports.i__payload.fields", "an object"),
    (("ports", "i__payload", "width"), "28", "ports.i__payload.width", "an integer"),
    (("ports", "o__valid", "width"), True, "ports.o__valid.width", "an integer"),
    (("ports", "i__payload", "fields", "b.phi", "offset"), 1.5,
     "ports.i__payload.fields.b.phi.offset", "an integer"),
    (("ports", "i__payload", "fields", "b.phi", "width"), None,
     "ports.i__payload.fields.b.phi.width", "an integer"),
])
def test_a_container_or_width_of_the_wrong_type_is_refused_by_name(path, value, key, kind):
    # hand-edited or foreign sidecars: one line naming the key, never a bare TypeError
    _, meta, _ = build_unit("rotation", Config())
    d = json.loads(meta.dumps())
    assert d["ports"]["i__payload"]["fields"]["b.phi"]   # the corruptions reach real keys
    _corrupt(d, path, value)
    with pytest.raises(BumpError, match=rf"sidecar key '{re.escape(key)}' must be {kind}"):
        loads(json.dumps(d))


def test_a_memory_of_the_wrong_type_is_refused_by_name():
    _, meta, _ = build_unit("sincos", Config())
    d = json.loads(meta.dumps())
    name = next(iter(d["memories"]))
    d["memories"][name]["depth"] = "1024"
    with pytest.raises(BumpError, match=rf"sidecar key 'memories\.{re.escape(name)}\.depth' must be an integer"):
        loads(json.dumps(d))
