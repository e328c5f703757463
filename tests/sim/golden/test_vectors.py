"""The datapath units' test vectors (sim/golden/vectors.py): payloads as the RTL takes them."""


from bumprtl.rtl.config import Config
from bumprtl.sim.golden.vectors import TINY, as_payloads, concat_codes, edge_codes, random_codes


def test_payloads_number_the_pixels_with_a_tag_that_wraps_at_tag_bits():
    """Payload i carries the input codes of pixel i and the running tag i mod 2**tag_bits
    (the testbenches match outputs to inputs by it); without specular there is no H."""
    cfg = TINY.replace(tag_bits=3)
    codes = concat_codes(random_codes(10, cfg, seed=1), random_codes(10, cfg, seed=2))
    payloads = as_payloads(codes, cfg)
    assert [p["tag"] for p in payloads] == [i % 8 for i in range(20)]
    for i, p in enumerate(payloads):
        assert all(p[k] == codes[k][i] for k in codes)
    plain = as_payloads(codes, cfg.replace(specular=False))
    assert all(not any(k.startswith("h.") for k in p) for p in plain)
    assert [p["tag"] for p in plain] == [i % 8 for i in range(20)]


def test_edge_codes_reach_the_poles_the_equator_and_the_azimuth_wrap():
    """theta 0, 90 and 180 degrees and phi at both sides of 0 for N and L, every code on the
    grid of the Config."""
    cfg = Config()
    codes = edge_codes(cfg)
    q, full = cfg.full_circle // 4, cfg.full_circle
    for v in ("n", "l"):
        assert {0, q, 2 * q} <= set(codes[f"{v}.theta"].tolist())
        assert {0, 1, full - 1} <= set(codes[f"{v}.phi"].tolist())
    for k, c in codes.items():
        hi = 2 * q if k.endswith("theta") else full - 1
        assert c.min() >= 0 and c.max() <= hi, k
