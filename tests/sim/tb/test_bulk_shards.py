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


def test_a_shard_runs_in_a_directory_holding_the_files_it_carries(monkeypatch):
    """bulk_shard writes ``files`` into its temporary directory and runs run_bulk there with
    the shard's source, the patterns and the chunk options; returns the run's counts."""
    from types import SimpleNamespace

    from bumprtl.sim.tb import bulk_shards
    seen = {}

    def run_bulk(sim, v, j, work, patterns, source, keep, **kw):
        seen.update(sim=sim, v=v.read_text(), j=j.read_text(), parent=v.parent,
                    patterns=patterns, source=source, keep=keep, kw=kw,
                    listing=sorted(p.name for p in v.parent.iterdir()))
        return SimpleNamespace(pixels={"no_stall": 5}, cycles={"no_stall": 9}, checked=True,
                               sim_s={"no_stall": 0.5}, build_s=2.0, cached=True)

    monkeypatch.setattr(bulk_shards, "run_bulk", run_bulk)
    source = {"kind": "sincos", "n": 5, "seed": 3001}
    r = bulk_shards.bulk_shard("verilator", {"u.v": "module u; endmodule", "u.json": "{}",
                                             "rom.hex": "00"}, "u.v", "u.json",
                               ["no_stall"], source, {"chunk": 64})
    assert seen["v"] == "module u; endmodule" and seen["j"] == "{}"
    assert seen["listing"] == ["rom.hex", "u.json", "u.v"]
    assert seen["patterns"] == ("no_stall",) and seen["source"] == source
    assert seen["keep"] is False and seen["kw"] == {"chunk": 64}
    assert not seen["parent"].exists()                   # the temporary directory is gone
    assert r == {"pixels": {"no_stall": 5}, "cycles": {"no_stall": 9}, "checked": True,
                 "sim_s": {"no_stall": 0.5}, "build_s": 2.0, "cached": True, "source": source}


def test_shards_run_as_jobs_their_counts_added_and_a_failure_named(monkeypatch, tmp_path):
    from bumprtl.sim.tb import bulk_shards
    from tests.tools.fake_jobs import fake_runner, outcome

    failing = {"seed": None}

    def shard(job):
        sim, files, v_name, j_name, patterns, source, kw = job.args
        if source["seed"] == failing["seed"]:
            return outcome(error="tb_bulk: 3 mismatches")
        return outcome({"pixels": {p: source["n"] for p in patterns},
                        "checked": source["seed"] != 1})

    Runner = fake_runner(shard)
    monkeypatch.setattr(bulk_shards, "Runner", Runner)
    monkeypatch.delenv("BUMPRTL_SCHEDULER", raising=False)
    (tmp_path / "u.v").write_text("module u; endmodule")
    (tmp_path / "u.json").write_text("{}")
    (tmp_path / "notes.txt").write_text("not carried")
    r = bulk_shards.run_bulk_shards("icarus", tmp_path / "u.v", tmp_path / "u.json",
                                    ("no_stall", "both"), {"kind": "sincos", "n": 10, "seed": 2},
                                    shards=3)
    assert Runner.workers == 2
    assert len(Runner.jobs) == 3 and all(sorted(job.args[1]) == ["u.json", "u.v"] for job in Runner.jobs)
    assert r["pixels"] == {"no_stall": 10, "both": 10} and r["checked"] is True
    assert [s["pixels"]["no_stall"] for s in r["shards"]] == [4, 3, 3]
    failing["seed"] = 2001
    with pytest.raises(AssertionError, match=r"bulk shards failed: bulk-icarus-u-sincos-shard1: "
                                             r"tb_bulk: 3 mismatches"):
        bulk_shards.run_bulk_shards("icarus", tmp_path / "u.v", tmp_path / "u.json",
                                    ("no_stall",), {"kind": "sincos", "n": 10, "seed": 2},
                                    shards=2, jobs=1)
