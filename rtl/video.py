"""Video timing for the board top (docs/board.md): the modes and the raster generator.

A :class:`VideoMode` is one line of the VESA table: active, front porch, sync and back
porch per axis, the sync polarities and the pixel clock. :data:`MODES` holds the modes
``bumprtl board`` accepts: ``640x480`` (VESA DMT 640 x 480 @ 60 Hz: 25.175 MHz nominal,
run at 25 MHz, h 640/16/96/48, v 480/10/2/33, both syncs negative), ``1280x720`` (CEA-861
720p60: 74.25 MHz nominal, run at the PLL's 25 / 7 x 104 / 5 MHz, h 1280/110/40/220, v 720/5/5/20,
both syncs positive) and ``test`` (32 x 24
with short blanking, the reduced mode the frame check in ``make test`` simulates; not a
monitor mode).

:class:`VideoTiming` counts the raster: ``x`` (0 .. h_total - 1) and ``y``; a line runs
active, front porch, sync, back porch; ``de`` is high on active pixels; ``hsync``/``vsync``
are the sync levels on the wire (low during the pulse for a negative sync). It starts at
the first line of the vertical front porch, so the pixel source has the vertical blanking
to fill its buffer before the first active pixel.
"""

from dataclasses import dataclass

from amaranth.hdl import Elaboratable, Module, Signal

from bumprtl.rtl.config import BumpError

__all__ = ["VideoMode", "MODES", "get_mode", "VideoTiming"]


@dataclass(frozen=True)
class VideoMode:
    name: str
    h_active: int
    h_front: int
    h_sync: int
    h_back: int
    v_active: int
    v_front: int
    v_sync: int
    v_back: int
    pixel_hz: float              # the clock the board runs
    nominal_hz: float            # the standard's
    h_negative: bool = True
    v_negative: bool = True
    zoom: int = 0                # screen pixels per texel: 2**zoom (rtl/board.texel_coords)

    @property
    def h_total(self):
        return self.h_active + self.h_front + self.h_sync + self.h_back

    @property
    def v_total(self):
        return self.v_active + self.v_front + self.v_sync + self.v_back

    @property
    def frame_clocks(self):
        return self.h_total * self.v_total

    @property
    def pixels(self):
        return self.h_active * self.v_active


MODES = {
    "640x480": VideoMode("640x480", 640, 16, 96, 48, 480, 10, 2, 33, 25e6, 25.175e6, zoom=1),
    # CEA-861 VIC 4: 74.25 MHz nominal; the ECP5 PLL from the ULX3S's 25 MHz makes the
    # shift clock 25 / 7 x 104 MHz (rtl/board.pll_dividers), 0.05 % above 5 x 74.25
    "1280x720": VideoMode("1280x720", 1280, 110, 40, 220, 720, 5, 5, 20, 25e6 / 7 * 104 / 5,
                          74.25e6, h_negative=False, v_negative=False, zoom=1),
    "test": VideoMode("test", 32, 4, 8, 4, 24, 2, 2, 2, 25e6, 25e6, zoom=0),
}


def get_mode(name):
    if name not in MODES:
        raise BumpError(f"mode must be one of {', '.join(MODES)}, got {name!r}", "mode")
    return MODES[name]


class VideoTiming(Elaboratable):
    """The raster counters (registers) of ``mode`` in the ``sync`` (pixel) domain and
    ``de``/``hsync``/``vsync`` decoded from them: ``x``, ``y`` and the three outputs describe
    the same pixel (the TMDS encoder registers them)."""

    def __init__(self, mode: VideoMode):
        self.mode = mode
        self.x = Signal(range(mode.h_total), name="x")
        self.y = Signal(range(mode.v_total), init=mode.v_active, name="y")
        self.de = Signal()
        self.hsync = Signal(init=int(mode.h_negative))
        self.vsync = Signal(init=int(mode.v_negative))

    def elaborate(self, platform):
        m, md = Module(), self.mode
        x, y = self.x, self.y
        with m.If(x == md.h_total - 1):
            m.d.sync += x.eq(0)
            with m.If(y == md.v_total - 1):
                m.d.sync += y.eq(0)
            with m.Else():
                m.d.sync += y.eq(y + 1)
        with m.Else():
            m.d.sync += x.eq(x + 1)
        hs0, vs0 = md.h_active + md.h_front, md.v_active + md.v_front
        m.d.comb += [
            self.de.eq((x < md.h_active) & (y < md.v_active)),
            self.hsync.eq(((x >= hs0) & (x < hs0 + md.h_sync)) ^ md.h_negative),
            self.vsync.eq(((y >= vs0) & (y < vs0 + md.v_sync)) ^ md.v_negative),
        ]
        return m
