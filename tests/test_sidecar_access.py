"""No module of rtl/, gen/ or sim/ reads the JSON sidecar as a raw dict: every reader goes
through rtl/sidecar.py (``load`` and the typed :class:`Sidecar`), the one module that knows
the file's shape.

The check is textual, line by line: a subscript by a sidecar key (``["ports"]``,
``["fields"]``, ``["named_ports"]``, ``["roms"]``, ``["memories"]``, the error bound keys),
a subscript of a variable named ``meta`` or ``sidecar``, and ``json.load``/``json.loads`` on
a line that names a sidecar (``sidecar``, ``j_path``/``jpath``/``j``, ``BUMPRTL_SIDECAR`` or
a ``{name|module|unit}.json`` path). ``test_each_offence_is_caught`` plants one line of each
kind in a small tree and sees each reported.
"""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
FOLDERS = ("rtl", "gen", "sim")
OWNER = Path("rtl") / "sidecar.py"

KEYS = ("ports", "fields", "named_ports", "roms", "memories", "error_bound_lsb",
        "error_bounds_lsb", "error_bound_ulp", "faithful_widths", "schema_version")
PATTERNS = {
    "sidecar key subscript": re.compile(r"""\[\s*["'](?:""" + "|".join(KEYS) + r""")["']\s*\]"""),
    "meta/sidecar subscript": re.compile(r"(?<![.\w])(?:meta|pmeta|sidecar)\s*\["),
    "meta/sidecar .get": re.compile(r"(?<![.\w])(?:meta|pmeta|sidecar)\.get\("),
    "json.load of a sidecar": re.compile(
        r"json\.loads?\(.*(?:sidecar|BUMPRTL_SIDECAR|\bj_?path\b|\(\s*j\s*\)|\bj\.read_text"
        r"|\{(?:name|module|unit)\}\.json)"),
}


# Lines that match a pattern but read no sidecar: (file, text in the line) -> what they read.
NOT_SIDECARS = {
    ("gen/flow/emit.py", 'entry["fields"] = layout_fields'): "port_table builds the port facts",
    ("gen/flow/resources.py", 'module["ports"]'): "a Yosys JSON netlist",
    ("gen/flow/units.py", 'found["faithful_widths"]'): "faithful_widths()'s own dict",
    ("sim/formal/contract.py", '["memories"]'): "the formal contract's memory records",
}


def offences(root=ROOT, folders=FOLDERS, allowed=NOT_SIDECARS):
    """``file:line: kind: text`` of every raw-dict access to a sidecar outside rtl/sidecar.py
    (but the lines of ``allowed``)."""
    bad = []
    for folder in folders:
        for path in sorted((root / folder).rglob("*.py")):
            rel = path.relative_to(root)
            if rel == OWNER:
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
            "rtl/sidecar.py"} <= files


PLANTED = {
    "sidecar key subscript": 'fields = meta.x["ports"]["i__payload"]',
    "meta/sidecar subscript": "latency = meta['latency']",
    "meta/sidecar .get": 'images = sidecar.get("memory_images", {})',
    "json.load of a sidecar": 'meta = json.loads((out / f"{name}.json").read_text())',
}


@pytest.mark.parametrize("kind", list(PLANTED))
def test_each_offence_is_caught(tmp_path, kind):
    (tmp_path / "sim").mkdir()
    (tmp_path / "sim" / "reader.py").write_text(f"def f(meta, out, name):\n    {PLANTED[kind]}\n")
    (tmp_path / "rtl").mkdir()
    (tmp_path / "rtl" / "sidecar.py").write_text(f"x = 1\n{PLANTED[kind]}\n")  # the owner may
    found = offences(tmp_path, ("rtl", "sim"))
    assert [f.split(": ")[:2] for f in found] == [["sim/reader.py:2", kind]]


def test_the_allowed_lines_are_still_there():
    """Each allowed line exists (a stale entry would hide a new offence on a changed line)."""
    for (path, text), why in NOT_SIDECARS.items():
        assert text in (ROOT / path).read_text(), (path, text, why)
