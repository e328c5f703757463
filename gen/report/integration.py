"""``bumprtl report integration``: the generated parts of docs/integration.md, the page an HDL
user reads, from the sidecar of the pipeline ``bumprtl emit`` writes.

The scene's pipeline is emitted as ``bumprtl emit pipeline --load port --ports named`` does
(into ``--out``), and from its sidecar (``built`` units, ``roms``, ``ports`` with their
payload fields, ``named_ports``, ``memory_images``, ``latency``) this writes, between the
``<!-- generated: NAME -->`` and ``<!-- end: NAME -->`` markers of the page:

``made-at``   the configuration and the command (``Made at: angle_bits=..., frac_bits=...``);
``diagram``   a Mermaid block diagram: the built units in order with their latencies and
              memories, the host write ports, the output buffer;
``ports``     the port table: every port of the named wrapper with its bits in the packed
              payload, its format and meaning;
``timing``    latency, throughput and the memory images;
``verilog``   an instantiation template of the named wrapper;
``load``      a testbench fragment that ``$readmemh``-reads each memory image and writes it
              through the host port.

The prose between the blocks is hand-written; a run rewrites only the blocks.
"""

import json
import re
from pathlib import Path

from bumprtl.gen.flow.memories import DEFAULT_DEVICE, emit_scene_unit, memory_images, scene_command
from bumprtl.gen.flow.named import named_module, named_ports, write_named
from bumprtl.gen.flow.units import default_module
from bumprtl.gen.render.rtl import scene_memories
from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.scenes.config import load_scene_config

__all__ = ["emit_for_integration", "blocks", "write_doc", "made_at", "add_parser"]

DOC = Path("docs/integration.md")
COMMAND = "bumprtl report integration"

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
    (r"diffuse", "diffuse intensity, 0..255 (ka + kd * max(N'.L', 0))"),
    (r"specular", "specular intensity, 0..255 (ks * (N'.H')^n)"),
    (r"color(\.\w)?", "Phong sum diffuse + specular, 0..255 (with a texture: the blended "
                      "channel)"),
    (r"diffuse_fine", "unrounded clamp(N'.L', 0, 1), frac_bits fractional bits (for the "
                      "light sum and texture blend)"),
    (r"specular_fine", "unrounded 255 (N'.H')^n with fractional bits"),
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
    field = p.get("field", "")
    for pattern, text in _MEANINGS:
        if re.fullmatch(pattern, field):
            return text
    return "see rtl/layouts.py"


def emit_for_integration(scene, out_dir, device=DEFAULT_DEVICE):
    """Emit ``scene``'s pipeline as ``bumprtl emit pipeline --load port --ports named`` does
    (top module ``bumprtl_pipeline``); returns its sidecar with ``named_ports``."""
    scene = load_scene_config(scene)
    module = default_module("pipeline")
    words, texels, table = scene_memories(scene)
    images = memory_images("pipeline", scene, words, texels, table, "port")
    v, j, _ = emit_scene_unit("pipeline", scene, out_dir, images, device,
                              scene_command("pipeline", scene, "port", module), module=module)
    meta = json.loads(j.read_text())
    command = meta["command"] + " --ports named"
    write_named(v, meta, command)
    meta["named_ports"] = {"module": named_module(module), "command": command,
                           "ports": named_ports(meta)}
    j.write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")
    return meta


def made_at(meta):
    """The page's record (rtl.config.Config.made_at) of the sidecar's Config."""
    cfg = Config(**meta["config"])
    return cfg.made_at(f"scene `{meta['scene']['name']}`, method {cfg.method}; `{COMMAND}`, "
                       f"from `{meta['named_ports']['command']}`")


def _unit_memories(meta, unit):
    roms = {k.split(".", 1)[1]: v for k, v in meta["roms"].items() if k.split(".")[0] == unit}
    if not roms:
        return ""
    groups = {}
    for name, r in roms.items():
        key = (re.sub(r"\d+$", "", name), r["depth"], r["width"])
        groups[key] = groups.get(key, 0) + 1
    return "<br/>" + "<br/>".join(f"{n} x {base} {d} x {w}" if n > 1 else f"{base} {d} x {w}"
                                  for (base, d, w), n in sorted(groups.items()))


def diagram(meta):
    """Mermaid flowchart: input stream -> built units -> output buffer -> output stream."""
    ports = meta["ports"]
    fin = ", ".join(sorted({f.split(".")[0] for f in ports["i__payload"]["fields"]}))
    fout = ", ".join(sorted({f.split(".")[0] for f in ports["o__payload"]["fields"]}))
    lines = ["```mermaid", "flowchart LR",
             f'  IN(["in: {fin}<br/>valid / ready"])']
    prev = "IN"
    for i, b in enumerate(meta["built"]):
        node = f"U{i}"
        lines.append(f'  {node}["{b["unit"]}: {b["class"]}<br/>latency {b["latency"]}'
                     f'{_unit_memories(meta, b["unit"])}"]')
        lines.append(f"  {prev} --> {node}")
        prev = node
    lines += ['  BUF["output buffer<br/>2 entries"]', f"  {prev} --> BUF",
              f'  OUT(["out: {fout}<br/>valid / ready"])', "  BUF --> OUT"]
    for img in meta.get("memory_images", {}).values():
        host = img["port"][0].rsplit("_w_en", 1)[0]
        target = next((f"U{i}" for i, b in enumerate(meta["built"])
                       if b["unit"] == ("fetch" if host in ("map", "tex") else "palette")), None)
        if target:
            lines += [f'  H_{host}[/"host: {", ".join(img["port"])}"/]',
                      f"  H_{host} -.-> {target}"]
    lines.append("```")
    return "\n".join(lines)


def port_table(meta):
    ports = meta["named_ports"]["ports"]
    rows = ["| Port | Dir | Width | Packed bits | Format | Meaning |", "|---|---|---|---|---|---|"]
    for name, p in ports.items():
        bits = (f"`{p['from']}[{p['bits'][1]}:{p['bits'][0]}]`" if p["bits"] is not None
                else f"`{p['from']}`")
        fmt = ("signed" if p["signed"] else "unsigned") if p["width"] > 1 else "bit"
        rows.append(f"| `{name}` | {p['dir']} | {p['width']} | {bits} | {fmt} | "
                    f"{_meaning(name, p)} |")
    return "\n".join(rows)


def timing(meta):
    lat = " + ".join(f"{b['unit']} {b['latency']}" for b in meta["built"])
    out = [f"* Latency: **{meta['latency']} cycles**: a pixel taken at rising edge t (in_valid "
           f"and in_ready high) leaves at edge t + {meta['latency']} (out_valid is high in the "
           f"cycle before it) when out_ready is held high; {lat}.",
           f"* Throughput: {meta['throughput']} pixel per clock while out_ready is high.",
           f"* Block RAM ({meta.get('block_ram', {}).get('device', DEFAULT_DEVICE)}): "
           f"{meta.get('block_ram', {}).get('dp16kd_needed', '?')} DP16KD of "
           f"{meta.get('block_ram', {}).get('dp16kd_available', '?')}."]
    for name, img in meta.get("memory_images", {}).items():
        out.append(f"* Memory image `{img['file']}` ({name}): {img['depth']} words of "
                   f"{img['width']} bits, through `{'`, `'.join(img['port'])}`; {img['layout']}.")
    return "\n".join(out)


def verilog_template(meta):
    ports = meta["named_ports"]["ports"]
    wrapper = meta["named_ports"]["module"]
    conns = ",\n".join(f"    .{n:<14}({'' if n in ('clk', 'rst') else 'my_'}{n})" for n in ports)
    return f"```verilog\n{wrapper} u_bump (\n{conns}\n);\n```"


def load_template(meta):
    """A Verilog testbench fragment that loads each ``load = port`` image through its port."""
    ports = meta["named_ports"]["ports"]
    out = ["```verilog"]
    for name, img in meta.get("memory_images", {}).items():
        if img["load"] != "port" or name == "lut":
            continue
        en, addr, data = img["port"][:3]
        out += [f"reg [{ports[data]['width'] - 1}:0] {name}_words [0:{img['depth'] - 1}];",
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


def blocks(meta):
    return {"made-at": made_at(meta), "diagram": diagram(meta), "ports": port_table(meta),
            "timing": timing(meta), "verilog": verilog_template(meta),
            "load": load_template(meta)}


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


def run(args):
    meta = emit_for_integration(args.scene, args.out)
    path = write_doc(args.doc, blocks(meta))
    print(f"wrote {path} ({made_at(meta)})")
    return 0


def add_parser(sub):
    p = sub.add_parser("integration", help="the generated parts of docs/integration.md",
                       description="Emit the scene's pipeline with named ports (--load port) and "
                                   "write docs/integration.md's generated blocks from its "
                                   "sidecar: block diagram, port table, latency, memory images, "
                                   "instantiation template.")
    p.add_argument("--scene", default="default", metavar="FILE|NAME",
                   help="scene whose pipeline the page describes (default: default)")
    p.add_argument("--out", type=Path, default=Path("build/integration"),
                   help="where the pipeline is emitted (default: build/integration)")
    p.add_argument("--doc", type=Path, default=DOC, help=f"the page (default: {DOC})")
    p.set_defaults(func=run)
