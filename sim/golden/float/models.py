"""The float64 golden models by name: fn(px: PixelInputs, cfg: Config) -> Result.

``conventional`` (the float64 Phong reference every method is measured against), then the
float64 references of the method registry (sim/golden/methods.py: each method's
``other_references`` and ``reference``, by its function name, in Table 1's column order),
each model once: a method whose models are another's (Ernst's are Peercy's) adds none.
"""

from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.methods import MODELS

__all__ = ["FLOAT_MODELS"]

FLOAT_MODELS = {"conventional": conventional}
for _m in sorted(MODELS.values(), key=lambda m: m.table1_column):
    for _f in (*_m.other_references, *([_m.reference] if _m.reference else [])):
        FLOAT_MODELS.setdefault(_f.__name__, _f)
