"""The JSON sidecar of an emitted design, typed and versioned: :class:`Sidecar`.

Every ``bumprtl emit`` writes ``<module>.json`` beside ``<module>.v``: the ports and the bit
layout of each payload, latency, throughput, memories, error bounds and the command that
reproduces the files. This module is the one place that knows the file's shape: writers
build a :class:`Sidecar` and :meth:`Sidecar.dump` it, readers :func:`load` it and use its
attributes and accessors (:attr:`Sidecar.input_fields`, :meth:`Sidecar.port`...).

Schema version :data:`SCHEMA_VERSION` (the ``schema_version`` key). Version 1 was the
untyped sidecar (no ``schema_version`` key); what changed from it is :data:`CHANGES_FROM_1`,
and from version 2 :data:`CHANGES_FROM_2`.
:func:`load` refuses a file of another version, an unknown key and a missing key with one
line (:class:`~bumprtl.rtl.config.BumpError`) naming the key and the supported version.
Every key is written in every file (``null`` where a fact does not apply to the unit), so a
missing key is always an error.
"""

import json
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path

from bumprtl.rtl.config import BumpError

__all__ = ["SCHEMA_VERSION", "CHANGES_FROM_1", "CHANGES_FROM_2", "SCHEMA", "Field", "Port", "NamedPort", "NamedPorts",
           "Memory", "ErrorBounds", "Sidecar", "load", "loads", "from_facts", "ports_from_table"]

SCHEMA_VERSION = 3

CHANGES_FROM_1 = ("version 1 had no schema_version; a payload field is "
                  "{offset, width, signed} instead of [offset, width, signed]; roms became "
                  "memories, each with kind rom or ram; the error facts moved under error_bounds; "
                  "palette, fetch and pipeline facts under palette, fetch and pipeline; every "
                  "key is present (null where it does not apply)")

CHANGES_FROM_2 = ("version 3 adds fifo_depth (the credit edge's FIFO depth, also its "
                  "credits); latency is from a pixel taken at i to its result offered at o "
                  "through the free-running pipe and its credit edge (the edge's FIFO adds two "
                  "cycles to version 2's latency)")

# What a reader of an older version is told changed since it.
CHANGES = {1: f"{CHANGES_FROM_1}; {CHANGES_FROM_2}", 2: CHANGES_FROM_2}

MEMORY_KINDS = ("rom", "ram")

# The schema, key by key: (JSON type, meaning). docs/integration.md's table is made from it
# (gen/report/integration.py); tests/rtl/test_sidecar.py holds it to the dataclasses.
SCHEMA = {
    "schema_version": ("int", f"{SCHEMA_VERSION}; a reader refuses any other"),
    "unit": ("string", "the unit emitted: sincos, rotation, illumination, palette, pipeline, "
                       "fetch (with _axis for --interface axis)"),
    "module": ("string", "the top module, also the stem of every file of the emission"),
    "command": ("string", "the full bumprtl command that writes these files again"),
    "interface": ("string", "stream (valid/ready and packed payloads) or axis (AXI4-Stream)"),
    "ports": ("object", "port name -> {dir: in or out, width, fields}"),
    "ports.NAME.fields": ("object or null", "a packed payload's fields: path -> {offset, "
                                            "width, signed}, bits [offset, offset + width)"),
    "latency": ("int", "cycles from a pixel taken at i to its result offered at o (the FIFO "
                       "empty)"),
    "fifo_depth": ("int", "the credit edge's FIFO depth, also its credits: pixels inside at "
                          "once (docs/architecture.md, The credit loop)"),
    "throughput": ("int", "items per clock while the output is ready"),
    "config": ("object", "the Config (widths, method, coefficients)"),
    "scene": ("object or null", "the SceneConfig of a pipeline or fetch unit"),
    "method": ("string or null", "rotation and illumination: the method"),
    "memories": ("object", "memory name (unit.memory inside a pipeline) -> {kind: rom or ram, "
                           "depth, width, bits}; ram: written through a port"),
    "memory_bits": ("int or null", "palette and fetch: bits of their memories"),
    "error_bounds": ("object", "{lsb, lsb_per_channel, ulp, note, faithful_widths, "
                               "faithful_widths_searched}: the proven bounds vs float64"),
    "named_ports": ("object or null", "--ports named: {module, command, ports: name -> {dir, "
                                      "width, signed, from, bits: [lsb, msb] or null, field}}"),
    "axis": ("object or null", "--interface axis: tdata/tuser/tlast packing and reset"),
    "memory_images": ("object or null", "pipeline and fetch: image -> {file, load, depth, "
                                        "width, layout[, port]}; the map and texture also "
                                        "map_width, map_height (texels of level 0); a "
                                        "map_memory = axi map: load axi, base, bytes, slot_bytes"),
    "block_ram": ("object or null", "pipeline and fetch: DP16KD blocks needed and available"),
    "pipeline": ("object or null", "pipeline: {built: units with class, latency, why; "
                                   "skipped: units with why}"),
    "palette": ("object or null", "palette: index_bits, blend, double_buffered, "
                                  "out_of_range_index"),
    "fetch": ("object or null", "fetch: outputs, level_bases, addressing"),
}


@dataclass(frozen=True)
class Field:
    """One field of a packed payload: bits ``[offset, offset + width)`` of the port, two's
    complement when ``signed``. Iterates as ``(offset, width, signed)``."""
    offset: int
    width: int
    signed: bool

    def __iter__(self):
        return iter((self.offset, self.width, self.signed))

    def __getitem__(self, i):
        return (self.offset, self.width, self.signed)[i]

    @property
    def msb(self):
        return self.offset + self.width - 1


@dataclass(frozen=True)
class Port:
    """A port of the emitted module: ``dir`` "in"|"out", ``width`` bits, and for a packed
    payload its ``fields`` (name -> :class:`Field`; None for a plain signal)."""
    dir: str
    width: int
    fields: dict | None = None


@dataclass(frozen=True)
class NamedPort:
    """A port of the ``--ports named`` wrapper: ``source`` is the unit's port it connects to
    (JSON key ``from``), ``bits`` ``(lsb, msb)`` within it (None: the whole port), ``field``
    the payload field (None for a handshake or plain port)."""
    dir: str
    width: int
    signed: bool
    source: str
    bits: tuple | None = None
    field: str | None = None


@dataclass(frozen=True)
class NamedPorts:
    """The ``--ports named`` wrapper: its module, the command that writes it, its ports."""
    module: str
    command: str
    ports: dict                      # name -> NamedPort, in port order


@dataclass(frozen=True)
class Memory:
    """A memory of the design: ``kind`` "rom" (contents fixed at build) or "ram" (written
    by the design or the host), ``depth`` words of ``width`` bits, ``bits`` in all."""
    kind: str
    depth: int
    width: int
    bits: int


@dataclass(frozen=True)
class ErrorBounds:
    """Proven error bounds: ``lsb`` the largest of ``lsb_per_channel`` (8-bit LSB vs
    float64), ``ulp`` (sincos: output ULP), ``note`` the method's note, ``faithful_widths``
    the narrowest ``{angle_bits, frac_bits}`` proving 1 LSB (None: none do; absent from
    ``searched`` methods that do not search them)."""
    lsb: float | None = None
    lsb_per_channel: dict | None = None
    ulp: float | None = None
    note: str | None = None
    faithful_widths_searched: bool = False
    faithful_widths: dict | None = None


@dataclass(frozen=True)
class Sidecar:
    """The facts of one emitted design (see the module docstring for the file format)."""
    unit: str                        # the unit emitted: sincos, rotation, ..., pipeline, fetch
    module: str                      # the top module (and file stem)
    command: str                     # the full command that reproduces the files
    interface: str                   # "stream" or "axis"
    ports: dict                      # name -> Port
    latency: int                     # cycles from input to output
    throughput: int                  # items per clock
    config: dict                     # the Config (Config.to_dict)
    scene: dict | None               # the SceneConfig of a scene unit (to_dict)
    method: str | None               # rotation/illumination: the method
    memories: dict                   # name -> Memory
    memory_bits: int | None          # palette/fetch: bits of their memories
    error_bounds: ErrorBounds
    named_ports: NamedPorts | None   # --ports named
    axis: dict | None                # --interface axis: tdata/tuser/tlast facts
    memory_images: dict | None       # scene units: name -> image record (file, load, ...)
    block_ram: dict | None           # scene units: DP16KD fit on the device
    pipeline: dict | None            # pipeline: {"built": [...], "skipped": [...]}
    palette: dict | None             # palette: index_bits, blend, double_buffered, ...
    fetch: dict | None               # fetch: outputs, level_bases, addressing
    fifo_depth: int                  # the credit edge's FIFO depth (= its credits)
    schema_version: int = SCHEMA_VERSION

    # -- accessors ---------------------------------------------------------------------
    def port(self, name):
        """The :class:`Port` ``name``; BumpError naming the ports if there is none."""
        if name not in self.ports:
            raise BumpError(f"{self.module}.json has no port {name!r} (ports: "
                            f"{', '.join(self.ports)})")
        return self.ports[name]

    def fields_of(self, port):
        """``{field: Field}`` of a packed port (``{}`` for a plain one)."""
        return dict(self.port(port).fields or {})

    @property
    def input_fields(self):
        return self.fields_of("i__payload")

    @property
    def output_fields(self):
        return self.fields_of("o__payload")

    @property
    def roms(self):
        return {n: m for n, m in self.memories.items() if m.kind == "rom"}

    @property
    def rams(self):
        return {n: m for n, m in self.memories.items() if m.kind == "ram"}

    @property
    def built(self):
        return list((self.pipeline or {}).get("built", []))

    @property
    def skipped(self):
        return list((self.pipeline or {}).get("skipped", []))

    def replace(self, **changes):
        return replace(self, **changes)

    # -- the file ----------------------------------------------------------------------
    def to_dict(self):
        out = asdict(self)
        out["ports"] = {n: _port_dict(p) for n, p in self.ports.items()}
        out["named_ports"] = None if self.named_ports is None else {
            "module": self.named_ports.module, "command": self.named_ports.command,
            "ports": {n: _named_dict(p) for n, p in self.named_ports.ports.items()}}
        return _plain(out)

    def dumps(self):
        return json.dumps(self.to_dict(), indent=2, sort_keys=True) + "\n"

    def dump(self, path):
        Path(path).write_text(self.dumps())
        return Path(path)


def _plain(value):
    """JSON-ready: tuples as lists, numpy scalars/arrays as Python values."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if hasattr(value, "tolist"):
        return value.tolist()
    if hasattr(value, "to_dict"):
        return _plain(value.to_dict())
    return value


def _port_dict(p):
    out = {"dir": p.dir, "width": p.width, "fields": None}
    if p.fields is not None:
        out["fields"] = {n: {"offset": f.offset, "width": f.width, "signed": f.signed}
                         for n, f in p.fields.items()}
    return out


def _named_dict(p):
    return {"dir": p.dir, "width": p.width, "signed": p.signed, "from": p.source,
            "bits": None if p.bits is None else list(p.bits), "field": p.field}


# -- reading ---------------------------------------------------------------------------
def _object(d, where):
    """``d`` if it is an object (a JSON dict), else BumpError naming the key."""
    if not isinstance(d, dict):
        raise BumpError(f"sidecar key {where!r} must be an object, got {type(d).__name__}")
    return d


def _int(v, where):
    """``v`` if it is an integer (never a bool), else BumpError naming the key."""
    if isinstance(v, bool) or not isinstance(v, int):
        raise BumpError(f"sidecar key {where!r} must be an integer, got {v!r}")
    return v


def _keys(d, want, where, optional=()):
    """Refuse a missing or unknown key of the object ``d`` at ``where``."""
    _object(d, where)
    for k in want:
        if k not in d and k not in optional:
            raise BumpError(f"sidecar lacks key {where + '.' if where else ''}{k} "
                            f"(schema_version {SCHEMA_VERSION})")
    for k in d:
        if k not in want:
            raise BumpError(f"sidecar key {where + '.' if where else ''}{k} is unknown to "
                            f"schema_version {SCHEMA_VERSION}")


_TOP = [f.name for f in fields(Sidecar)]


def _from_dict(d):
    version = d.get("schema_version") if isinstance(d, dict) else None
    if not isinstance(d, dict) or "schema_version" not in d:
        raise BumpError(f"sidecar schema_version missing: a version-1 (untyped) sidecar; this "
                        f"bumprtl reads schema_version {SCHEMA_VERSION} only ({CHANGES[1]}); "
                        f"re-emit it with its command")
    if not isinstance(version, int) or isinstance(version, bool) or version != SCHEMA_VERSION:
        changed = f" ({CHANGES[version]})" if version in (1, 2) and not isinstance(version, bool) \
            else ""
        raise BumpError(f"sidecar schema_version must be {SCHEMA_VERSION}, got {version!r}"
                        f"{changed}; re-emit it with its command")
    _keys(d, _TOP, "")
    ports = {}
    for n, p in _object(d["ports"], "ports").items():
        _keys(p, ("dir", "width", "fields"), f"ports.{n}")
        fs = None if p["fields"] is None else {}
        for fn, f in _object(p["fields"] or {}, f"ports.{n}.fields").items():
            w = f"ports.{n}.fields.{fn}"
            _keys(f, ("offset", "width", "signed"), w)
            fs[fn] = Field(_int(f["offset"], f"{w}.offset"), _int(f["width"], f"{w}.width"),
                           bool(f["signed"]))
        ports[n] = Port(p["dir"], _int(p["width"], f"ports.{n}.width"), fs)
    memories = {}
    for n, m in _object(d["memories"], "memories").items():
        _keys(m, ("kind", "depth", "width", "bits"), f"memories.{n}")
        if m["kind"] not in MEMORY_KINDS:
            raise BumpError(f"sidecar memories.{n}.kind must be one of "
                            f"{', '.join(MEMORY_KINDS)}, got {m['kind']!r}")
        memories[n] = Memory(m["kind"], *(_int(m[k], f"memories.{n}.{k}")
                                          for k in ("depth", "width", "bits")))
    e = d["error_bounds"]
    _keys(e, [f.name for f in fields(ErrorBounds)], "error_bounds")
    named = d["named_ports"]
    if named is not None:
        _keys(named, ("module", "command", "ports"), "named_ports")
        nports = {}
        for n, p in _object(named["ports"], "named_ports.ports").items():
            _keys(p, ("dir", "width", "signed", "from", "bits", "field"), f"named_ports.ports.{n}")
            nports[n] = NamedPort(p["dir"], _int(p["width"], f"named_ports.ports.{n}.width"),
                                  bool(p["signed"]), p["from"],
                                  None if p["bits"] is None else tuple(p["bits"]), p["field"])
        named = NamedPorts(named["module"], named["command"], nports)
    return Sidecar(**{**d, "ports": ports, "memories": memories,
                      "error_bounds": ErrorBounds(**e), "named_ports": named})


def loads(text, name="sidecar"):
    """The :class:`Sidecar` of JSON ``text``; BumpError (one line, prefixed with ``name``)
    for another schema version, a missing or an unknown key."""
    try:
        d = json.loads(text)
    except json.JSONDecodeError as e:
        raise BumpError(f"{name}: not JSON ({e})") from None
    try:
        return _from_dict(d)
    except BumpError as e:
        raise BumpError(f"{name}: {e}") from None


def load(path):
    """The :class:`Sidecar` of the file ``path`` (see :func:`loads`)."""
    path = Path(path)
    return loads(path.read_text(), path.name)


# -- writing ---------------------------------------------------------------------------
_ERROR_KEYS = ("error_bound_lsb", "error_bounds_lsb", "error_bound_ulp", "error_note",
               "faithful_widths")
_PALETTE_KEYS = ("index_bits", "blend", "double_buffered", "out_of_range_index")
_FETCH_KEYS = ("outputs", "level_bases", "addressing")
_PIPELINE_KEYS = ("built", "skipped")
_OTHER_KEYS = ("config", "scene", "latency", "fifo_depth", "throughput", "method", "roms", "memory_bits",
               "interface", "axis", "memory_images", "block_ram")


def _port(p):
    fs = p.get("fields")
    return Port(p["dir"], int(p["width"]), None if fs is None else
                {n: Field(int(o), int(w), bool(s)) for n, (o, w, s) in fs.items()})


def ports_from_table(table):
    """``{name: Port}`` of a port table ``{name: {"dir", "width"[, "fields": {name:
    (offset, width, signed)}]}}`` (gen/flow/emit.py ``port_table``)."""
    return {n: _port(p) for n, p in table.items()}


def _memory(m):
    return Memory(m.get("kind", "rom"), int(m["depth"]), int(m["width"]), int(m["bits"]))


def from_facts(unit, command, ports, facts, module=None):
    """The :class:`Sidecar` of a unit from the facts its builder collects: ``ports`` as
    ``{name: {"dir", "width"[, "fields": {name: (offset, width, signed)}]}}``, ``facts``
    the unit's dict (config, latency, throughput, roms -- each memory with its ``kind`` --,
    error bounds, ...). A key this schema does not know is refused (BumpError)."""
    known = set(_ERROR_KEYS + _PALETTE_KEYS + _FETCH_KEYS + _PIPELINE_KEYS + _OTHER_KEYS)
    unknown = sorted(set(facts) - known)
    if unknown:
        raise BumpError(f"sidecar fact {unknown[0]!r} has no place in schema_version "
                        f"{SCHEMA_VERSION}")
    pick = lambda keys: {k: facts[k] for k in keys if k in facts} or None
    err = ErrorBounds(lsb=facts.get("error_bound_lsb"),
                      lsb_per_channel=facts.get("error_bounds_lsb"),
                      ulp=facts.get("error_bound_ulp"), note=facts.get("error_note"),
                      faithful_widths_searched="faithful_widths" in facts,
                      faithful_widths=facts.get("faithful_widths"))
    return Sidecar(
        unit=unit, module=module or unit, command=command,
        interface=facts.get("interface", "stream"),
        ports=ports_from_table(ports),
        latency=int(facts["latency"]), fifo_depth=int(facts["fifo_depth"]),
        throughput=int(facts["throughput"]),
        config=_plain(facts["config"]), scene=_plain(facts.get("scene")),
        method=facts.get("method"),
        memories={n: _memory(m) for n, m in sorted((facts.get("roms") or {}).items())},
        memory_bits=facts.get("memory_bits"), error_bounds=err, named_ports=None,
        axis=_plain(facts.get("axis")), memory_images=_plain(facts.get("memory_images")),
        block_ram=_plain(facts.get("block_ram")), pipeline=_plain(pick(_PIPELINE_KEYS)),
        palette=_plain(pick(_PALETTE_KEYS)), fetch=_plain(pick(_FETCH_KEYS)))

