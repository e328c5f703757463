"""The method registry, hardware side: one :class:`Method` record per method, the only list
of method names.

A method is its hardware (a rotation, or setup, Component and an illumination Component;
rtl/exact.py, rtl/lee.py, rtl/baselines/<name>.py) and a few facts (title, Table 1
baseline or not, whether lights can share its rotated normal, why the FPGA flow does not
place it). Its bit-exact golden models, input encoding, error bound and float64 reference
are the models' record of the same name, beside the models in sim/golden/methods.py
(docs/architecture.md, "Layers"): the hardware layer does not import the models that
check it. Everything hardware that depends on the method reads it from here:
``rotation.VectorRotation`` and ``illumination.Illumination``, ``Config``'s check of
``method``, the scene checks, the emitter, the formal targets and the FPGA report.

A record names its component classes by module path (``"bumprtl.rtl.exact:ExactRotation"``)
and imports them on first use, so that ``Config`` (which the datapaths import) can check
``method`` against this registry without an import cycle.

A method whose hardware is another's (:attr:`Method.hardware_of`: Ernst's per-pixel
datapath is Peercy's, Lee Table 1 and rtl/baselines/peercy.py) keeps its own name and
Table 1 column, builds the other's components, and is placed, proved and rendered once,
under the other's name (:data:`HARDWARE`).
"""

import importlib
from dataclasses import dataclass

from bumprtl.rtl.errors import ConfigError

__all__ = ["Method", "METHODS", "PER_PIXEL", "BASELINES", "HARDWARE", "get", "register"]

_LAYER = "bumprtl.rtl."


def _resolve(path):
    """``"bumprtl.rtl.module:attr"`` -> the object (imported on first use)."""
    module, _, attr = path.partition(":")
    if not module.startswith(_LAYER) or not attr:
        raise ValueError(f"hardware path {path!r} must name an attribute of a bumprtl.rtl module")
    return getattr(importlib.import_module(module), attr)


@dataclass(frozen=True)
class Method:
    """What one method builds.

    Attributes
    ----------
    name : str
        ``Config.method``.
    title : str
        Display name (reports, plots).
    baseline : bool
        A Lee et al. Table 1 comparison design, built for the cost comparison only; scenes
        and pipelines use the others (:attr:`per_pixel`).
    table1_column : int
        Position among the designs of ``bumprtl report table1`` (the paper's column order,
        ours last).
    rotation_path, illumination_path, layout_path : str
        ``"bumprtl.rtl.<module>:<name>"`` of the rotation (Table 1's setup) and illumination
        ``wiring.Component`` classes, ``cls(cfg, target=None)``, and of ``rotated_layout``
        (``cfg -> data.Layout``: the rotation's output payload = the illumination's input);
        read through :attr:`rotation`, :attr:`illumination`, :attr:`rotated_layout`.
    cartesian : bool
        The inputs (and a bump map's N') are Cartesian components, not binary angles.
    rotates_normal : bool
        The rotation turns N' into N's frame once (n'') and keeps each vector's terms apart
        from it, instead of rotating L and H into tangent space. Only such a method lets a
        scene have a flat bump map (n'' rotated once per polygon) or several lights (they
        share the one n''); the pipeline then builds the vectors' terms with
        ``rtl/exact.vector_terms`` (``pipeline.VectorTerms``).
    not_placed : str or None
        Why the ECP5 flow (gen/flow/fpga.py) does not place this method's units; None: it
        is placed.
    hardware_of : str or None
        The method whose hardware this one is (its paths are that record's); None: its own.
    """

    name: str
    title: str
    baseline: bool
    table1_column: int
    rotation_path: str
    illumination_path: str
    layout_path: str
    cartesian: bool
    rotates_normal: bool
    not_placed: str | None = None
    hardware_of: str | None = None

    @property
    def per_pixel(self):
        """A method scenes and pipelines use (not a Table 1 baseline)."""
        return not self.baseline

    @property
    def rotation(self):
        return _resolve(self.rotation_path)

    @property
    def illumination(self):
        return _resolve(self.illumination_path)

    @property
    def rotated_layout(self):
        return _resolve(self.layout_path)

    @property
    def hardware(self):
        """The name the hardware is placed, proved and rendered under."""
        return self.hardware_of or self.name


def _alias(name, title, table1_column, of):
    """``name``'s record building ``of``'s hardware (same paths and input format)."""
    base = _RECORDS[of]
    return Method(name, title, base.baseline, table1_column, base.rotation_path,
                  base.illumination_path, base.layout_path, base.cartesian, base.rotates_normal,
                  base.not_placed, hardware_of=of)


_RECORDS = {m.name: m for m in (
    Method("exact", "exact angular method", baseline=False, table1_column=6,
           rotation_path="bumprtl.rtl.exact:ExactRotation",
           illumination_path="bumprtl.rtl.exact:ExactIllumination",
           layout_path="bumprtl.rtl.exact:rotated_layout", cartesian=False, rotates_normal=True),
    Method("lee", "Lee et al. 2003 (errata fixed)", baseline=False, table1_column=5,
           rotation_path="bumprtl.rtl.lee:LeeRotation",
           illumination_path="bumprtl.rtl.lee:LeeIllumination",
           layout_path="bumprtl.rtl.lee:rotated_layout", cartesian=False, rotates_normal=False),
    Method("peercy", "Peercy et al. 1997", baseline=True, table1_column=1,
           rotation_path="bumprtl.rtl.baselines.peercy:PeercyRotation",
           illumination_path="bumprtl.rtl.baselines.peercy:PeercyIllumination",
           layout_path="bumprtl.rtl.baselines.peercy:setup_output_layout", cartesian=True,
           rotates_normal=False),
)}
# Ernst et al. 1998 differ from Peercy only in how the bump map is built (preprocessing,
# Lee Sec. 2): the per-pixel setup and the straightforward Phong are Peercy's, and Table 1
# gives both the same setup counts (rtl/baselines/peercy.py).
_RECORDS["ernst"] = _alias("ernst", "Ernst et al. 1998", 4, of="peercy")
_RECORDS["kim"] = Method(
    "kim", "Kim et al. 2001", baseline=True, table1_column=3,
    rotation_path="bumprtl.rtl.baselines.kim:KimRotation",
    illumination_path="bumprtl.rtl.baselines.kim:KimIllumination",
    layout_path="bumprtl.rtl.lee:rotated_layout", cartesian=False, rotates_normal=False)

METHODS = dict(_RECORDS)
PER_PIXEL = BASELINES = HARDWARE = ()


def _derive():
    """The lists every consumer reads, derived from :data:`METHODS`."""
    global PER_PIXEL, BASELINES, HARDWARE
    PER_PIXEL = tuple(n for n, m in METHODS.items() if m.per_pixel)    # scenes and pipelines
    BASELINES = tuple(n for n, m in METHODS.items() if m.baseline)     # Table 1 cost comparison
    HARDWARE = tuple(n for n, m in METHODS.items() if m.hardware_of is None)  # distinct hardware


_derive()


def register(method: Method):
    """Add ``method`` to :data:`METHODS` (after the built-in ones) and derive the lists again;
    modules that read the lists take them when they are imported, so a method added this
    way (tests/tools/toy_method.py) is registered before they are. Returns it."""
    if method.name in METHODS:
        raise ConfigError(f"method {method.name!r} is registered already", "method")
    METHODS[method.name] = method
    _derive()
    return method


def get(name) -> Method:
    """The record of method ``name``; a :class:`ConfigError` naming ``method`` and the
    allowed names if there is none."""
    if name not in METHODS:
        raise ConfigError(f"method must be one of {', '.join(METHODS)}, got {name!r}", "method")
    return METHODS[name]
