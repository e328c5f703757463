"""``bumprtl report integration``: the generated parts of docs/integration.md, the page an HDL
user reads, from the sidecar of the pipeline ``bumprtl emit`` writes.

The scene's pipeline is emitted by ``bumprtl emit pipeline --load port --name my_bump --ports
named`` itself (in process, into ``--out``), and from its sidecar (``built`` units, ``memories``,
``ports`` with their payload fields, ``named_ports``, ``memory_images``, ``latency``,
``command``) and the golden model this writes, between the ``<!-- generated: NAME -->`` and
``<!-- end: NAME -->`` markers of the page:

``made-at``   the configuration and the command (``Made at: angle_bits=..., frac_bits=...``);
``diagram``   a Mermaid block diagram: the built units in order with their latencies and
              memories, the host write ports, the credit edge;
``ports``     the port table: every port of the named wrapper with its bits in the packed
              payload, its format and meaning;
``timing``    latency, throughput and the memory images;
``example``   one pixel worked through: physical angles -> codes -> the outputs, as Python
              that runs the golden model and asserts the numbers (the doc test runs it), and
              the packed payload words;
``verilog``   an instantiation template of the named wrapper;
``load``      a testbench fragment that ``$readmemh``-reads each memory image and writes it
              through the host port.
``sidecar``   the sidecar's schema (rtl/sidecar.py ``SCHEMA``), its version, what changed
              from version 1, and this design's facts from it.

The prose between the blocks is hand-written; a run rewrites only the blocks.
"""

import contextlib
import io
import re
from pathlib import Path

import numpy as np

from bumprtl.gen.cli.main import main
from bumprtl.gen.flow.memories import DEFAULT_DEVICE
from bumprtl.gen.flow.named import named_ports
from bumprtl.gen.render.rtl import scene_memories
from bumprtl.gen.tools import docs
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.sidecar import CHANGES_FROM_1, CHANGES_FROM_2, SCHEMA, SCHEMA_VERSION
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.golden.common import cartesian_to_polar, polar_to_cartesian
from bumprtl.sim.golden.fixed.common import angle_codes
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
from bumprtl.sim.scenes.config import load_scene_config

__all__ = ["emit_for_integration", "blocks", "write_doc", "made_at", "integration_report", "NAME",
           "example_pixel", "pack_payload"]

DOC = Path("docs/integration.md")
COMMAND = "bumprtl report integration"
NAME = "my_bump"              # the --name the page's examples use

# field path (regular expression) -> meaning; the first match wins.
_MEANINGS = (
    (r"u|v", "texel coordinate of mip level 0 (two's complement; wrapped or clamped by the "
             "scene's addressing)"),
    (r"level", "mip level (values past the last level read the last level)"),
    (r"n\.phi|n\.theta", "world surface normal N as binary angles (phi azimuth, theta polar "
                         "angle; full circle = 2^angle_bits)"),
    (r"(extra_lights\.\d+\.)?l\.(phi|theta)", "light vector L as binary angles"),
    (r"(extra_lights\.\d+\.)?h\.(phi|theta)", "halfway vector H = normalize(L + V) as binary "
                                              "angles (specular only)"),
    (r"b\.(phi|theta)", "tangent-space bump normal N' as binary angles"),
    (r"tag", "side-band tag: passed through unchanged, in order (e.g. the pixel address)"),
    (r"diffuse", "round(255 clamp(N'.L', 0, 1)), 0..255"),
    (r"specular", "round(255 (N'.H')^n), 0..255 (n = spec_exponent)"),
    (r"color(\.\w)?", "Phong sum (eq. 2) min(255, round(255 ka + kd 255 clamp(N'.L', 0, 1) + "
                      "ks 255 (N'.H')^n)) of the unrounded terms, 0..255 (with a texture: the "
                      "blended channel)"),
    (r"diffuse_fine", "unrounded clamp(N'.L', 0, 1), frac_bits fractional bits (for the "
                      "light sum and texture blend)"),
    (r"specular_fine", "unrounded 255 (N'.H')^n with 9 fractional bits (rtl/tables.py "
                       "SPEC_FRAC_BITS)"),
    (r"index", "palette index"),
    (r"oor", "palette index out of range (the colour reads as 0)"),
)
_PORTS = {
    "clk": "clock; everything is synchronous to its rising edge",
    "rst": "synchronous reset, active high (Amaranth's sync domain)",
    "in_valid": "the producer offers a pixel (stream handshake)",
    "in_ready": "the pipeline takes the offered pixel at this edge when in_valid is high",
    "out_valid": "a shaded pixel is on the out_* ports",
    "out_ready": "the consumer takes it at this edge when out_valid is high",
    "map_w_en": "host write port of the bump map: write map_w_data at map_w_addr this edge",
    "map_w_addr": "host write port: word address (see the memory image's layout)",
    "map_w_data": "host write port: the word",
    "tex_w_en": "host write port of the colour texture: write enable",
    "tex_w_addr": "colour texture word address",
    "tex_w_data": "colour texture word (r [7:0], g [15:8], b [23:16])",
    "poly_en": "flat map: load the polygon registers from poly this edge",
    "poly": "flat map: the polygon's rotated normal terms",
    "lut_w_en": "palette colour table write (held until lut_w_ready)",
    "lut_w_addr": "palette colour table address",
    "lut_w_data": "palette colour table entry",
    "lut_w_ready": "the colour table takes the write this edge",
    "lut_swap": "swap the colour table's banks (a new frame)",
    "lut_bank": "the bank in front",
}


def _meaning(port, p):
    if port in _PORTS:
        return _PORTS[port]
    field = p.field or ""
    for pattern, text in _MEANINGS:
        if re.fullmatch(pattern, field):
            return text
    return "see rtl/layouts.py"


def emit_for_integration(scene, out_dir, name=NAME, flags=()):
    """Emit ``scene``'s pipeline with ``bumprtl emit pipeline --scene SCENE [FLAGS] --load port
    --name NAME --ports named --out OUT_DIR`` (the command itself, in process; ``scene`` a
    name or a TOML path, ``flags`` further ``bumprtl emit`` flags); returns its sidecar."""
    argv = ["emit", "pipeline", "--scene", str(scene), *flags, "--load", "port", "--name", name,
            "--ports", "named", "--out", str(out_dir)]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        if main(argv) != 0:
            raise BumpError(f"bumprtl {' '.join(argv)} failed")
    return load_sidecar(Path(out_dir) / f"{name}.json")


def made_at(meta):
    """The page's record (gen/tools/docs.made_at) of the sidecar's Config."""
    cfg = Config(**meta.config)
    return docs.made_at(cfg, f"scene `{meta.scene['name']}`, method {cfg.method}; `{COMMAND}`, "
                       f"from `{meta.command}`")


def _unit_memories(meta, unit):
    roms = {k.split(".", 1)[1]: v for k, v in meta.memories.items() if k.split(".")[0] == unit}
    if not roms:
        return ""
    groups = {}
    for name, r in roms.items():
        key = (re.sub(r"\d+$", "", name), r.depth, r.width)
        groups[key] = groups.get(key, 0) + 1
    return "<br/>" + "<br/>".join(f"{n} x {base} {d} x {w}" if n > 1 else f"{base} {d} x {w}"
                                  for (base, d, w), n in sorted(groups.items()))


def diagram(meta):
    """Mermaid flowchart: input stream -> credits -> built units -> FIFO -> output stream."""
    fin = ", ".join(sorted({f.split(".")[0] for f in meta.input_fields}))
    fout = ", ".join(sorted({f.split(".")[0] for f in meta.output_fields}))
    lines = ["```mermaid", "flowchart LR",
             f'  IN(["in: {fin}<br/>valid / ready"])',
             f'  CR{{"credits<br/>{meta.fifo_depth}"}}', "  IN --> CR"]
    prev = "CR"
    for i, b in enumerate(meta.built):
        node = f"U{i}"
        lines.append(f'  {node}["{b["unit"]}: {b["class"]}<br/>latency {b["latency"]}'
                     f'{_unit_memories(meta, b["unit"])}"]')
        lines.append(f"  {prev} --> {node}")
        prev = node
    lines += [f'  BUF["FIFO<br/>{meta.fifo_depth} entries"]', f"  {prev} --> BUF",
              "  BUF -. credit back .-> CR",
              f'  OUT(["out: {fout}<br/>valid / ready"])', "  BUF --> OUT"]
    for img in (meta.memory_images or {}).values():
        host = img["port"][0].rsplit("_w_en", 1)[0]
        target = next((f"U{i}" for i, b in enumerate(meta.built)
                       if b["unit"] == ("fetch" if host in ("map", "tex") else "palette")), None)
        if target:
            lines += [f'  H_{host}[/"host: {", ".join(img["port"])}"/]',
                      f"  H_{host} -.-> {target}"]
    lines.append("```")
    return "\n".join(lines)


def _ordered_ports(meta):
    """The named wrapper's ports in its port order (the sidecar's JSON keeps them sorted)."""
    return {n: meta.named_ports.ports[n] for n in named_ports(meta)}


def port_table(meta):
    ports = _ordered_ports(meta)
    rows = ["| Port | Dir | Width | Packed bits | Format | Meaning |", "|---|---|---|---|---|---|"]
    for name, p in ports.items():
        bits = (f"`{p.source}[{p.bits[1]}:{p.bits[0]}]`" if p.bits is not None
                else f"`{p.source}`")
        fmt = ("signed" if p.signed else "unsigned") if p.width > 1 else "bit"
        rows.append(f"| `{name}` | {p.dir} | {p.width} | {bits} | {fmt} | "
                    f"{_meaning(name, p)} |")
    return "\n".join(rows)


def timing(meta):
    lat = " + ".join(f"{b['unit']} {b['latency']}" for b in meta.built)
    block_ram = meta.block_ram or {}
    out = [f"* Latency: **{meta.latency} cycles**: a pixel taken at rising edge t (in_valid "
           f"and in_ready high) leaves at edge t + {meta.latency} (out_valid is high in the "
           f"cycle before it) when out_ready is held high; {lat}.",
           f"* Throughput: {meta.throughput} pixel per clock while out_ready is high.",
           f"* Block RAM ({block_ram.get('device', DEFAULT_DEVICE)}): "
           f"{block_ram.get('dp16kd_needed', '?')} DP16KD of "
           f"{block_ram.get('dp16kd_available', '?')}."]
    for name, img in (meta.memory_images or {}).items():
        out.append(f"* Memory image `{img['file']}` ({name}): {img['depth']} words of "
                   f"{img['width']} bits, through `{'`, `'.join(img['port'])}`; {img['layout']}.")
    return "\n".join(out)


# The worked example: one pixel of the scene, physical angles in degrees (phi, theta).
EXAMPLE = {"u": 5, "v": 3, "n": (-30, 20), "l": (60, 45), "view": (0, 0)}


def example_pixel(scene):
    """``(codes, outputs)`` of :data:`EXAMPLE` through ``scene``'s golden pipeline: the input
    payload fields as the encoder rounds them (H = normalize(L + V)), the tag the texel's
    word address, and the output fields (:func:`~bumprtl.sim.golden.fixed.pipeline.pipeline_fixed`
    with the scene's own map)."""
    scene = load_scene_config(scene)
    cfg, e, deg = scene.config, EXAMPLE, np.pi / 180
    angles = {"n": [a * deg for a in e["n"]], "l": [a * deg for a in e["l"]]}
    view = polar_to_cartesian(*[a * deg for a in e["view"]])
    angles["h"] = cartesian_to_polar(polar_to_cartesian(*angles["l"]) + view)
    codes = {"u": e["u"], "v": e["v"], "tag": e["v"] * scene.texture_size + e["u"]}
    for vec, (phi, theta) in angles.items():
        codes[f"{vec}.phi"] = int(angle_codes(phi, cfg))
        codes[f"{vec}.theta"] = int(angle_codes(theta, cfg))
    words = scene_memories(scene)[0]
    out = pipeline_fixed({k: np.array([c]) for k, c in codes.items()}, scene, words)
    return codes, {k: int(v[0]) for k, v in out.items()} | {"tag": codes["tag"]}


def pack_payload(fields, values):
    """A packed payload word from ``{field: value}`` and the sidecar's ``{field: [offset,
    width, signed]}`` (two's complement within its width)."""
    word = 0
    for name, (off, width, _) in fields.items():
        word |= (int(values[name]) & ((1 << width) - 1)) << off
    return word


def example(meta):
    """The worked example as Python that recomputes it with the golden model and asserts
    every number, then the packed payload words of the same pixel."""
    e, module = EXAMPLE, meta.module
    scene = load_scene_config(meta.scene)
    named = load_scene_config(scene.name).to_dict()
    over = {k: v for k, v in scene.to_dict().items() if named.get(k) != v}
    source = f'"{scene.name}"' + (f", {over!r}" if over else "")
    codes, out = example_pixel(scene)
    fin, fout = meta.input_fields, meta.output_fields
    missing = (set(fin) - set(codes)) | (set(fout) - set(out))
    if missing:
        raise BumpError(f"the worked example has no value for {', '.join(sorted(missing))}")
    wi, wo = meta.port("i__payload").width, meta.port("o__payload").width
    code = f'''```python
import numpy as np

from bumprtl.gen.render.rtl import scene_memories
from bumprtl.sim.golden.common import cartesian_to_polar, polar_to_cartesian
from bumprtl.sim.golden.fixed.common import angle_codes
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
from bumprtl.sim.scenes.config import load_scene_config

scene = load_scene_config({source})        # the scene {module} was emitted from
cfg = scene.config
deg = np.pi / 180
n = ({e["n"][0]} * deg, {e["n"][1]} * deg)   # world normal N: (phi, theta)
l = ({e["l"][0]} * deg, {e["l"][1]} * deg)   # light L
view = polar_to_cartesian({e["view"][0]} * deg, {e["view"][1]} * deg)   # viewer V
h = cartesian_to_polar(polar_to_cartesian(*l) + view)   # H = normalize(L + V)
codes = {{"u": {e["u"]}, "v": {e["v"]}, "tag": {codes["tag"]}}}   # tag: the texel's word address
for vec, (phi, theta) in {{"n": n, "l": l, "h": h}}.items():
    codes[f"{{vec}}.phi"] = int(angle_codes(phi, cfg))       # round, wrap mod 2^angle_bits
    codes[f"{{vec}}.theta"] = int(angle_codes(theta, cfg))
assert codes == {codes!r}

words = scene_memories(scene)[0]                  # the words of {module}_map.hex
out = pipeline_fixed({{k: np.array([c]) for k, c in codes.items()}}, scene, words)
out = {{k: int(x[0]) for k, x in out.items()}} | {{"tag": codes["tag"]}}
assert out == {out!r}
```'''
    return (f"{code}\n\nPacked: `i__payload` = {wi}'h{pack_payload(fin, codes):x}, "
            f"`o__payload` = {wo}'h{pack_payload(fout, out):x} (the fields at the bit positions "
            f"of the port table).")


def verilog_template(meta):
    ports = _ordered_ports(meta)
    wrapper = meta.named_ports.module
    conns = ",\n".join(f"    .{n:<14}({'' if n in ('clk', 'rst') else 'my_'}{n})" for n in ports)
    return f"```verilog\n{wrapper} u_bump (\n{conns}\n);\n```"


def load_template(meta):
    """A Verilog testbench fragment that loads each ``load = port`` image through its port."""
    ports = _ordered_ports(meta)
    out = ["```verilog"]
    for name, img in (meta.memory_images or {}).items():
        if img["load"] != "port" or name == "lut":
            continue
        en, addr, data = img["port"][:3]
        out += [f"reg [{ports[data].width - 1}:0] {name}_words [0:{img['depth'] - 1}];",
                f'initial $readmemh("{img["file"]}", {name}_words);', "integer a;",
                "initial begin",
                f"  {en} = 1'b0;",
                "  @(negedge rst);                      // after reset, before the first pixel",
                f"  for (a = 0; a < {img['depth']}; a = a + 1) begin",
                f"    @(posedge clk) {en} <= 1'b1; {addr} <= a; {data} <= {name}_words[a];",
                "  end",
                f"  @(posedge clk) {en} <= 1'b0;",
                "end"]
    out.append("```")
    return "\n".join(out)


def sidecar_schema(meta):
    """The sidecar's schema table (rtl/sidecar.py ``SCHEMA``), its version, what changed from
    the untyped version 1 and from version 2, and the facts of this design's sidecar."""
    rows = ["| Key | JSON type | Meaning |", "|---|---|---|"]
    rows += [f"| `{k}` | {t} | {m} |" for k, (t, m) in SCHEMA.items()]
    fin, fout = meta.input_fields, meta.output_fields
    return "\n".join([
        f"`{meta.module}.json` has `schema_version` **{meta.schema_version}** "
        f"(`bumprtl.rtl.sidecar.SCHEMA_VERSION` = {SCHEMA_VERSION}). Every key is written in "
        f"every sidecar (`null` where it does not apply); `bumprtl.rtl.sidecar.load` refuses a "
        f"file of another version, with a missing or an unknown key, in one line naming the key "
        f"and the version it reads.", "", *rows, "",
        f"Changed from version 1 (the untyped sidecar of bumprtl 0.2 and before): "
        f"{CHANGES_FROM_1}. Changed from version 2: {CHANGES_FROM_2}.", "",
        f"This design's sidecar: latency {meta.latency}, FIFO depth {meta.fifo_depth}, ROMs {len(meta.roms)}, RAMs "
        f"{len(meta.rams)}, `i__payload` {meta.port('i__payload').width} bits in "
        f"{len(fin)} fields, `o__payload` {meta.port('o__payload').width} bits in {len(fout)} "
        f"fields, {len(meta.named_ports.ports)} named ports."])


def blocks(meta):
    return {"made-at": made_at(meta), "diagram": diagram(meta), "ports": port_table(meta),
            "timing": timing(meta), "example": example(meta), "verilog": verilog_template(meta),
            "load": load_template(meta), "sidecar": sidecar_schema(meta)}


def write_doc(doc, generated):
    """Replace every ``<!-- generated: NAME -->`` ... ``<!-- end: NAME -->`` block of ``doc``;
    a block the page lacks is an error naming it."""
    doc = Path(doc)
    text = doc.read_text()
    for name, body in generated.items():
        pattern = re.compile(rf"(<!-- generated: {re.escape(name)} -->\n).*?(<!-- end: "
                             rf"{re.escape(name)} -->)", re.S)
        if not pattern.search(text):
            raise BumpError(f"doc {doc} has no '<!-- generated: {name} -->' block")
        text = pattern.sub(lambda m, body=body: m.group(1) + body + "\n" + m.group(2), text)
    doc.write_text(text)
    return doc


def integration_report(scene="default", out=Path("build/integration"), doc=DOC, name=NAME):
    """``bumprtl report integration``: emits ``scene``'s pipeline under ``out`` (port
    prefix ``name``) and writes the generated blocks of ``doc``; returns 0."""
    meta = emit_for_integration(scene, out, name)
    path = write_doc(doc, blocks(meta))
    print(f"wrote {path} ({made_at(meta)})")
    return 0
