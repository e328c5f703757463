"""No module of rtl/, gen/, sim/ or tests/ reads or writes the JSON sidecar as a raw dict:
every reader goes through rtl/sidecar.py (``load`` and the typed :class:`Sidecar`), the one
module that knows the file's shape, and every writer through :meth:`Sidecar.dump`. Its own
tests (tests/rtl/test_sidecar.py, which edits a sidecar's dict to see ``load`` refuse it) and
this file (its planted offences) are exempt. The mutation harness (tests/mutants) reads the
sidecar through ``load`` too and keeps its own record of a target in a file of another name
and shape (tests/mutants/harness_ports.py).

The check is textual, line by line: a subscript by a sidecar key (``["ports"]``,
``["fields"]``, ``["dir"]``, ``["named_ports"]``, ``["roms"]``, ``["memories"]``, the error
bound keys), a subscript of a variable named ``meta`` or ``sidecar``, ``json.load``/
``json.loads`` on a line that names a sidecar (``sidecar``, ``j_path``/``jpath``/``j``,
``BUMPRTL_SIDECAR`` or a ``{name|module|unit}.json`` path), ``json.dump``/``json.dumps``
written to a ``{name|module|unit}.json`` path, and a dict literal with a ``"unit"`` and a
``"ports"`` key (a sidecar's shape made by hand). ``test_each_offence_is_caught`` plants one
line of each kind in a small tree, under sim/ and under tests/mutants/, and sees each
reported.
"""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
FOLDERS = ("rtl", "gen", "sim", "tests")
# the sidecar's module, its own tests and this file
OWNERS = (Path("rtl") / "sidecar.py", Path("tests") / "rtl" / "test_sidecar.py",
          Path("tests") / "test_sidecar_access.py")

KEYS = ("ports", "fields", "dir", "named_ports", "roms", "memories", "error_bound_lsb",
        "error_bounds_lsb", "error_bound_ulp", "faithful_widths", "schema_version")
PATTERNS = {
    "sidecar key subscript": re.compile(r"""\[\s*["'](?:""" + "|".join(KEYS) + r""")["']\s*\]"""),
    "meta/sidecar subscript": re.compile(r"(?<![.\w])(?:meta|pmeta|sidecar)\s*\["),
    "meta/sidecar .get": re.compile(r"(?<![.\w])(?:meta|pmeta|sidecar)\.get\("),
    "json.load of a sidecar": re.compile(
        r"json\.loads?\(.*(?:sidecar|BUMPRTL_SIDECAR|\bj_?path\b|\(\s*j\s*\)|\bj\.read_text"
        r"|\{(?:name|module|unit)\}\.json)"),
    "json.dump to a sidecar": re.compile(
        r"\{(?:name|module|unit)\}\.json[\"']\)\.write_text\(json\.dumps?\("),
    "sidecar-shaped dict": re.compile(r"""["']unit["']\s*:.*["']ports["']\s*:"""),
}


# Lines that match a pattern but read no sidecar: (file, text in the line) -> what they read.
NOT_SIDECARS = {
    ("gen/flow/emit.py", 'entry["fields"] = layout_fields'): "port_table builds the port facts",
    ("gen/flow/resources.py", 'module["ports"]'): "a Yosys JSON netlist",
    ("gen/flow/units.py", 'found["faithful_widths"]'): "faithful_widths()'s own dict",
    ("sim/formal/contract.py", '["memories"]'): "the formal contract's memory records",
    ("gen/report/timing.py", 'f"{name}.json").write_text(json.dumps(source'):
        "a WaveDrom diagram's source",
    ("tests/gen/flow/test_resources.py", 'netlist = json.loads((tmp_path / f"{name}.json")'):
        "a Yosys JSON netlist",
    ("tests/rtl/test_no_clock_enable.py", 'return json.loads((work / f"{name}.json").read_text())["modules"]'):
        "a Yosys JSON netlist",
    ("tests/gen/report/test_timing.py", 'src = json.loads((tmp_path / f"{name}.json")'):
        "a WaveDrom diagram's source",
    ("tests/gen/report/test_integration.py", 'out["ports"]'):
        "the integration page's blocks (gen/report/integration.py blocks)",
    ("tests/mutants/netlist_cone.py", 'self.ports = mod["ports"]'): "a Yosys JSON module",
    ("tests/mutants/test_netlist_pdr.py", 'for n, p in mod["ports"].items()'):
        "a Yosys JSON module",
    ("tests/mutants/netlist_rel.py", 'mod["ports"] = {k: v for k, v in mod["ports"].items()'):
        "a Yosys JSON module (reach's cone)",
    ("tests/mutants/test_netlist_reach.py", 'json.loads(text)["modules"]["product"]["ports"]'):
        "a Yosys JSON module",
}


def offences(root=ROOT, folders=FOLDERS, allowed=NOT_SIDECARS):
    """``file:line: kind: text`` of every raw-dict access to a sidecar outside OWNERS (but the
    lines of ``allowed``)."""
    bad = []
    for folder in folders:
        for path in sorted((root / folder).rglob("*.py")):
            rel = path.relative_to(root)
            if rel in OWNERS:
                continue
            for n, line in enumerate(path.read_text().splitlines(), 1):
                if any(f == rel.as_posix() and t in line for f, t in allowed):
                    continue
                for kind, pattern in PATTERNS.items():
                    if pattern.search(line):
                        bad.append(f"{rel}:{n}: {kind}: {line.strip()}")
    return bad


def test_no_raw_sidecar_access():
    bad = offences()
    assert not bad, ("read the sidecar through bumprtl.rtl.sidecar (load, Sidecar's attributes "
                     "and accessors), not as a dict:\n  " + "\n  ".join(bad))


def test_the_checked_tree_has_the_readers():
    """The check looks where the readers are (a moved folder would pass it vacuously)."""
    files = {p.relative_to(ROOT).as_posix() for f in FOLDERS for p in (ROOT / f).rglob("*.py")}
    assert {"sim/tb/stream.py", "gen/flow/named.py", "gen/report/integration.py",
            "rtl/sidecar.py", "tests/mutants/netlist.py", "tests/mutants/netlist_board.py",
            "tests/mutants/harness_ports.py"} <= files


PLANTED = {
    "sidecar key subscript": 'fields = meta.x["ports"]["i__payload"]',
    "meta/sidecar subscript": "latency = meta['latency']",
    "meta/sidecar .get": 'images = sidecar.get("memory_images", {})',
    "json.load of a sidecar": 'meta = json.loads((out / f"{name}.json").read_text())',
    "json.dump to a sidecar": '(out / f"{unit}.json").write_text(json.dumps(record, indent=1))',
    "sidecar-shaped dict": 'record = {"unit": unit, "ports": {"clk": {"width": 1}}}',
}
# a port's direction by its key: the mutation harness read a sidecar's ports this way
PLANTED_DIR = "ins = [n for n, p in ports.items() if p['dir'] == 'in']"


@pytest.mark.parametrize("where", ["sim/reader.py", "tests/mutants/reader.py"])
@pytest.mark.parametrize("kind, line", [*PLANTED.items(),
                                        ("sidecar key subscript", PLANTED_DIR)])
def test_each_offence_is_caught(tmp_path, where, kind, line):
    for path in (where, *OWNERS):       # the owners may
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text(f"def f(meta, out, name, unit, ports, record):\n    {line}\n")
    found = offences(tmp_path, ("rtl", "sim", "tests"))
    assert [f.split(": ")[:2] for f in found] == [[f"{where}:2", kind]]


def test_the_allowed_lines_are_still_there():
    """Each allowed line exists (a stale entry would hide a new offence on a changed line)."""
    for (path, text), why in NOT_SIDECARS.items():
        assert text in (ROOT / path).read_text(), (path, text, why)
