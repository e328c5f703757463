"""FlashLoader: copies the map's image from the board's SPI flash into the SDRAM at power-up
(docs/flash.md).

The flash is read with the JEDEC READ command (0x03): CS# low, the opcode and a 24-bit byte
address shifted in most significant bit first, then data bytes, most significant bit first,
for as long as SCLK runs with CS# low (the address counts up by itself). SPI mode 0: SCLK
idles low, the flash samples MOSI on SCLK's rising edge and shifts MISO out on its falling
edge; the loader samples MISO as it raises SCLK, ``half_period - 1`` clocks after the
falling edge that shifted it out: the flash's clock-to-output time and the board's delays
must fit in that (one clock at the default 2, 10 ns at 100 MHz). SCLK is the clock over
``2 * half_period``. The loader stops SCLK low (CS# held
low) whenever the bytes it has read wait for the AXI write channel: a flash is a static
design, a pause in SCLK's low phase is allowed at any bit.

The bytes go to the memory in AXI4 write bursts of ``burst`` beats of ``data_bits`` from
``base``, in flash order, byte k of a beat at bits 8k .. 8k + 7 (little-endian, the byte
order of the map's image, rtl/cache.tiled_image). A burst's AW is sent (AWVALID held until
AWREADY, its payload stable) before its first W beat; WLAST marks its last beat; every B
response is taken (BREADY high). ``done`` rises once the last B response is in, ``error``
(sticky) if any BRESP is not OKAY. The copy starts after reset and runs once.
"""

from dataclasses import dataclass

from amaranth.hdl import Cat, Const, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from bumprtl.rtl.config import ConfigError, check_int, check_pow2
from bumprtl.rtl.sdram import axi_write_signature

__all__ = ["FlashConfig", "FlashLoader", "spi_signature", "READ", "FLASH_BYTES_MAX",
           "DATA_BITS"]

READ = 0x03                   # JEDEC READ: opcode, 24-bit address, data
FLASH_BYTES_MAX = 1 << 24     # what a 24-bit address reaches
DATA_BITS = (8, 16, 32, 64)   # the AXI data widths the loader writes


@dataclass(frozen=True)
class FlashConfig:
    """The copy: ``length`` bytes from flash byte ``offset`` to memory byte ``base``.

    Parameters
    ----------
    offset : int
        First flash byte, 0 .. 2**24 - length (a 24-bit READ address).
    length : int
        Bytes to copy, a whole number of bursts (``burst * data_bits / 8`` bytes each).
    base : int
        First memory byte, a multiple of a burst's bytes (no burst crosses a 4 KB page),
        ``base + length <= 2**addr_bits``.
    addr_bits, data_bits : int
        The AXI port's address width (8 .. 32) and data width (8, 16, 32 or 64).
    burst : int
        Beats a burst, a power of two, 1 .. 256, at most 4096 bytes.
    half_period : int
        Clock cycles of each SCLK phase, 2 .. 64 (SCLK = clock / (2 half_period)); MISO is
        sampled ``half_period - 1`` clocks after SCLK falls.
    """

    offset: int
    length: int
    base: int = 0
    addr_bits: int = 25
    data_bits: int = 16
    burst: int = 8
    half_period: int = 2

    def __post_init__(self):
        check_int("addr_bits", self.addr_bits, 8, 32)
        if self.data_bits not in DATA_BITS:
            raise ConfigError(f"data_bits must be one of {', '.join(map(str, DATA_BITS))}, got "
                              f"{self.data_bits!r}", "data_bits")
        check_pow2("burst", self.burst, 1, min(256, 4096 // self.word_bytes))
        check_int("half_period", self.half_period, 2, 64,
                  "MISO is sampled half_period - 1 clocks after SCLK falls")
        check_int("length", self.length, self.burst_bytes, FLASH_BYTES_MAX,
                  f"a whole number of {self.burst_bytes}-byte bursts")
        if self.length % self.burst_bytes:
            raise ConfigError(f"length = {self.length} must be a whole number of "
                              f"{self.burst_bytes}-byte bursts", "length")
        check_int("offset", self.offset, 0, FLASH_BYTES_MAX - self.length,
                  f"{self.length} bytes from it within the 24-bit address")
        check_int("base", self.base, 0, (1 << self.addr_bits) - self.length,
                  f"{self.length} bytes from it within the {self.addr_bits}-bit address")
        if self.base % self.burst_bytes:
            raise ConfigError(f"base = {self.base} must be a multiple of a burst's "
                              f"{self.burst_bytes} bytes", "base")

    @property
    def word_bytes(self):
        return self.data_bits // 8

    @property
    def burst_bytes(self):
        return self.burst * self.word_bytes

    @property
    def bursts(self):
        return self.length // self.burst_bytes


def spi_signature():
    """The flash's SPI pins, the loader's view."""
    return wiring.Signature({"sclk": Out(1), "cs_n": Out(1), "mosi": Out(1), "miso": In(1)})


class FlashLoader(wiring.Component):
    """The copy of :class:`FlashConfig` (module docstring).

    Members
    -------
    spi : Out(spi_signature())
    axi : Out(axi_write_signature(addr_bits, data_bits))
    done, error : Out(1)
    """

    def __init__(self, cfg: FlashConfig):
        self.cfg = cfg
        super().__init__({"spi": Out(spi_signature()),
                          "axi": Out(axi_write_signature(cfg.addr_bits, cfg.data_bits)),
                          "done": Out(1), "error": Out(1)})

    def elaborate(self, platform):
        m, c = Module(), self.cfg
        spi, axi = self.spi, self.axi
        n_bytes, wb = c.length, c.word_bytes
        cmd_bits = 32
        # SCLK's phase timer: a tick every half_period cycles
        timer = Signal(range(c.half_period), name="half_timer")
        tick = Signal()
        m.d.comb += tick.eq(timer == 0)
        m.d.sync += timer.eq(Mux(tick, c.half_period - 1, timer - 1))

        # one byte read and not yet taken into the word being assembled
        byte, byte_valid = Signal(8, name="byte"), Signal(name="byte_valid")
        shift_in = Signal(8, name="shift_in")
        command = Signal(cmd_bits, name="command", init=(READ << 24) | c.offset)
        edges = Signal(range(cmd_bits + 8 * n_bytes + 1), name="rising_edges")
        reading = edges >= cmd_bits
        at_byte_start = reading & (edges[:3] == 0)       # (edges - 32) % 8 == 0
        m.d.comb += spi.mosi.eq(command[-1])
        sclk, cs_n = Signal(name="sclk"), Signal(name="cs_n", init=1)
        m.d.comb += [spi.sclk.eq(sclk), spi.cs_n.eq(cs_n)]
        total = cmd_bits + 8 * n_bytes
        with m.FSM(name="spi"):
            with m.State("START"):                      # CS# high for a phase after reset
                with m.If(tick):
                    m.d.sync += cs_n.eq(0)
                    m.next = "LOW"
            with m.State("LOW"):                        # MOSI holds its bit
                # a new byte only once the one before it is taken
                with m.If(tick & ~(at_byte_start & byte_valid)):
                    m.d.sync += [sclk.eq(1), edges.eq(edges + 1)]
                    with m.If(reading):
                        m.d.sync += shift_in.eq(Cat(spi.miso, shift_in[:7]))
                        with m.If(edges[:3] == 7):      # the byte's eighth bit
                            m.d.sync += [byte.eq(Cat(spi.miso, shift_in[:7])), byte_valid.eq(1)]
                    m.next = "HIGH"
            with m.State("HIGH"):
                with m.If(tick):
                    m.d.sync += [sclk.eq(0), command.eq(command << 1)]
                    with m.If(edges == total):
                        m.next = "STOP"
                    with m.Else():
                        m.next = "LOW"
            with m.State("STOP"):                       # CS# high after the last falling edge
                with m.If(tick):
                    m.d.sync += cs_n.eq(1)
                    m.next = "IDLE"
            with m.State("IDLE"):
                pass

        # bytes into words, words into W beats behind their burst's AW
        word, have = Signal(c.data_bits, name="word"), Signal(range(wb + 1), name="word_bytes")
        beats = c.bursts * c.burst
        moved = Signal(range(beats + 1), name="beats_moved")
        burst_bits = (c.burst - 1).bit_length()
        w_index = moved >> burst_bits                  # the burst of the next beat
        aw_count = Signal(range(c.bursts + 1), name="aw_accepted")
        b_count = Signal(range(c.bursts + 1), name="b_received")
        awaddr = Signal(c.addr_bits, name="awaddr", init=c.base)
        awvalid, wvalid, wlast = Signal(name="awvalid"), Signal(name="wvalid"), Signal(name="wlast")
        wdata = Signal(c.data_bits, name="wdata")
        with m.If(byte_valid & (have != wb)):
            m.d.sync += [word.word_select(have, 8).eq(byte), have.eq(have + 1), byte_valid.eq(0)]
        w_free = ~wvalid | axi.wready
        move = (have == wb) & w_free & (aw_count > w_index)
        with m.If(wvalid & axi.wready):
            m.d.sync += wvalid.eq(0)
        with m.If(move):
            m.d.sync += [wdata.eq(word), wvalid.eq(1), have.eq(0), moved.eq(moved + 1),
                         wlast.eq(moved[:burst_bits] == c.burst - 1 if burst_bits else 1)]
        with m.If(~awvalid & (aw_count == w_index) & (aw_count < c.bursts)):
            m.d.sync += awvalid.eq(1)
        with m.If(awvalid & axi.awready):
            m.d.sync += [awvalid.eq(0), aw_count.eq(aw_count + 1),
                         awaddr.eq(awaddr + c.burst_bytes)]
        with m.If(axi.bvalid):
            m.d.sync += b_count.eq(b_count + 1)
            with m.If(axi.bresp != 0):
                m.d.sync += self.error.eq(1)
        m.d.comb += [
            axi.awid.eq(0), axi.awaddr.eq(awaddr), axi.awlen.eq(c.burst - 1),
            axi.awsize.eq(Const((wb - 1).bit_length(), 3)), axi.awburst.eq(1),
            axi.awvalid.eq(awvalid),
            axi.wdata.eq(wdata), axi.wstrb.eq(Const((1 << wb) - 1, wb)), axi.wlast.eq(wlast),
            axi.wvalid.eq(wvalid), axi.bready.eq(1),
            self.done.eq(b_count == c.bursts),
        ]
        return m
