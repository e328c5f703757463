"""A serial NOR flash as the loader sees it (rtl/flash.py, docs/flash.md), written from the
JEDEC READ command's definition in SPI flash datasheets (e.g. ISSI IS25LP128, the ULX3S's
part family): mode 0, one command per CS# low period, READ (0x03) = opcode, 24-bit address,
then data from that address on, most significant bit first, the address counting up and
wrapping at the end of the array.

:class:`SpiFlash` is stepped once a clock with the pins the loader drives and returns MISO;
it records what it was asked for and every rule broken (``errors``): an opcode other than
READ, SCLK high when CS# falls or rises (mode 0 idles low), an SCLK phase shorter than
``min_phase`` clocks (the part's fastest READ clock), CS# raised inside a byte of the
command.
"""

__all__ = ["SpiFlash", "READ"]

READ = 0x03


class SpiFlash:
    """``image``: the array's bytes; ``min_phase``: the shortest SCLK high or low phase, in
    clocks of the stepping; ``delay``: clocks from the step that sees SCLK fall to the one
    whose MISO carries the next bit (a part's clock-to-output time and the board's wires;
    until then MISO keeps the bit before)."""

    def __init__(self, image, min_phase=1, delay=1):
        self.image = bytes(image)
        self.min_phase, self.delay = min_phase, delay
        self._pending = None       # [clocks left, bit] of a bit on its way to MISO
        self.errors = []
        self.reads = []            # (address, bytes sent) of every READ
        self._cs_n, self._sclk = 1, 0
        self._phase = 0            # clocks since SCLK last changed
        self._miso = 0
        self._bits = 0             # rising edges since CS# fell
        self._shift = 0
        self._addr = None

    def _error(self, text):
        if len(self.errors) < 20:
            self.errors.append(text)

    def step(self, cs_n, sclk, mosi):
        """One clock with these pin values; returns MISO for the next."""
        cs_n, sclk, mosi = int(cs_n), int(sclk), int(mosi)
        if self._pending is not None:
            self._pending[0] -= 1
            if self._pending[0] <= 0:
                self._miso, self._pending = self._pending[1], None
        if cs_n != self._cs_n:
            if self._sclk or sclk:
                self._error(f"CS# {'rose' if cs_n else 'fell'} with SCLK high (mode 0 idles low)")
            if cs_n:                                  # the end of a command
                if 0 < self._bits < 32 or (self._bits > 32 and self._addr is None):
                    self._error(f"CS# rose after {self._bits} bits, inside the command")
                if self._addr is not None:
                    self.reads[-1] = (self.reads[-1][0], (self._bits - 32) // 8)
            else:
                self._bits, self._shift, self._addr, self._miso = 0, 0, None, 0
            self._cs_n = cs_n
        if sclk != self._sclk:
            if self._phase < self.min_phase:
                self._error(f"SCLK phase of {self._phase} clocks, shorter than {self.min_phase}")
            self._phase = 0
            if not cs_n and sclk:                     # rising: sample MOSI
                self._rising(mosi)
            elif not cs_n and self._addr is not None:  # falling, reading: the next bit out
                self._falling()
            self._sclk = sclk
        self._phase += 1
        return self._miso

    def _rising(self, mosi):
        self._bits += 1
        if self._bits <= 32:
            self._shift = (self._shift << 1) | mosi
        if self._bits == 8 and self._shift != READ:
            self._error(f"opcode {self._shift:#04x}: only READ ({READ:#04x}) is modelled")
        if self._bits == 32 and self._shift >> 24 == READ:
            self._addr = self._shift & 0xFFFFFF
            self.reads.append((self._addr, 0))

    def _falling(self):
        k = self._bits - 32                           # data bits sent so far
        byte = self.image[(self._addr + k // 8) % len(self.image)]
        bit = byte >> (7 - k % 8) & 1
        if self.delay:
            self._pending = [self.delay, bit]
        else:
            self._miso = bit
