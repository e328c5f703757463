"""Refusals of sim/ that no other test reached (docs/coverage.md's per-branch list): a
geometry the scenes do not know, a payload value that does not fit its field, a field the
bulk codec cannot carry, an output file that is not whole words."""

import numpy as np
import pytest

from bumprtl.rtl.config import BumpError
from bumprtl.sim.scenes import GEOMETRIES, texel_coordinates
from bumprtl.sim.tb.bulk_codec import decode_words, encode_words
from bumprtl.sim.tb.stream import pack, unpack


def test_texel_coordinates_refuse_an_unknown_geometry():
    u, v, mask = texel_coordinates(GEOMETRIES[0], 8, 8)
    assert u.shape == v.shape == mask.shape == (8, 8)
    with pytest.raises(BumpError, match="geometry must be one of .*got 'cone'"):
        texel_coordinates("cone", 8, 8)


FIELDS = {"a": (0, 4, False), "b": (4, 3, True)}


def test_pack_refuses_a_value_outside_its_field():
    word = pack(FIELDS, {"a": 15, "b": -4})
    assert unpack(FIELDS, word) == {"a": 15, "b": -4}
    for values, name in (({"a": 16}, "a = 16"), ({"b": 4}, "b = 4"), ({"b": -5}, "b = -5"),
                         ({"a": -1}, "a = -1")):
        with pytest.raises(ValueError, match=f"payload field {name} does not fit"):
            pack(FIELDS, values)


def test_bulk_codec_refuses_wide_fields_and_output_files_of_broken_words():
    # the output file: per word its 32-bit limbs, least significant first, little-endian
    got = decode_words(FIELDS, 7, np.array([0x41, 0x3F], "<u4").tobytes())
    assert got["a"].tolist() == [1, 15] and got["b"].tolist() == [-4, 3]
    assert len(encode_words(FIELDS, 7, {"a": np.array([1, 15]), "b": np.array([-4, 3])})) > 0
    with pytest.raises(BumpError, match="payload field 'w' is 64 bits; the bulk codec takes <= 63"):
        encode_words({"w": (0, 64, False)}, 64, {"w": np.array([1])})
    wide = {"w": (0, 40, False)}                      # two limbs a word
    two = np.array([5, 1, 7, 0], "<u4").tobytes()
    assert decode_words(wide, 40, two)["w"].tolist() == [5 + (1 << 32), 7]
    with pytest.raises(AssertionError, match="not whole 8-byte words \\(12 bytes\\)"):
        decode_words(wide, 40, two[:12])
    with pytest.raises(AssertionError, match="not whole 8-byte words \\(13 bytes\\)"):
        decode_words(wide, 40, two[:13])               # a torn last limb: not numpy's error
