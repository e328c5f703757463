"""A toy method added the way docs/contributing.md ("Adding a method") says, for
tests/test_add_a_method.py: imported first (``python -m pytest -p tests.tools.toy_method``,
or ``import tests.tools.toy_method`` before anything else), it registers method ``toy``.

Steps 1-3 (RTL, bit-exact model, float64 reference) reuse the exact method's modules, so the
toy builds real hardware and has real models; step 4 is the two registry records, the
hardware's (rtl/methods.py) and the models' (sim/golden/methods.py), joined by the name.
Nothing else is edited: every list of methods must pick it up from the registry.
"""

from bumprtl.rtl import methods as hardware
from bumprtl.sim.golden.fixed import exact as fixed_exact
from bumprtl.sim.golden.fixed.common import quantize_pixels
from bumprtl.sim.golden.float.exact import exact

NAME = "toy"

hardware.register(hardware.Method(
    NAME, "toy method (the exact datapath under another name)", baseline=False,
    table1_column=7, rotation_path="bumprtl.rtl.exact:ExactRotation",
    illumination_path="bumprtl.rtl.exact:ExactIllumination",
    layout_path="bumprtl.rtl.exact:rotated_layout", cartesian=False, rotates_normal=False))

from bumprtl.sim.golden import methods as models  # noqa: E402  (after the hardware record)


def toy(px, cfg):
    """The toy's float64 reference (its name is its FLOAT_MODELS and render name)."""
    return exact(px, cfg)


models.register(models.Models(
    NAME, rotation_fixed=fixed_exact.rotation_fixed,
    illumination_fixed=fixed_exact.illumination_fixed, encode=quantize_pixels,
    from_angle_codes=lambda codes, cfg: codes,
    predicted_error_bound_lsb=fixed_exact.predicted_error_bound_lsb,
    error_note="the exact method's bound (sim/golden/fixed/exact.predicted_error_bound_lsb)",
    reference=toy))
