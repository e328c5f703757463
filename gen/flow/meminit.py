"""A faster writer of memory contents for Amaranth's RTLIL back end, same bytes out.

Amaranth 0.5's ``rtlil`` back end writes a memory's initial contents (the ``DATA`` of its
``$meminit_v2`` cell) by making one netlist constant per bit and joining them again into one
binary constant: one Python object per bit of every table, which dominates the emission of
the scenes with large sine ROMs (the ``full`` scene's).
:func:`install` replaces that one method of the back end (``ModuleEmitter.emit_memory``) by
one that formats the words straight into the same constant, so every emitted file keeps its
bytes (tests/gen/flow/test_meminit.py compares the two writers' output). It is installed
only on the Amaranth version it was written against; on any other the back end is left as
it is.
"""

from amaranth import __version__ as AMARANTH_VERSION
from amaranth.back import rtlil
from amaranth.hdl import _nir

__all__ = ["install", "installed", "SUPPORTED"]

SUPPORTED = ("0.5.10",)
_ORIGINAL = rtlil.ModuleEmitter.emit_memory


def _init_constant(init, width):
    """The ``DATA`` sigspec Amaranth's ``sigspec`` gives for ``init``'s bits (word 0's bit 0
    last in the string): ``"<depth * width>'<bits, most significant first>"``."""
    mask = (1 << width) - 1
    bits = "".join(format(row & mask, f"0{width}b") for row in reversed(init))
    return f"{len(bits)}'{bits}"


def _emit_memory(self, cell_idx, cell):
    if not cell.init or not cell.width:                  # Amaranth's own path: no constant
        return _ORIGINAL(self, cell_idx, cell)
    memory_info = self.memories[cell_idx]
    self.builder.cell("$meminit_v2", ports={
        "ADDR": self.sigspec(),
        "DATA": _init_constant(cell.init, cell.width),
        "EN": self.sigspec(_nir.Value.ones(cell.width)),
    }, parameters={
        "MEMID": memory_info.memid,
        "ABITS": 0,
        "WIDTH": cell.width,
        "WORDS": cell.depth,
        "PRIORITY": 0,
    }, src_loc=cell.src_loc)


def installed():
    return rtlil.ModuleEmitter.emit_memory is _emit_memory


def install():
    """Use the faster writer (idempotent); a no-op on an Amaranth other than SUPPORTED."""
    if AMARANTH_VERSION in SUPPORTED:
        rtlil.ModuleEmitter.emit_memory = _emit_memory
    return installed()
