# Emission, placement and the board flow. Amaranth's RTLIL back end writes memory contents
# through gen/flow/meminit.py's faster writer (the same bytes).
from bumprtl.gen.flow.meminit import install as _install_meminit

_install_meminit()
