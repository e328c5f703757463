"""Bit-exact int64 model of the Ernst baseline (rtl/baselines/ernst.py): the same hardware
as Peercy's (the difference is how the bump map is built), so the same model, re-exported
under the names every method's golden model has (``rotation_fixed``, ``illumination_fixed``,
``encode``, ``predicted_error_bound_lsb``)."""

from bumprtl.sim.golden.fixed.peercy import (encode, from_angle_codes, illumination_fixed,
                                             input_keys, predicted_error_bound_lsb, rotation_fixed)

__all__ = ["rotation_fixed", "illumination_fixed", "encode", "from_angle_codes", "input_keys",
           "predicted_error_bound_lsb"]
