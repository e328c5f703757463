"""The method registry, models side: per method of the hardware registry (rtl/methods.py,
joined by the method's name) its bit-exact golden models, input encoding, proven error
bound and float64 reference, and the golden entry points of ``cfg.method``.

The hardware registry is the only list of method names; this module has one record per
name of it (checked at import) and adds nothing to the list. A :class:`Models` record
also answers for its hardware record (``title``, ``baseline``, ``rotation``...): tests,
benches and reports read the joined view from here, the hardware from rtl/methods.py.

Adding a method: its models (sim/golden/fixed/<name>.py, sim/golden/float/<name>.py) and
one :class:`Models` entry in :data:`MODELS` under the name of its hardware record
(docs/contributing.md, "Adding a method").
"""

from collections.abc import Callable
from dataclasses import dataclass

from bumprtl.rtl import methods as hardware
from bumprtl.rtl.config import Config, ConfigError
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.fixed import exact as fixed_exact
from bumprtl.sim.golden.fixed import kim as fixed_kim
from bumprtl.sim.golden.fixed import lee as fixed_lee
from bumprtl.sim.golden.fixed import peercy as fixed_peercy
from bumprtl.sim.golden.fixed.common import quantize_pixels
from bumprtl.sim.golden.float.exact import exact
from bumprtl.sim.golden.float.kim import kim
from bumprtl.sim.golden.float.lee import lee_corrected, lee_printed
from bumprtl.sim.golden.float.peercy import peercy

__all__ = ["Models", "MODELS", "METHODS", "PER_PIXEL", "BASELINES", "HARDWARE", "get",
           "register", "rotation_fixed", "illumination_fixed", "datapath_fixed", "encode_pixels"]

PER_PIXEL, BASELINES, HARDWARE = hardware.PER_PIXEL, hardware.BASELINES, hardware.HARDWARE


@dataclass(frozen=True)
class Models:
    """What one method is checked against; the hardware record of the same name answers
    the other attributes (:meth:`__getattr__`).

    Attributes
    ----------
    name : str
        The hardware record's name (``Config.method``).
    rotation_fixed : callable
        ``(codes, cfg) -> dict``: the bit-exact rotation output fields (flattened names).
    illumination_fixed : callable
        ``(rot, cfg) -> dict``: ndotl, ndoth and the 8-bit diffuse, specular, color.
    encode : callable
        ``(PixelInputs, cfg) -> codes``: float64 pixels to the rotation unit's input codes
        (binary angles, ``quantize_pixels``, or the method's own ``encode``).
    from_angle_codes : callable
        ``(codes, cfg) -> codes``: binary-angle codes (sim/golden/vectors.py) to the rotation
        unit's input codes of the same directions (the identity for the polar methods), so
        the shared edge-case stimulus drives every method.
    predicted_error_bound_lsb : callable
        ``(cfg, channel="diffuse", lights=1) -> int``: the proven error bound of one output
        channel (``diffuse``, ``specular``, ``color``, ``blend``) against float64, 8-bit LSB.
    error_note : str
        What the bound means and where it is proved or measured (the emitter's sidecar).
    reference : callable or None
        The float64 model ``(PixelInputs, cfg) -> Result`` (sim/golden/float/); its
        function name is its name in ``FLOAT_MODELS`` and ``bumprtl render --model``.
    other_references : tuple
        Further float64 models of the method listed in ``FLOAT_MODELS`` before
        ``reference`` (lee: the paper's equations as printed).
    faithful_widths : callable or None
        ``(cfg) -> (angle_bits, frac_bits) or None``: the narrowest widths at which the
        method's bound proves every output channel within 1 LSB of float64 end to end (the
        sidecar's ``faithful_widths``). None: not searched (lee: its approximations, not
        its widths, set the error; the baselines are measured, not tuned).
    """

    name: str
    rotation_fixed: Callable
    illumination_fixed: Callable
    encode: Callable
    from_angle_codes: Callable
    predicted_error_bound_lsb: Callable
    error_note: str
    reference: Callable | None = None
    other_references: tuple = ()
    faithful_widths: Callable | None = None

    def __getattr__(self, attr):
        if attr.startswith("__"):
            raise AttributeError(attr)
        return getattr(hardware.get(self.name), attr)

    def datapath_fixed(self, codes, cfg: Config):
        """Rotation then illumination, bit-exact: the rotation fields, ndotl, ndoth and the
        8-bit diffuse, specular, color."""
        rot = self.rotation_fixed(codes, cfg)
        return {**rot, **self.illumination_fixed(rot, cfg)}


def _same_codes(codes, cfg: Config):
    """The polar methods' inputs are the binary-angle codes themselves."""
    return codes


_UNQUANTIZED = "the largest over the channels (error_bounds.lsb; each channel in error_bounds.lsb_per_channel) vs float64 on unquantized inputs"
_CARTESIAN_NOTE = (f"{_UNQUANTIZED}, Cartesian input codes from "
                   "sim/golden/fixed/peercy.encode "
                   "(proof: sim/golden/fixed/peercy.predicted_error_bound_lsb)")
_PEERCY = dict(rotation_fixed=fixed_peercy.rotation_fixed,
               illumination_fixed=fixed_peercy.illumination_fixed,
               encode=fixed_peercy.encode, from_angle_codes=fixed_peercy.from_angle_codes,
               predicted_error_bound_lsb=fixed_peercy.predicted_error_bound_lsb,
               error_note=_CARTESIAN_NOTE, reference=peercy)

MODELS = {}


def register(models: Models):
    """Add ``models`` under the name of its hardware record (a :class:`ConfigError` naming
    ``method`` when there is none); returns it."""
    hardware.get(models.name)
    MODELS[models.name] = models
    return models


register(Models("exact", rotation_fixed=fixed_exact.rotation_fixed,
                illumination_fixed=fixed_exact.illumination_fixed,
                encode=quantize_pixels, from_angle_codes=_same_codes,
                predicted_error_bound_lsb=fixed_exact.predicted_error_bound_lsb,
                error_note=f"{_UNQUANTIZED} (proof: sim/golden/fixed/exact.predicted_error_bound_lsb)",
                reference=exact, faithful_widths=fixed_exact.faithful_widths))
register(Models("lee", rotation_fixed=fixed_lee.rotation_fixed,
                illumination_fixed=fixed_lee.illumination_fixed,
                encode=quantize_pixels, from_angle_codes=_same_codes,
                predicted_error_bound_lsb=fixed_lee.predicted_error_bound_lsb,
                error_note=("lee's geometric approximations: no width bounds the diffuse error "
                            "vs float64 below the full range (measured by bumprtl bench float64, "
                            "bench lee-widths)"),
                reference=lee_corrected, other_references=(lee_printed,)))
register(Models("peercy", **_PEERCY))
# Ernst's per-pixel work is Peercy's (rtl/methods.py): the same models.
register(Models("ernst", **_PEERCY))
register(Models("kim", rotation_fixed=fixed_kim.rotation_fixed,
                illumination_fixed=fixed_kim.illumination_fixed,
                encode=quantize_pixels, from_angle_codes=_same_codes,
                predicted_error_bound_lsb=fixed_kim.predicted_error_bound_lsb,
                error_note=f"{_UNQUANTIZED} (proof: sim/golden/fixed/kim.predicted_error_bound_lsb)",
                reference=kim))

# One models' record per hardware record (a method added later registers its models right
# after its hardware, tests/tools/toy_method.py; tests/rtl/test_methods.py checks the two
# registries name the same methods).
if [n for n in MODELS if n not in hardware.METHODS]:
    raise ImportError(f"sim/golden/methods.py has models for {', '.join(MODELS)}; the hardware "
                      f"registry (rtl/methods.py) lists {', '.join(hardware.METHODS)}")

METHODS = MODELS        # the joined view: name -> models record answering for its hardware


def get(name) -> Models:
    """The joined record of method ``name``; a :class:`ConfigError` naming ``method`` and
    the allowed names if there is none (or if its models are not registered)."""
    hardware.get(name)
    if name not in MODELS:
        raise ConfigError(f"method {name!r} has hardware (rtl/methods.py) but no models' "
                          f"record (sim/golden/methods.py register)", "method")
    return MODELS[name]


# --- The golden models of ``cfg.method``: one entry point for tests, testbenches, benches ---

def rotation_fixed(codes, cfg: Config):
    """The rotation unit's output fields (flattened names) from its input codes."""
    return get(cfg.method).rotation_fixed(codes, cfg)


def illumination_fixed(rot, cfg: Config):
    """The illumination unit's output (ndotl, ndoth, diffuse, specular, color) from the
    rotation fields."""
    return get(cfg.method).illumination_fixed(rot, cfg)


def datapath_fixed(codes, cfg: Config):
    """Rotation then illumination: :meth:`Models.datapath_fixed` of ``cfg.method``."""
    return get(cfg.method).datapath_fixed(codes, cfg)


def encode_pixels(px: PixelInputs, cfg: Config):
    """Float64 pixels -> the input codes of ``cfg.method``'s rotation unit: binary angles
    for the polar methods (exact, lee, kim), Cartesian components for Peercy and Ernst
    (what a Cartesian rasterizer would interpolate)."""
    return get(cfg.method).encode(px, cfg)
