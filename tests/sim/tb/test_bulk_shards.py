"""How a bulk run is split into shards (sim/tb/bulk_shards.py); the shards through a real
scheduler are tests/gen/test_cluster.py's (make fpga)."""

import pytest

from bumprtl.rtl.config import BumpError
from bumprtl.sim.tb.bulk_shards import shard_sources


def test_shards_split_the_vectors_and_draw_their_own_seeds():
    parts = shard_sources({"kind": "sincos", "n": 10, "seed": 3}, 4)
    assert [p["n"] for p in parts] == [3, 3, 2, 2]
    assert [p["seed"] for p in parts] == [3, 3001, 3002, 3003]       # shard 0 is the unsharded run's
    assert shard_sources({"kind": "sincos", "n": 10, "seed": 3}, 1) == [{"kind": "sincos", "n": 10, "seed": 3}]
    assert len(shard_sources({"kind": "sincos", "n": 2, "seed": 1}, 5)) == 2  # no empty shard
    with pytest.raises(BumpError, match="shards = 0 is out of range"):
        shard_sources({"kind": "sincos", "n": 10}, 0)
