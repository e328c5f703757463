"""Test vectors for an emitted scene pipeline, or a rotation or illumination unit alone
(``bumprtl vectors``): stimulus, the expected outputs of the bit-exact golden model, and a
self-checking Verilog bench for them.

Three sources of pixels:

* ``frame``: the scene's own frame, the stimulus ``bumprtl render`` streams
  (gen/render/rtl.scene_stimulus): the first ``count`` pixels in raster order of the
  smallest power-of-two frame (side >= 16) that has ``count`` pixels;
* ``random``: seeded random valid pixels (sim/golden/fixed/pipeline.random_inputs: texel
  coordinates over the whole signed port range, N' and L, H above the surface);
* a ``.csv`` or ``.npy`` file of the user's own pixels as physical values
  (:func:`read_user_pixels`): texel coordinates, and N, L, H as polar angles in radians,
  encoded to the port codes by the golden model's one encoder,
  sim/golden/methods.encode_pixels (binary angles: ``round(angle / 2 pi * 2**angle_bits)``
  modulo the full circle).

A unit (:func:`unit_vectors`) takes the datapath's inputs: the default scene's frame, random
pixels, or for rotation a file of N, L, H and N' angles (:func:`rotation_columns`).

The memories (bump map, colour texture, palette colour table) are the ones ``bumprtl emit``
builds into or writes beside the design (gen/render/rtl.scene_memories), and a flat map's
polygon registers those of the scene's frame, so the expected outputs
(sim/golden/fixed/pipeline.pipeline_fixed) are what the emitted Verilog must produce. They
come from the golden model, never from simulating the RTL.

:func:`write_vectors` emits the design with named ports (gen/flow/named.py) into the output
directory, one ``$readmemh`` file per input and per output field, and the testbench
(gen/flow/vectors_tb.py).
"""

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bumprtl.gen.flow.emit import port_table
from bumprtl.gen.flow.memories import (
    DEFAULT_DEVICE,
    LOADS,
    check_scene_fits,
    emit_scene_unit,
    hex_text,
    memory_images,
    scene_command,
)
from bumprtl.gen.flow.named import named_module, with_named, write_named
from bumprtl.gen.flow.units import UNITS, emit_unit
from bumprtl.gen.flow.vectors_tb import bench_verilog, run_commands
from bumprtl.gen.render.rtl import scene_memories, scene_stimulus, sim_scene
from bumprtl.rtl.bumpfetch import coord_bits, level_bits
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.layouts import light_keys, pack
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.sidecar import load, ports_from_table
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.fixed.palette_lut import palette_colors
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed, random_inputs
from bumprtl.sim.golden.methods import encode_pixels
from bumprtl.sim.golden.methods import get as get_models
from bumprtl.sim.golden.vectors import random_codes
from bumprtl.sim.scenes.config import SceneConfig, load_scene_config

__all__ = ["SOURCES", "MAX_COUNT", "DEFAULT_COUNT", "Vectors", "pipeline_fields",
           "pixel_columns", "read_user_pixels", "encode_user_pixels", "pipeline_vectors",
           "write_vectors", "run_commands", "UNIT_SOURCES", "unit_fields", "rotation_columns",
           "unit_vectors", "check_count"]

SOURCES = ("frame", "random")          # or a .csv / .npy file of the user's pixels
MAX_COUNT = 1 << 20                    # pixels (a 1024 x 1024 frame)
DEFAULT_COUNT = 1000
FRAME_MIN = 16                         # the smallest frame side bumprtl render draws
_TWO_PI = 2 * math.pi


@dataclass
class Vectors:
    """Pixels for one scene pipeline (or one unit) and what it must output.

    ``unit``: ``pipeline`` (of ``scene``) or a unit of :data:`UNIT_SOURCES` (of ``config``).
    ``inputs``/``expected``: ``{payload field: int64 array}`` keyed like the flattened
    payloads (``"n.phi"``, ``"color"``, ``"tag"``); ``words``, ``texels``, ``table``: the
    memories (None where the scene has none); ``polygon``: a flat map's polygon registers.
    """
    scene: SceneConfig | None          # None for a unit
    source: str
    seed: int
    inputs: dict
    expected: dict
    words: object = None
    texels: object = None
    table: object = None
    polygon: dict = None
    unit: str = "pipeline"
    config: Config | None = None       # a unit's Config (a pipeline's is its scene's)

    def __len__(self):
        return len(self.inputs["tag"])


def _silenced(dut):
    """``dut`` whose plan is read but never elaborated: no unused-elaboratable warning."""
    for unit in (dut, *dut.units.values()):
        unit._MustUse__silence = True
    return dut


def pipeline_fields(scene: SceneConfig):
    """``(input fields, output fields, ports)`` of ``BumpPipeline(scene)``: the payload
    field tables ``{path: Field}`` and ``{name: Port}`` (rtl/sidecar.py, from
    gen/flow/emit.port_table), read off its signature without elaborating it."""
    ports = ports_from_table(port_table(_silenced(BumpPipeline(scene.hardware))))
    return ports["i__payload"].fields, ports["o__payload"].fields, ports


def _column(path):
    return path.replace(".", "_")


def pixel_columns(scene: SceneConfig):
    """The columns of a user's pixel file for ``scene``, in port order: one per input field
    (``u``, ``v``, ``level``, ``n_phi``, ..., ``extra_lights_0_l_phi``: the named port
    without ``in_``), ``tag`` last and optional. Returns ``{column: (field, kind)}``, kind
    ``coord`` (integer texel coordinate), ``level``, ``phi``/``theta`` (radians) or ``tag``."""
    fields, _, _ = pipeline_fields(scene)
    out = {}
    for path in sorted(fields, key=lambda p: fields[p][0]):
        if path == "tag":
            continue
        kind = ("coord" if path in ("u", "v") else "level" if path == "level" else
                path.rsplit(".", 1)[-1])
        if kind not in ("coord", "level", "phi", "theta"):
            raise BumpError(f"the {scene.name} pipeline has an input field {path!r} that a pixel "
                            f"file cannot give")
        out[_column(path)] = (path, kind)
    out["tag"] = ("tag", "tag")
    return out


def _ranges(scene: SceneConfig | None, cfg: Config):
    """Allowed range of each kind of column: (low, high, text); coordinates and levels only
    with a scene."""
    tag = (1 << cfg.tag_bits) - 1
    out = {"phi": (0.0, _TWO_PI, "radians in [0, 2*pi]"),
           "theta": (0.0, math.pi, "radians in [0, pi]"),
           "tag": (0, tag, f"integers in [0, {tag}]")}
    if scene is not None:
        half, top = 1 << (coord_bits(scene) - 1), (1 << level_bits(scene)) - 1
        out.update({"coord": (-half, half - 1, f"integers in [{-half}, {half - 1}]"),
                    "level": (0, top, f"integers in [0, {top}]")})
    return out


def _read_table(path: Path):
    """``({column: float64 array}, rows)`` of a CSV file with a header row, or of a
    structured .npy array (its field names) or a 2-D .npy (columns unnamed: None keys)."""
    suffix = path.suffix.lower()
    try:
        if suffix == ".npy":
            arr = np.load(path, allow_pickle=False)
            if arr.dtype.names:
                return {n: np.asarray(arr[n], np.float64).ravel() for n in arr.dtype.names}, arr.size
            if arr.ndim != 2:
                raise BumpError(f"--source {path}: a .npy file must be a structured array (one "
                                f"field per column) or 2-D (rows x columns), got shape {arr.shape}")
            return [np.asarray(arr[:, k], np.float64) for k in range(arr.shape[1])], arr.shape[0]
        with open(path, newline="") as f:
            rows = [r for r in csv.reader(f) if r and any(c.strip() for c in r)]
    except (OSError, ValueError, UnicodeDecodeError) as e:
        raise BumpError(f"--source {path}: cannot read it ({e.__class__.__name__}: {e})") from None
    if not rows:
        raise BumpError(f"--source {path}: empty file; a header row of column names comes first")
    header = [c.strip() for c in rows[0]]
    cols = {h: [] for h in header}
    for n, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise BumpError(f"--source {path}: line {n} has {len(row)} values, the header "
                            f"{len(header)}")
        for h, c in zip(header, row, strict=True):
            try:
                cols[h].append(float(c))
            except ValueError:
                raise BumpError(f"--source {path}: line {n}, column {h}: {c.strip()!r} is not a "
                                f"number") from None
    return {h: np.asarray(v, np.float64) for h, v in cols.items()}, len(rows) - 1


def read_user_pixels(path, scene: SceneConfig):
    """The pixels of a ``.csv`` (header row of column names) or ``.npy`` file (a structured
    array with the same names, or a 2-D array with the columns in :func:`pixel_columns`'
    order) as ``{column: float64 array}``, every column checked against its range: texel
    coordinates and levels integers in the port's range, ``*_phi`` in [0, 2 pi], ``*_theta``
    in [0, pi] radians, ``tag`` (optional) an integer of ``tag_bits``. A
    :class:`BumpError` names the parameter, the column and the allowed range."""
    return _user_table(path, pixel_columns(scene), _ranges(scene, scene.config),
                       f"the {scene.name} pipeline")


def _user_table(path, columns, ranges, what):
    """:func:`read_user_pixels` for the ``columns`` (``{column: (field, kind)}``, ``tag``
    last and optional) of ``what``."""
    path = Path(path)
    if path.suffix.lower() not in (".csv", ".npy"):
        raise BumpError(f"--source must be one of {', '.join(SOURCES)} or a .csv or .npy file, "
                        f"got {str(path)!r}")
    if not path.is_file():
        raise BumpError(f"--source {path}: no such file")
    need = [c for c in columns if c != "tag"]
    table, rows = _read_table(path)
    if isinstance(table, list):                          # a 2-D .npy: columns by position
        if len(table) not in (len(need), len(need) + 1):
            raise BumpError(f"--source {path}: {len(table)} columns; {what} takes "
                            f"{len(need)} ({', '.join(need)}) and an optional tag")
        table = dict(zip([*need, "tag"], table, strict=False))
    names = set(table)
    if names - set(columns) or set(need) - names:
        raise BumpError(f"--source {path}: columns must be {', '.join(need)} (and optionally "
                        f"tag) for {what}, got {', '.join(table)}")
    if rows == 0:
        raise BumpError(f"--source {path}: no pixels (a header only)")
    for col, values in table.items():
        lo, hi, text = ranges[columns[col][1]]
        integral = columns[col][1] in ("coord", "level", "tag")
        bad = ~np.isfinite(values) | (values < lo) | (values > hi)
        if integral:
            bad |= np.isfinite(values) & (values != np.round(values))
        if bad.any():
            k = int(np.argmax(bad))
            raise BumpError(f"--source {path}: column {col} must hold {text}, got {values[k]:.6g} "
                            f"in pixel {k}")
    return table


def encode_user_pixels(table, scene: SceneConfig):
    """Physical pixel values (:func:`read_user_pixels`) -> the input payload codes: angles by
    sim/golden/methods.encode_pixels of the scene's method (one PixelInputs per light; N' comes
    from the map, so its angles are 0 here and unused), coordinates and tag as integers
    (tag default: the pixel index modulo 2**tag_bits)."""
    columns = pixel_columns(scene)
    cfg = scene.config
    n = len(next(iter(table.values())))
    zero = np.zeros(n)
    get = lambda key: table.get(_column(key), zero)
    out = {}
    for col, (path, kind) in columns.items():
        if kind in ("coord", "level") and col in table:
            out[path] = np.rint(table[col]).astype(np.int64)
    for keys in light_keys(cfg):
        px = PixelInputs(n_phi=get("n.phi"), n_theta=get("n.theta"),
                         l_phi=get(keys["l.phi"]), l_theta=get(keys["l.theta"]),
                         h_phi=get(keys.get("h.phi", "h.phi")),
                         h_theta=get(keys.get("h.theta", "h.theta")), b_phi=zero, b_theta=zero)
        codes = encode_pixels(px, cfg)
        for own, key in (("n.phi", "n.phi"), ("n.theta", "n.theta"), *keys.items()):
            if _column(key) in columns:
                if own not in codes:
                    raise BumpError(f"method {cfg.method!r} does not encode {own} as a binary "
                                    f"angle; a pixel file needs a polar method (exact, lee, kim)")
                out[key] = np.asarray(codes[own], np.int64)
    tag = table.get("tag")
    out["tag"] = (np.arange(n, dtype=np.int64) & ((1 << scene.tag_bits) - 1) if tag is None
                  else np.rint(tag).astype(np.int64))
    return out


def _frame_side(count):
    """The side of the smallest frame of at least ``count`` pixels: a power of two >= 16."""
    return max(FRAME_MIN, 1 << max(0, math.ceil(math.sqrt(count)) - 1).bit_length())


def check_count(count):
    """A :class:`BumpError` naming ``--count`` unless 1 <= count <= MAX_COUNT."""
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_COUNT:
        raise BumpError(f"--count must be an integer in [1, {MAX_COUNT}], got {count!r}")


def _check_source(source, count, seed):
    """The checks every source shares; returns the pixel count of a frame or random source."""
    if source not in SOURCES and Path(source).suffix.lower() not in (".csv", ".npy"):
        raise BumpError(f"--source must be one of {', '.join(SOURCES)} or a .csv or .npy file, "
                        f"got {source!r}")
    if count is not None:
        check_count(count)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 1 << 31:
        raise BumpError(f"--seed must be an integer in [0, {(1 << 31) - 1}], got {seed!r}")
    return DEFAULT_COUNT if count is None else count


def _file_count(table, source, count):
    """The pixels taken from a file: every row, or the first ``count``."""
    rows = len(next(iter(table.values())))
    if count is not None and count > rows:
        raise BumpError(f"--count must be at most the {rows} pixels of {source}, got {count}")
    return rows if count is None else count


def pipeline_vectors(scene: SceneConfig, source="random", count=None, seed=1) -> Vectors:
    """:class:`Vectors` of ``count`` pixels (None: DEFAULT_COUNT, or every row of a file) from
    ``source`` (``frame``, ``random`` or a .csv/.npy path; module docstring) for the
    pipeline of ``scene``; ``seed`` seeds the random pixels. Bad input raises a
    :class:`BumpError` naming the parameter; nothing is written."""
    source = str(source)
    n = _check_source(source, count, seed)
    fields, outs, _ = pipeline_fields(scene)
    user = None
    if source not in SOURCES:                  # checked before any map or frame is built
        user = read_user_pixels(source, scene)
        n = _file_count(user, source, count)
        user = {k: v[:n] for k, v in user.items()}
    words, texels, table = scene_memories(scene)
    # the frame gives the pixels (frame) and a flat map's polygon registers (every source)
    frame, _, polygon, _, _ = scene_stimulus(scene, _frame_side(n) if source == "frame"
                                             else FRAME_MIN)
    if source == "frame":
        inputs = {k: v[:n] for k, v in frame.items()}
    elif source == "random":
        inputs = random_inputs(scene, n, np.random.default_rng(seed))
    else:
        inputs = encode_user_pixels(user, scene)
    inputs = {k: np.asarray(v, np.int64) for k, v in inputs.items() if k in fields}
    if set(inputs) != set(fields):
        raise AssertionError(f"stimulus fields {sorted(inputs)} != the pipeline's {sorted(fields)}")
    golden = pipeline_fixed(inputs, scene, words, polygon, texels)
    if scene.shading == "palette":
        oor = golden["index"] >= scene.config.palette_size     # an index past the table
        golden = {**golden, **palette_colors({**golden, "index": np.where(oor, 0, golden["index"])},
                                             table, scene),
                  "oor": oor.astype(np.int64)}
        for c in ("color.r", "color.g", "color.b", "color.a"):
            golden[c] = np.where(oor, 0, golden[c])
    golden["tag"] = inputs["tag"]
    missing = set(outs) - set(golden)
    if missing:
        raise AssertionError(f"the golden model gives no {', '.join(sorted(missing))}")
    expected = {k: np.asarray(golden[k], np.int64) for k in outs}
    return Vectors(scene, source, seed, inputs, expected, words, texels, table, polygon)


# unit -> the sources it takes (its inputs are the datapath's: no map, no memories)
UNIT_SOURCES = {"rotation": ("frame", "random", "file"), "illumination": ("frame", "random")}
_PIXEL_KEYS = ("n.phi", "n.theta", "l.phi", "l.theta", "h.phi", "h.theta", "b.phi", "b.theta")


def unit_fields(unit, cfg: Config):
    """``(input fields, output fields)`` of unit ``unit`` (gen/flow/units.py) at ``cfg``."""
    dut = UNITS[unit].build(cfg)
    dut._MustUse__silence = True
    ports = ports_from_table(port_table(dut))
    return ports["i__payload"].fields, ports["o__payload"].fields


def rotation_columns(cfg: Config):
    """The columns of a pixel file for the rotation unit: N, L, (H with specular) and the
    bump normal N' (``b``) as polar angles in radians, ``tag`` optional; as
    :func:`pixel_columns`."""
    keys = [k for k in _PIXEL_KEYS if cfg.specular or not k.startswith("h.")]
    return {**{_column(k): (k, k.rsplit(".", 1)[1]) for k in keys}, "tag": ("tag", "tag")}


def unit_vectors(unit, cfg: Config, source="random", count=None, seed=1) -> Vectors:
    """:class:`Vectors` of ``count`` pixels for the rotation or illumination unit of ``cfg``:
    ``frame`` (the default scene's frame, encoded by the method's encoder,
    sim/golden/methods.encode_pixels), ``random`` (sim/golden/vectors.random_codes: valid
    pixels, as the method's input codes) or, for rotation, a .csv/.npy of physical angles
    (:func:`rotation_columns`). Illumination's inputs are the rotation's outputs of those
    pixels. Expected outputs: the method's bit-exact models."""
    if unit not in UNIT_SOURCES:
        raise BumpError(f"--unit must be one of {', '.join(UNIT_SOURCES)}, got {unit!r}")
    source = str(source)
    is_file = source not in SOURCES
    if is_file and "file" not in UNIT_SOURCES[unit]:
        raise BumpError(f"--source FILE applies to --pipeline and --unit rotation (the "
                        f"{unit} unit's inputs are rotated terms, not angles); use "
                        f"{' or '.join(UNIT_SOURCES[unit])}")
    n = _check_source(source, count, seed)
    fields, outs = unit_fields(unit, cfg)
    mask = (1 << cfg.tag_bits) - 1
    models = get_models(cfg.method)
    if is_file:
        table = _user_table(source, rotation_columns(cfg), _ranges(None, cfg), "the rotation unit")
        n = _file_count(table, source, count)
        zero = np.zeros(n)
        px = PixelInputs(**{f.replace(".", "_"): table.get(_column(f), zero)[:n]
                            for f in _PIXEL_KEYS})
        codes = encode_pixels(px, cfg)
        tag = table.get("tag")
        tag = np.arange(n) & mask if tag is None else np.rint(tag[:n])
    elif source == "frame":
        side = _frame_side(n)
        px = sim_scene(load_scene_config("default"), side).px
        codes = {k: np.asarray(v).ravel()[:n] for k, v in encode_pixels(px, cfg).items()}
        tag = np.arange(n) & mask
    else:
        codes = models.from_angle_codes(random_codes(n, cfg, seed), cfg)
        tag = np.arange(n) & mask
    codes = {k: np.asarray(v, np.int64) for k, v in codes.items()}
    rot = models.rotation_fixed(codes, cfg)
    inputs, golden = (codes, rot) if unit == "rotation" else (rot, models.illumination_fixed(rot, cfg))
    inputs = {**{k: np.asarray(inputs[k], np.int64) for k in fields if k != "tag"},
              "tag": np.asarray(tag, np.int64)}
    missing = set(outs) - set(golden) - {"tag"}
    if missing:
        raise AssertionError(f"the golden model gives no {', '.join(sorted(missing))}")
    expected = {**{k: np.asarray(golden[k], np.int64) for k in outs if k != "tag"},
                "tag": inputs["tag"]}
    return Vectors(None, source, seed, inputs, expected, unit=unit, config=cfg)


def _emit_unit_named(v: Vectors, out, module):
    """A rotation or illumination unit emitted as ``bumprtl emit UNIT --ports named``."""
    vpath, jpath = emit_unit(v.unit, v.config, out, module=module)
    return _add_named(vpath, jpath), [vpath, vpath.with_name(f"{named_module(module)}.v"), jpath]


def _add_named(vpath, jpath, device=DEFAULT_DEVICE):
    """Write the named-ports wrapper and record it in the sidecar, whose ``command`` becomes
    the ``bumprtl emit ... --ports named`` line that writes these files (as emit records
    it: ``--device`` when not the default); returns the sidecar."""
    meta = load(jpath)
    command = meta.command + " --ports named"
    write_named(vpath, meta, command)
    meta = with_named(meta, named_module(vpath.stem), command)
    meta = meta.replace(command=command + (f" --device {device}" if device != DEFAULT_DEVICE else ""))
    meta.dump(jpath)
    return meta


def _emit_named(v: Vectors, out, module, load, device):
    """The pipeline emitted as ``bumprtl emit pipeline --ports named`` does it: ``(sidecar,
    paths)``."""
    images = memory_images("pipeline", v.scene, v.words, v.texels, v.table, load)
    vpath, jpath, hexes = emit_scene_unit("pipeline", v.scene, out, images, device,
                                          scene_command("pipeline", v.scene, load, module),
                                          module=module)
    meta = _add_named(vpath, jpath, device)
    return meta, [vpath, vpath.with_name(f"{named_module(module)}.v"), jpath, *hexes]


def _field_hex(values, width):
    return hex_text(np.asarray(values, np.int64) & ((1 << width) - 1), width)


def write_vectors(v: Vectors, out, module="bumprtl_pipeline", load="initial", top=None,
                  device=DEFAULT_DEVICE, command=None):
    """Write into ``out``: the design (``<module>.v``, ``<module>_named.v``, the sidecar and
    its memory images, as ``bumprtl emit pipeline --ports named --load LOAD``), one
    ``$readmemh`` file per field (``<module>_in_<field>.hex``, ``<module>_out_<field>.hex``,
    the expected words; ``<module>_poly.hex`` for a flat map) and ``<module>_tb.v``, the
    self-checking bench (gen/flow/vectors_tb.py). ``top``: the bench instantiates this
    module (your own top with the named ports' clk, rst, in_* and out_*, which loads its
    maps itself) instead of ``<module>_named``. Returns the paths written."""
    if load not in LOADS:
        raise BumpError(f"--load must be one of {', '.join(LOADS)}, got {load!r}")
    out = Path(out)
    if v.scene is None:                        # a unit: no memories to load or fit
        meta, paths = _emit_unit_named(v, out, module)
    else:
        if device is not None:
            check_scene_fits(v.scene, device)  # refused before anything is written
        meta, paths = _emit_named(v, out, module, load, device)
    ports = meta.named_ports.ports
    for direction, values in (("in", v.inputs), ("out", v.expected)):
        for field, arr in values.items():
            name = f"{direction}_{_column(field)}"
            path = out / f"{module}_{name}.hex"
            path.write_text(_field_hex(arr, ports[name].width))
            paths.append(path)
    poly = None
    if "poly" in meta.ports and v.polygon is not None:
        poly = out / f"{module}_poly.hex"
        poly.write_text(hex_text([pack(meta.fields_of("poly"), v.polygon)], meta.port("poly").width))
        paths.append(poly)
    command = command or (f"bumprtl vectors --unit {v.unit}" if v.scene is None else
                          f"bumprtl vectors --pipeline {v.scene.name}") + f" --count {len(v)}"
    tb = out / f"{module}_tb.v"
    tb.write_text(bench_verilog(meta, module, len(v), v.seed, command, top=top))
    paths.append(tb)
    return paths
