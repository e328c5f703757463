"""A broken copy of an emitted design for the benches' own tests: the same top module, ports
and file name, one bit of one output port inverted. A bench that passes on it checks
nothing."""

import re
from pathlib import Path

_DECL = re.compile(r"^\s*(input|output)\s+(\[\d+:\d+\]\s+)?(\\?[^\s;]+)\s*;", re.M)


def flip_output_bit(v_path, dest_dir, port="o__payload", bit=0):
    """Write ``dest_dir/<same name>.v``: the design's top renamed ``<top>__ok`` and a new
    top of the old name around it whose ``port`` has ``bit`` inverted. Returns its path."""
    v_path, dest_dir = Path(v_path), Path(dest_dir)
    top, text = v_path.stem, Path(v_path).read_text()
    header = re.search(rf"^module {re.escape(top)}\((.*?)\);", text, re.M | re.S)
    names = [p.strip() for p in header.group(1).split(",")]
    body = text[header.end():text.index("endmodule", header.end())]
    decls = {m.group(3): (m.group(1), (m.group(2) or "").strip()) for m in _DECL.finditer(body)}
    assert set(names) <= set(decls) and decls[port][0] == "output", (names, port)
    ok = next(f"{top}__ok{n or ''}" for n in range(100) if f"module {top}__ok{n or ''}(" not in text)
    inner = text[:header.start()] + f"module {ok}(" + text[header.start() + len(f"module {top}("):]
    lines = [f"module {top}({', '.join(names)});"]
    for n in names:
        kind, width = decls[n]
        lines.append(f"  {kind} {width + ' ' if width else ''}{n};")
    lines.append(f"  wire {decls[port][1] + ' ' if decls[port][1] else ''}{port}__ok;")
    conns = ", ".join(f".{n}({port}__ok)" if n == port else f".{n}({n})" for n in names)
    lines.append(f"  {ok} ok ({conns});")
    lines.append(f"  assign {port} = {port}__ok ^ ({len_of(decls[port][1])}'d1 << {bit});")
    lines.append("endmodule")
    dest_dir.mkdir(parents=True, exist_ok=True)
    out = dest_dir / v_path.name
    out.write_text(inner + "\n" + "\n".join(lines) + "\n")
    return out


def len_of(width):
    """Bits of a Verilog range ``[hi:lo]`` ('' is one bit)."""
    if not width:
        return 1
    hi, lo = map(int, width.strip("[]").split(":"))
    return abs(hi - lo) + 1
