"""Timing constraints shipped with the package: ``ecp5.lpf`` (the nextpnr-ecp5 clock) and
``bumprtl.sdc``; read them with ``importlib.resources.files("bumprtl.constraints")``."""
