"""The bulk path's payload codec: stimulus field arrays checked against the unit's sidecar
and packed into the stimulus file, and the output file unpacked into field arrays.

The files are binary: ``$readmemh`` parses about 1 us per 104-bit word in Verilator,
``$fread`` of big-endian bytes a tenth of that; ``$fwrite("%u")`` writes 32-bit
little-endian limbs, byte-identical on Icarus and Verilator (an X would read as 0 and fail
the golden check). sim/tb/bulk_dpi.cpp reads and writes the same bytes.
"""

import numpy as np

from bumprtl.rtl.config import BumpError

__all__ = ["check_stimulus", "encode_words", "decode_words"]


def _fields(meta, port):
    return {k: tuple(v) for k, v in meta.fields_of(port).items()}


def check_stimulus(meta, inputs, widths=None):
    """Refuse stimulus arrays that do not match the unit's sidecar, before any build.

    ``inputs``: ``{field: integer array}``, every input payload field of the sidecar (tag
    included) and no other, all of one length; ``widths`` (optional): ``{field: bits}``
    the arrays were made for. Raises :class:`BumpError` naming the field and both widths.
    """
    unit = f"{meta.unit}.json"
    fields = _fields(meta, "i__payload")
    for name in inputs:
        if name not in fields:
            raise BumpError(f"stimulus field {name!r} is not an input field of {unit} "
                            f"(i__payload fields: {', '.join(fields)})")
    for name in fields:
        if name not in inputs:
            raise BumpError(f"stimulus lacks field {name!r} of {unit} "
                            f"(i__payload field {name!r}: {fields[name][1]} bits)")
    lengths = {len(np.asarray(v).reshape(-1)) for v in inputs.values()}
    if len(lengths) > 1:
        raise BumpError(f"stimulus fields differ in length: {sorted(lengths)}")
    for name, (_off, width, signed) in fields.items():
        kind = "signed" if signed else "unsigned"
        if widths and name in widths and int(widths[name]) != width:
            raise BumpError(f"stimulus field {name!r} is {int(widths[name])} bits wide, "
                            f"{unit} i__payload field {name!r} is {width} bits ({kind})")
        arr = np.asarray(inputs[name])
        if arr.dtype.kind not in "iub":
            raise BumpError(f"stimulus field {name!r} must be an integer array, got {arr.dtype}")
        if arr.size == 0:
            continue
        lo, hi = int(arr.min()), int(arr.max())
        fmin, fmax = (-(1 << (width - 1)), (1 << (width - 1)) - 1) if signed else (0, (1 << width) - 1)
        if lo < fmin or hi > fmax:
            need = _bits_needed(lo, hi, signed)
            raise BumpError(f"stimulus field {name!r} needs {need} bits (values {lo}..{hi}), "
                            f"{unit} i__payload field {name!r} is {width} bits ({kind}, "
                            f"{fmin}..{fmax})")
    return lengths.pop() if lengths else 0


def _bits_needed(lo, hi, signed):
    if signed or lo < 0:
        return max(int(lo).bit_length() + (lo < 0), int(hi).bit_length() + 1, 1)
    return max(int(hi).bit_length(), 1)


def _limbs(fields, width, arrays):
    """Field arrays -> the packed words as 32-bit limbs ``(limbs, n)`` (uint64, least
    significant limb first); negative values are two's complement."""
    n = len(next(iter(arrays.values()))) if arrays else 0
    limbs = np.zeros(((width + 31) // 32, n), np.uint64)
    for name, (off, w, _signed) in fields.items():
        if w > 63:
            raise BumpError(f"payload field {name!r} is {w} bits; the bulk codec takes <= 63")
        v = np.asarray(arrays[name]).astype(np.int64).reshape(-1).view(np.uint64) & np.uint64((1 << w) - 1)
        done = 0
        while done < w:
            pos = off + done
            k, sh = divmod(pos, 32)
            take = min(32 - sh, w - done)
            limbs[k] |= ((v >> np.uint64(done)) & np.uint64((1 << take) - 1)) << np.uint64(sh)
            done += take
    return limbs


def encode_words(fields, width, arrays):
    """Pack field arrays into the stimulus file of a ``width``-bit payload, vectorised, as
    ``$fread`` reads a memory: ceil(width / 8) bytes per word, most significant first."""
    limbs = _limbs(fields, width, arrays)
    nbytes = (width + 7) // 8
    out = np.empty((limbs.shape[1], nbytes), np.uint8)
    for b in range(nbytes):
        j = nbytes - 1 - b                      # byte index from the least significant
        out[:, b] = ((limbs[j // 4] >> np.uint64(8 * (j % 4))) & np.uint64(255)).astype(np.uint8)
    return out.tobytes()


def decode_words(fields, width, data):
    """The output file (``$fwrite("%u")`` per word: 32-bit limbs, least significant first,
    each little-endian, on Icarus and Verilator alike) -> ``{field: int64 array}``, signed
    fields sign-extended."""
    nlimbs = (width + 31) // 32
    if len(data) % 4:               # np.frombuffer's own ValueError names no file or word
        raise AssertionError(f"output file is not whole {4 * nlimbs}-byte words ({len(data)} bytes)")
    raw = np.frombuffer(data, "<u4")
    if raw.size % nlimbs:
        raise AssertionError(f"output file is not whole {4 * nlimbs}-byte words ({len(data)} bytes)")
    limbs = raw.reshape(-1, nlimbs).T.astype(np.uint64)
    n = limbs.shape[1]
    out = {}
    for name, (off, w, signed) in fields.items():
        v = np.zeros(n, np.uint64)
        done = 0
        while done < w:
            pos = off + done
            k, sh = divmod(pos, 32)
            take = min(32 - sh, w - done)
            v |= ((limbs[k] >> np.uint64(sh)) & np.uint64((1 << take) - 1)) << np.uint64(done)
            done += take
        s = v.astype(np.int64)
        if signed and w:
            s = np.where(s >> (w - 1) & 1, s - (1 << w), s)
        out[name] = s
    return out
