"""The method registry: one :class:`Method` record per method, everything that differs
between methods in one place.

A method is its hardware (a rotation, or setup, Component and an illumination Component;
rtl/exact.py, rtl/lee.py, rtl/baselines/<name>.py), its bit-exact golden models
(sim/golden/fixed/<name>.py: ``rotation_fixed``, ``illumination_fixed``, ``encode`` when its
inputs are not binary angles, ``predicted_error_bound_lsb``), its float64 reference
(sim/golden/float/<name>.py) and a few facts (title, Table 1 baseline or not, whether
lights can share its rotated normal, why the FPGA flow does not place it). Everything
that depends on the method reads it from here: ``rotation.VectorRotation`` and
``illumination.Illumination``, the golden dispatch below, the scene checks
(rtl/scene.py), the emitter's sidecar (gen/flow/units.py), the stress bench, the sweep,
the Table 1 and FPGA reports, the fixed-point render and the tests.

Adding a method: its RTL module, its golden module(s), one entry in :data:`METHODS` and its
name in ``config.METHOD_NAMES`` (Config validates against those names without importing
this module, which imports the datapaths, which import Config).

This module imports the RTL and golden modules; none of them imports it back.
"""

from dataclasses import dataclass
from typing import Callable, Optional

from bumprtl.rtl import exact as rtl_exact
from bumprtl.rtl import lee as rtl_lee
from bumprtl.rtl.baselines.ernst import ErnstIllumination, ErnstRotation
from bumprtl.rtl.baselines.kim import KimIllumination, KimRotation
from bumprtl.rtl.baselines.peercy import PeercyIllumination, PeercyRotation, setup_output_layout
from bumprtl.rtl.config import METHOD_NAMES, Config, ConfigError
from bumprtl.rtl.exact import ExactIllumination, ExactRotation
from bumprtl.rtl.lee import LeeIllumination, LeeRotation
from bumprtl.sim.golden.common import PixelInputs
from bumprtl.sim.golden.fixed import ernst as fixed_ernst
from bumprtl.sim.golden.fixed import exact as fixed_exact
from bumprtl.sim.golden.fixed import kim as fixed_kim
from bumprtl.sim.golden.fixed import lee as fixed_lee
from bumprtl.sim.golden.fixed import peercy as fixed_peercy
from bumprtl.sim.golden.fixed.common import quantize_pixels
from bumprtl.sim.golden.float.ernst import ernst
from bumprtl.sim.golden.float.exact import exact
from bumprtl.sim.golden.float.kim import kim
from bumprtl.sim.golden.float.lee import lee_corrected
from bumprtl.sim.golden.float.peercy import peercy

__all__ = ["Method", "METHODS", "PER_PIXEL", "BASELINES", "get", "rotation_fixed",
           "illumination_fixed", "datapath_fixed", "encode_pixels"]


@dataclass(frozen=True)
class Method:
    """What one method is, builds and is checked against.

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
    rotation, illumination : type
        The ``wiring.Component`` classes, ``cls(cfg, target=None)``: the rotation (Table 1's
        setup) and the illumination datapath.
    rotated_layout : callable
        ``cfg -> data.Layout``: the rotation's output payload = the illumination's input.
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
    cartesian : bool
        The inputs (and a bump map's N') are Cartesian components, not binary angles.
    rotates_normal : bool
        The rotation turns N' into N's frame once (n'') and keeps each vector's terms apart
        from it, instead of rotating L and H into tangent space. Only such a method lets a
        scene have a flat bump map (n'' rotated once per polygon) or several lights (they
        share the one n''); the pipeline then builds the vectors' terms with
        ``rtl/exact.vector_terms`` (``pipeline.VectorTerms``) and the polygon's n'' with
        ``sim/golden/fixed/exact.rotation_fixed``, the exact method's.
    predicted_error_bound_lsb : callable
        ``(cfg, channel="diffuse", lights=1) -> int``: the proven error bound of one output
        channel (``diffuse``, ``specular``, ``color``, ``blend``) against float64, 8-bit LSB.
    error_note : str
        What the bound means and where it is proved or measured (the emitter's sidecar).
    reference : callable or None
        The float64 model ``(PixelInputs, cfg) -> Result`` (sim/golden/float/).
    not_placed : str or None
        Why the ECP5 flow (gen/flow/fpga.py) does not place this method's units; None: it
        is placed.
    faithful_widths : callable or None
        ``(cfg) -> (angle_bits, frac_bits) or None``: the narrowest widths at which the
        method's bound proves every output channel within 1 LSB of float64 end to end (the
        sidecar's ``faithful_widths``). None here: not searched (lee: its approximations, not
        its widths, set the error; the baselines are measured, not tuned).
    """

    name: str
    title: str
    baseline: bool
    table1_column: int
    rotation: type
    illumination: type
    rotated_layout: Callable
    rotation_fixed: Callable
    illumination_fixed: Callable
    encode: Callable
    from_angle_codes: Callable
    cartesian: bool
    rotates_normal: bool
    predicted_error_bound_lsb: Callable
    error_note: str
    reference: Optional[Callable] = None
    not_placed: Optional[str] = None
    faithful_widths: Optional[Callable] = None

    @property
    def per_pixel(self):
        """A method scenes and pipelines use (not a Table 1 baseline)."""
        return not self.baseline

    def datapath_fixed(self, codes, cfg: Config):
        """Rotation then illumination, bit-exact: the rotation fields, ndotl, ndoth and the
        8-bit diffuse, specular, color."""
        rot = self.rotation_fixed(codes, cfg)
        return {**rot, **self.illumination_fixed(rot, cfg)}


def _same_codes(codes, cfg: Config):
    """The polar methods' inputs are the binary-angle codes themselves."""
    return codes


_UNQUANTIZED = "the largest over the channels (error_bound_lsb; each channel in error_bounds_lsb) vs float64 on unquantized inputs"
_CARTESIAN_NOTE = (f"{_UNQUANTIZED}, Cartesian input codes from "
                   "sim/golden/fixed/peercy.encode "
                   "(proof: sim/golden/fixed/peercy.predicted_error_bound_lsb)")
METHODS = {m.name: m for m in (
    Method("exact", "exact angular method", baseline=False, table1_column=6,
           rotation=ExactRotation, illumination=ExactIllumination,
           rotated_layout=rtl_exact.rotated_layout,
           rotation_fixed=fixed_exact.rotation_fixed,
           illumination_fixed=fixed_exact.illumination_fixed,
           encode=quantize_pixels, from_angle_codes=_same_codes, cartesian=False,
           rotates_normal=True,
           predicted_error_bound_lsb=fixed_exact.predicted_error_bound_lsb,
           error_note=f"{_UNQUANTIZED} (proof: sim/golden/fixed/exact.predicted_error_bound_lsb)",
           reference=exact, faithful_widths=fixed_exact.faithful_widths),
    Method("lee", "Lee et al. 2003 (errata fixed)", baseline=False, table1_column=5,
           rotation=LeeRotation, illumination=LeeIllumination,
           rotated_layout=rtl_lee.rotated_layout,
           rotation_fixed=fixed_lee.rotation_fixed,
           illumination_fixed=fixed_lee.illumination_fixed,
           encode=quantize_pixels, from_angle_codes=_same_codes, cartesian=False,
           rotates_normal=False,
           predicted_error_bound_lsb=fixed_lee.predicted_error_bound_lsb,
           error_note=("lee's geometric approximations: no width bounds the diffuse error vs "
                       "float64 below the full range (measured by bumprtl bench float64, bench "
                       "lee-widths)"),
           reference=lee_corrected),
    Method("peercy", "Peercy et al. 1997", baseline=True, table1_column=1,
           rotation=PeercyRotation, illumination=PeercyIllumination,
           rotated_layout=setup_output_layout,
           rotation_fixed=fixed_peercy.rotation_fixed,
           illumination_fixed=fixed_peercy.illumination_fixed,
           encode=fixed_peercy.encode, from_angle_codes=fixed_peercy.from_angle_codes,
           cartesian=True, rotates_normal=False,
           predicted_error_bound_lsb=fixed_peercy.predicted_error_bound_lsb,
           error_note=_CARTESIAN_NOTE, reference=peercy),
    Method("ernst", "Ernst et al. 1998", baseline=True, table1_column=4,
           rotation=ErnstRotation, illumination=ErnstIllumination,
           rotated_layout=setup_output_layout,
           rotation_fixed=fixed_ernst.rotation_fixed,
           illumination_fixed=fixed_ernst.illumination_fixed,
           encode=fixed_ernst.encode, from_angle_codes=fixed_ernst.from_angle_codes,
           cartesian=True, rotates_normal=False,
           predicted_error_bound_lsb=fixed_ernst.predicted_error_bound_lsb,
           error_note=_CARTESIAN_NOTE, reference=ernst),
    Method("kim", "Kim et al. 2001", baseline=True, table1_column=3,
           rotation=KimRotation, illumination=KimIllumination,
           rotated_layout=rtl_lee.rotated_layout,
           rotation_fixed=fixed_kim.rotation_fixed,
           illumination_fixed=fixed_kim.illumination_fixed,
           encode=quantize_pixels, from_angle_codes=_same_codes, cartesian=False,
           rotates_normal=False,
           predicted_error_bound_lsb=fixed_kim.predicted_error_bound_lsb,
           error_note=f"{_UNQUANTIZED} (proof: sim/golden/fixed/kim.predicted_error_bound_lsb)",
           reference=kim),
)}

if tuple(METHODS) != METHOD_NAMES:
    raise ImportError(f"rtl/methods.py registers {', '.join(METHODS)} but config.METHOD_NAMES "
                      f"is {', '.join(METHOD_NAMES)}: keep the two in the same order")

PER_PIXEL = tuple(n for n, m in METHODS.items() if m.per_pixel)    # scenes and pipelines
BASELINES = tuple(n for n, m in METHODS.items() if m.baseline)     # Table 1 cost comparison


def get(name) -> Method:
    """The record of method ``name``; a :class:`ConfigError` naming ``method`` and the
    allowed names if there is none."""
    if name not in METHODS:
        raise ConfigError(f"method must be one of {', '.join(METHODS)}, got {name!r}")
    return METHODS[name]


# --- The golden models of ``cfg.method``: one entry point for tests, testbenches, benches ---

def rotation_fixed(codes, cfg: Config):
    """The rotation unit's output fields (flattened names) from its input codes."""
    return get(cfg.method).rotation_fixed(codes, cfg)


def illumination_fixed(rot, cfg: Config):
    """The illumination unit's output (ndotl, ndoth, diffuse, specular, color) from the
    rotation fields."""
    return get(cfg.method).illumination_fixed(rot, cfg)


def datapath_fixed(codes, cfg: Config):
    """Rotation then illumination: :meth:`Method.datapath_fixed` of ``cfg.method``."""
    return get(cfg.method).datapath_fixed(codes, cfg)


def encode_pixels(px: PixelInputs, cfg: Config):
    """Float64 pixels -> the input codes of ``cfg.method``'s rotation unit: binary angles
    for the polar methods (exact, lee, kim), Cartesian components for Peercy and Ernst
    (what a Cartesian rasterizer would interpolate)."""
    return get(cfg.method).encode(px, cfg)
