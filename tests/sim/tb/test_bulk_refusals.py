"""run_bulk's refusals before any build and its verdicts after the run (sim/tb/bulk.py),
without a simulator: an unknown traffic pattern, inputs and a source together or neither,
an expected field the unit does not output, an AXI latency out of range; then a run whose
summary reports an error (a timeout or a mismatch) or that wrote none."""

import json

import pytest

from bumprtl.gen.flow.units import build_unit
from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.tb import bulk
from bumprtl.sim.tb.bulk import SimulationTimeout, run_bulk


@pytest.fixture
def sincos(tmp_path):
    dut, meta, _ = build_unit("sincos", Config(angle_bits=8, frac_bits=9))
    dut._MustUse__silence = True                        # built for its sidecar only
    j = meta.dump(tmp_path / "sincos.json")
    v = tmp_path / "sincos.v"
    v.write_text("module sincos(); endmodule\n")
    return v, j


def _no_build(*a, **k):
    raise AssertionError("built before the refusal")


@pytest.mark.parametrize("kw, message", [
    ({"patterns": ("no_stall", "sometimes")}, "traffic pattern must be one of"),
    ({}, "run_bulk takes stimulus inputs or a source, not both"),
    ({"inputs": {"angle": [1]}, "source": {"kind": "sincos", "n": 1}},
     "run_bulk takes stimulus inputs or a source, not both"),
    ({"inputs": {"angle": [1, 2], "tag": [0, 1]}, "expected": {"tan": [0, 0]}},
     "expected field 'tan' is not an output field of sincos.json (o__payload fields: cos, sin, tag)"),
    ({"source": {"kind": "sincos", "n": 1}, "axi_latency": 0},
     "axi_latency must be an integer in [1, 65535], got 0"),
    ({"source": {"kind": "sincos", "n": 1}, "axi_latency": True},
     "axi_latency must be an integer in [1, 65535], got True"),
])
def test_bad_runs_are_refused_before_the_build(kw, message, sincos, tmp_path, monkeypatch):
    monkeypatch.setattr(bulk, "build", _no_build)
    v, j = sincos
    with pytest.raises(BumpError) as e:
        run_bulk("icarus", v, j, tmp_path / "work", **kw)
    assert message in str(e.value)
    assert not (tmp_path / "work").exists()


def test_custom_traffic_patterns_are_accepted(sincos, tmp_path, monkeypatch):
    monkeypatch.setattr(bulk, "build", lambda *a, **k: (_ for _ in ()).throw(
        RuntimeError("reached the build")))
    v, j = sincos
    with pytest.raises(RuntimeError, match="reached the build"):
        run_bulk("icarus", v, j, tmp_path / "work", patterns=("sometimes",),
                 traffic={"sometimes": (0.5, 0.5)}, source={"kind": "sincos", "n": 1})


class _Runner:
    summary = None
    results = None

    def test(self, **kw):
        work = kw["test_dir"]
        job = json.loads((work / "bulk_job.json").read_text())
        _Runner.job = job
        if _Runner.summary is not None:
            (work / "bulk_summary.json").write_text(json.dumps(_Runner.summary))
        return _Runner.results


@pytest.mark.parametrize("summary, exc, message", [
    ({"error": "no output for 5000 cycles", "timeout": True}, SimulationTimeout,
     "bulk run on icarus: no output for 5000 cycles"),
    ({"error": "pixel 3: sin 5 != 6"}, AssertionError, "bulk run on icarus: pixel 3: sin 5 != 6"),
    (None, AssertionError, "bulk cocotb run on icarus failed (no summary)"),
])
def test_a_run_that_reports_an_error_or_nothing_raises(summary, exc, message, tmp_path,
                                                       monkeypatch):
    monkeypatch.setattr(bulk, "runners", lambda: {"icarus": _Runner})
    _Runner.summary, _Runner.results = summary, None
    work = tmp_path / "w"
    work.mkdir()
    with pytest.raises(exc, match=message.replace("(", r"\(").replace(")", r"\)")):
        bulk._run_job("icarus", "top", tmp_path, work, tmp_path / "u.json", ("no_stall",),
                      {"angle": [1, 2]}, {"sin": [0, 0]}, [], None, True, "verilog", 64,
                      100, 1, {"no_stall": (0.0, 0.0)}, None)
    assert _Runner.job["source"] == {"kind": "arrays", "path": str(work / "bulk_arrays.npz")}
    assert _Runner.job["patterns"] == ["no_stall"] and _Runner.job["chunk"] == 64


def test_check_stimulus_takes_empty_fields_and_still_checks_the_values_of_full_ones():
    """An empty stimulus (no pixels) has no values to range-check; the same fields with one
    value out of range are refused."""
    import numpy as np

    from bumprtl.sim.tb.bulk_codec import check_stimulus

    _, meta, _ = build_unit("rotation", Config())
    fields = meta.fields_of("i__payload")
    check_stimulus(meta, {k: np.zeros(0, np.int64) for k in fields})
    big = {k: np.zeros(2, np.int64) for k in fields}
    name = next(k for k, f in fields.items() if not f.signed)
    big[name][1] = 1 << fields[name].width
    with pytest.raises(BumpError, match=repr(name)):
        check_stimulus(meta, big)
