"""Stall-safe pipeline bookkeeping shared by every unit (DESIGN §5).

The whole pipe advances when the output is empty or being taken,
``adv = ~o.valid | o.ready``; every register, including the ROM read ports, is enabled by
``adv``, so a stall freezes the pipe and never drops a lookup. ``o.valid`` comes straight
from a register and never depends on ``o.ready`` (stream rule 1).
"""

from amaranth.hdl import Signal, Value

__all__ = ["StallPipe"]


class StallPipe:
    """Valid chain and delay lines of a ``depth``-stage pipe from stream ``i`` to ``o``.

    Parameters
    ----------
    m : Module
    i, o : stream interfaces of the enclosing component (``i`` flipped, ``o`` not)
    depth : int
        Number of register stages between ``i`` and ``o`` (the latency).
    """

    def __init__(self, m, i, o, depth):
        if depth < 1:
            raise ValueError(f"pipeline depth must be >= 1, got {depth}")
        self.m = m
        self.depth = depth
        self.adv = Signal(name="adv")
        m.d.comb += [self.adv.eq(~o.valid | o.ready), i.ready.eq(self.adv)]
        self.valid = [i.valid]
        for n in range(1, depth + 1):
            v = Signal(name=f"stage{n}_valid")
            with m.If(self.adv):
                m.d.sync += v.eq(self.valid[-1])
            self.valid.append(v)
        m.d.comb += o.valid.eq(self.valid[depth])

    def register(self, value, name):
        """``value`` delayed by one ``adv``-enabled register."""
        value = Value.cast(value)
        reg = Signal(value.shape(), name=name)
        with self.m.If(self.adv):
            self.m.d.sync += reg.eq(value)
        return reg

    def delay(self, value, stages, name):
        """``value`` delayed by ``stages`` ``adv``-enabled registers (0 returns it as is)."""
        for n in range(stages):
            value = self.register(value, f"{name}_d{n + 1}")
        return value
