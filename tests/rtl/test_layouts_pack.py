"""rtl/layouts.pack and unpack, the one packing of payloads and host words (the benches'
streams, the polygon registers' set-up word of the bulk wrapper and of ``bumprtl vectors``):
each field at its offset in two's complement, a negative field never spilling into the
fields above it."""

from bumprtl.rtl.layouts import pack, unpack

# name -> (offset, width, signed)
FIELDS = {"a": (0, 4, True), "b": (4, 6, False), "c": (10, 3, True)}


def test_a_negative_low_field_leaves_the_fields_above_it():
    # c = -4 -> 0b100, b = 5 -> 0b000101, a = -1 -> 0b1111, written out by hand
    assert pack(FIELDS, {"a": -1, "b": 5, "c": -4}) == 0b100_000101_1111
    assert pack(FIELDS, {"a": -8}) == 0b1000                      # a missing field is 0


def test_unpack_gives_every_value_back():
    for values in ({"a": -1, "b": 5, "c": -4}, {"a": 7, "b": 63, "c": 3}, {"a": -8, "b": 0, "c": -1}):
        assert unpack(FIELDS, pack(FIELDS, values)) == values
