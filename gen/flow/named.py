"""``bumprtl emit UNIT --ports named``: a thin Verilog wrapper with one named port per payload
field, generated from the sidecar's field table (a :class:`~bumprtl.rtl.sidecar.Sidecar`).

The emitted unit carries each stream's fields packed into one vector (``i__payload``,
``o__payload``; their bit positions are in the sidecar's ``ports``). The wrapper
``<module>_named`` (file ``<module>_named.v``) instantiates ``<module>`` and gives every
field its own port: ``in_<field>`` and ``out_<field>`` (a field path ``n.phi`` becomes
``in_n_phi``), ``in_valid``/``in_ready``/``out_valid``/``out_ready`` for the handshake, and
every other port of the unit (``clk``, ``rst``, the host write ports) under its own name.
It holds no logic: wires only, so latency, throughput and reset are the unit's. It passes
the project's Verilator lint (gen/flow/emit.py ``lint``) with the unit's file beside it.
"""

import re
from pathlib import Path

from bumprtl.rtl.config import BumpError
from bumprtl.rtl.sidecar import Field, NamedPort, NamedPorts

__all__ = ["named_ports", "named_wrapper", "write_named", "named_module", "with_named"]

_STREAMS = {"i": ("in", "i__payload", "i__valid", "i__ready"),
            "o": ("out", "o__payload", "o__valid", "o__ready")}


def named_module(module):
    return f"{module}_named"


def _ident(path):
    return re.sub(r"[^A-Za-z0-9_]", "_", path)


def named_ports(meta):
    """``{port: NamedPort}`` of the wrapper of the unit with sidecar ``meta`` (a
    :class:`~bumprtl.rtl.sidecar.Sidecar`), in port order: ``source`` is the unit's port,
    ``bits`` ``(lsb, msb)`` within it (None: the whole port)."""
    ports = meta.ports
    if "i__payload" not in ports or "o__payload" not in ports:
        raise BumpError("ports = named needs a unit with i__payload and o__payload (the stream "
                        "interface), not --interface axis")
    out = {n: NamedPort(ports[n].dir, ports[n].width, False, n) for n in ("clk", "rst")
           if n in ports}
    stream_ports = set(out)
    for _side, (prefix, payload, valid, ready) in _STREAMS.items():
        stream_ports |= {payload, valid, ready}
        pdir = ports[payload].dir
        out[f"{prefix}_valid"] = NamedPort(pdir, 1, False, valid)
        out[f"{prefix}_ready"] = NamedPort("out" if pdir == "in" else "in", 1, False, ready)
        fields = meta.fields_of(payload) or {"data": Field(0, ports[payload].width, False)}
        for path, (off, width, signed) in sorted(fields.items(), key=lambda kv: kv[1].offset):
            name = f"{prefix}_{_ident(path)}"
            if name in out:
                raise BumpError(f"ports = named: two fields of {payload} map to port {name}")
            out[name] = NamedPort(pdir, width, bool(signed), payload, (off, off + width - 1), path)
    for name, p in sorted(ports.items()):
        if name in stream_ports:
            continue
        if name in out:
            raise BumpError(f"ports = named: the unit's port {name} clashes with a field port")
        out[name] = NamedPort(p.dir, p.width, False, name)
    return out


def with_named(meta, module, command):
    """``meta`` with its ``named_ports`` record: the wrapper ``module`` written by
    ``command``."""
    return meta.replace(named_ports=NamedPorts(module, command, named_ports(meta)))


def _vec(width, signed=False):
    return ("signed " if signed else "") + (f"[{width - 1}:0] " if width > 1 else "")


def named_wrapper(meta, module, command):
    """Verilog text of ``<module>_named`` around ``module`` (sidecar ``meta``)."""
    ports = named_ports(meta)
    wrapper = named_module(module)
    decl = ",\n".join(f"  {'input' if p.dir == 'in' else 'output'} wire "
                      f"{_vec(p.width, p.signed)}{n}" for n, p in ports.items())
    body, conns = [], []
    for payload in ("i__payload", "o__payload"):
        width = meta.port(payload).width
        fields = sorted((p.bits[0], p.bits[1], n) for n, p in ports.items()
                        if p.source == payload and p.bits is not None)
        covered = sum(hi - lo + 1 for lo, hi, _ in fields)
        unused = payload == "o__payload" and covered < width
        if unused:
            body.append("  /* verilator lint_off UNUSEDSIGNAL */")
        body.append(f"  wire {_vec(width)}{payload};")
        if unused:
            body.append("  /* verilator lint_on UNUSEDSIGNAL */")
        if payload == "i__payload":            # fields (and zeros in any gap), MSB first
            parts, pos = [], 0
            for lo, hi, n in fields:
                if lo > pos:
                    parts.append(f"{lo - pos}'d0")
                parts.append(n)
                pos = hi + 1
            if pos < width:
                parts.append(f"{width - pos}'d0")
            body.append(f"  assign i__payload = {{{', '.join(reversed(parts))}}};")
        else:
            body += [f"  assign {n} = o__payload[{hi}:{lo}];" for lo, hi, n in fields]
        conns.append(f"    .{payload}({payload})")
    for n, p in ports.items():
        if p.bits is None:
            conns.append(f"    .{p.source}({n})")
    return (f"// Generated by: {command}\n"
            f"// Do not edit: regenerate with the command above.\n"
            f"// Named ports around `{module}`: one port per payload field of {module}.json,\n"
            f"// wires only (latency, throughput, reset and handshake are {module}'s).\n"
            f"module {wrapper} (\n{decl}\n);\n" + "\n".join(body) + "\n"
            f"  {module} u_{module} (\n" + ",\n".join(conns) + "\n  );\nendmodule\n")


def write_named(v_path, meta, command):
    """Write ``<module>_named.v`` beside the unit ``v_path``; returns its path."""
    v_path = Path(v_path)
    module = v_path.stem
    path = v_path.with_name(f"{named_module(module)}.v")
    path.write_text(named_wrapper(meta, module, command))
    return path
