"""gen/flow/meminit.py: the faster writer of memory contents gives Amaranth's own bytes."""

import pytest
from amaranth.back import rtlil
from amaranth.hdl import Module, signed, unsigned
from amaranth.lib.memory import Memory

from bumprtl.gen.flow import meminit


def _design(shapes):
    """A module reading every memory of ``shapes`` (shape, init), and its ports."""
    m, ports = Module(), []
    for k, (shape, init) in enumerate(shapes):
        mem = Memory(shape=shape, depth=len(init), init=init)
        m.submodules[f"mem{k}"] = mem
        port = mem.read_port()
        ports += [port.addr, port.data]
    return m, ports


def _both(design_of):
    """The RTLIL text of a fresh design with Amaranth's writer, then with ours."""
    saved = rtlil.ModuleEmitter.emit_memory
    try:
        rtlil.ModuleEmitter.emit_memory = meminit._ORIGINAL
        m, ports = design_of()
        theirs = rtlil.convert(m, name="top", ports=ports, emit_src=False)
        rtlil.ModuleEmitter.emit_memory = meminit._emit_memory
        m, ports = design_of()
        ours = rtlil.convert(m, name="top", ports=ports, emit_src=False)
    finally:
        rtlil.ModuleEmitter.emit_memory = saved
    return theirs, ours


SHAPES = [
    (unsigned(17), [0, 1, 2**16, 2**17 - 1, 12345, 0x1F0F0]),      # a sine ROM's words
    (signed(9), [-256, -1, 0, 1, 255, -77, 3]),                    # negative words
    (unsigned(1), [1, 0, 0, 1, 1]),                                 # one bit wide
    (unsigned(70), [2**69 + 5, 3, 0, 2**70 - 1]),                   # wider than a machine word
    (unsigned(8), [0x5A]),                                          # one word
    (unsigned(12), [0] * 9),                                        # all zero
]


@pytest.mark.parametrize("k", range(len(SHAPES)))
def test_each_shape_gives_amaranths_own_bytes(k):
    theirs, ours = _both(lambda: _design([SHAPES[k]]))
    assert "$meminit_v2" in theirs
    assert ours == theirs


@pytest.mark.parametrize("width", [8, 0])
def test_a_ram_without_contents_or_of_no_width_gives_amaranths_own_bytes(width):
    """A RAM written at run time (contents all zero) and a zero-width memory (no constant
    at all: Amaranth's own path), same bytes."""
    def ram():
        m = Module()
        m.submodules.mem = mem = Memory(shape=unsigned(width), depth=4, init=[])
        w, r = mem.write_port(), mem.read_port()
        return m, [w.addr, w.data, w.en, r.addr, r.data]
    theirs, ours = _both(ram)
    assert ours == theirs


def test_another_amaranth_keeps_its_own_writer(monkeypatch):
    monkeypatch.setattr(rtlil.ModuleEmitter, "emit_memory", meminit._ORIGINAL)
    monkeypatch.setattr(meminit, "AMARANTH_VERSION", "0.6.0")
    assert meminit.install() is False
    assert rtlil.ModuleEmitter.emit_memory is meminit._ORIGINAL


def test_a_design_of_several_memories_gives_amaranths_own_bytes():
    theirs, ours = _both(lambda: _design(SHAPES))
    assert ours == theirs


def test_the_constant_puts_word_0_bit_0_last():
    # words 1 and 2 of 2 bits: 0b10 then 0b01, most significant word first in the string
    assert meminit._init_constant([1, 2], 2) == "4'1001"
    assert meminit._init_constant([-1], 3) == "3'111"


def test_installed_on_the_pinned_amaranth():
    import bumprtl.gen.flow  # noqa: F401  (installs it)
    assert meminit.AMARANTH_VERSION in meminit.SUPPORTED
    assert meminit.installed()
