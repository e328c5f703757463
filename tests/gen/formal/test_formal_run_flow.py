"""gen/formal/run.py's decisions with every sby run replaced by a stand-in: which job runs,
in which mode and to which depth, how its status becomes the table's word, when the BMC
fallback comes in, what a failure says and where its trace is kept. The real sby runs are
make formal's (and tests/sim/formal's quick subset); here only the runner's own logic,
read against its docstring: k-induction first, BMC to ``latency + margin`` when induction
does not close (``bounded``), covers to the chain's latency plus the margin, the covers of
the credit property deep enough to spend every credit."""

import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from bumprtl.gen.formal import run as fr
from bumprtl.gen.tools.sby import FormalResult
from bumprtl.sim.formal import axi
from bumprtl.sim.formal.mutants import MUTANTS
from bumprtl.sim.formal.targets import TARGETS


class FakeSby:
    """run_sby's stand-in: ``answers`` maps a job name to (status, trace, timed out, log);
    every call is recorded as (name, mode, depth, script, timeout)."""

    def __init__(self, answers=None, default=("PASS", None, False, "")):
        self.answers, self.default, self.calls = answers or {}, default, []

    def __call__(self, top, workdir, name, mode="prove", depth=10, script=(), timeout=3600,
                 **_):
        self.calls.append((name, mode, depth, tuple(script), timeout))
        status, trace, timed_out, log = self.answers.get(name, self.default)
        failed = ["model.il:7.1-7.9 assert"] if status == "FAIL" else []
        return FormalResult(name, mode, depth, status, 0.01, Path(workdir), trace, failed, log,
                            timed_out)


@pytest.fixture
def sby(monkeypatch):
    fake = FakeSby()
    monkeypatch.setattr(fr, "run_sby", fake)
    return fake


def test_a_property_that_proves_is_proved_by_induction_alone(sby, tmp_path):
    row = fr.check(TARGETS["sincos"], "hold", tmp_path)
    assert row.result == "proved" and row.ok
    assert [(c[0], c[1], c[2], c[4]) for c in sby.calls] == \
        [("hold", "prove", fr.INDUCTION_DEPTH, fr.PROVE_TIMEOUT)]
    assert row.latency == TARGETS["sincos"].unit().latency and row.detail == ""


@pytest.mark.parametrize("answer", [("UNKNOWN", None, False, ""), ("FAIL", None, False, ""),
                                    ("ERROR", None, True, "")])
def test_induction_that_does_not_close_falls_back_to_bmc_at_latency_plus_the_margin(
        sby, tmp_path, answer):
    """UNKNOWN, a FAIL without a trace (the induction step's, not a real counterexample) or
    a time-out: BMC without the lemmas to latency + BMC_MARGIN, reported as bounded."""
    sby.answers["order"] = answer
    row = fr.check(TARGETS["sincos"], "order", tmp_path)
    latency = TARGETS["sincos"].unit().latency
    assert [c[:3] for c in sby.calls] == [("order", "prove", fr.INDUCTION_DEPTH),
                                         ("order_bmc", "bmc", latency + fr.BMC_MARGIN)]
    assert sby.calls[1][3] == fr.ORDER_SCRIPT            # the same script as the proof's
    assert row.result == "bounded" and row.ok


def test_the_bank_property_falls_back_to_its_own_margin(sby, tmp_path):
    sby.answers["bank"] = ("UNKNOWN", None, False, "")
    target = next(t for t in TARGETS.values() if "bank" in t.props)
    row = fr.check(target, "bank", tmp_path)
    latency = target.unit().latency
    assert sby.calls[1][:3] == ("bank_bmc", "bmc", latency + fr.BANK_MARGIN + fr._front(target.unit()))
    assert row.result == "bounded"


def test_a_failed_bmc_after_the_fallback_is_a_failure(sby, tmp_path):
    sby.answers["order"] = ("UNKNOWN", None, False, "")
    sby.answers["order_bmc"] = ("FAIL", tmp_path / "trace.vcd", False, "")
    row = fr.check(TARGETS["sincos"], "order", tmp_path)
    assert row.result == "FAIL" and not row.ok and row.trace.endswith("trace.vcd")


def test_a_counterexample_of_the_induction_is_a_failure_without_fallback(sby, tmp_path):
    sby.answers["hold"] = ("FAIL", tmp_path / "hold.vcd", False, "")
    row = fr.check(TARGETS["sincos"], "hold", tmp_path)
    assert [c[0] for c in sby.calls] == ["hold"]
    assert row.result == "FAIL" and row.detail == "model.il:7.1-7.9 assert"


def test_an_sby_error_names_the_last_line_of_its_log(sby, tmp_path):
    sby.answers["quiet"] = ("ERROR", None, False, "first line\nERROR: the solver died\n")
    row = fr.check(TARGETS["sincos"], "quiet", tmp_path)
    assert row.result == "ERROR" and row.detail == "ERROR: the solver died"
    sby.answers["quiet"] = ("ERROR", None, False, "  \n")
    assert fr.check(TARGETS["sincos"], "quiet", tmp_path).detail == "sby error"


@pytest.mark.parametrize("status,word", [("PASS", "covered"), ("FAIL", "NOT COVERED"),
                                         ("ERROR", "ERROR")])
def test_covers_run_to_the_latency_plus_the_margin(sby, tmp_path, status, word):
    dut = TARGETS["sincos"].unit()
    sby.answers["cover"] = (status, None, False, "x")
    sby.answers["credit_cover"] = (status, None, False, "x")
    sby.answers["hold_cover"] = (status, None, False, "x")
    assert fr.check(TARGETS["sincos"], "cover", tmp_path).result == word
    assert fr.check(TARGETS["sincos"], "credit_cover", tmp_path).result == word
    assert fr.check(TARGETS["sincos"], "hold_cover", tmp_path).result == word
    depths = {c[0]: (c[1], c[2]) for c in sby.calls}
    assert depths["cover"] == ("cover", dut.latency + fr.BMC_MARGIN)
    assert depths["hold_cover"] == ("cover", dut.latency + fr.BMC_MARGIN)
    # the credit covers spend every credit: the FIFO's depth on top
    assert depths["credit_cover"] == ("cover", dut.latency + dut.fifo_depth + fr.BMC_MARGIN)


@pytest.mark.parametrize("name", list(MUTANTS)[:2])
def test_a_broken_unit_must_fail_with_a_trace(sby, tmp_path, name):
    _cls, prop = MUTANTS[name]
    sby.default = ("FAIL", tmp_path / "t.vcd", False, "")
    assert fr.check_mutant(name, tmp_path).result == "fails as expected"
    sby.default = ("FAIL", None, False, "")                 # a failure without a trace
    assert fr.check_mutant(name, tmp_path).result == "FAIL"
    sby.default = ("PASS", None, False, "")
    row = fr.check_mutant(name, tmp_path)
    assert row.result == "NOT CAUGHT" and not row.ok and row.unit == f"mutant {name}"
    assert all(c[1] == "bmc" for c in sby.calls)


class FakeAxi:
    """sim/formal/axi's prove, bmc and cover replaced: each returns (top, result)."""

    def __init__(self, answers):
        self.answers, self.calls = answers, []
        self.top = SimpleNamespace(lemmas=[1, 2, 3], describe=lambda f: f"rule at {f}")

    def _result(self, kind, name, depth):
        self.calls.append((kind, name, depth))
        status, trace, timed_out = self.answers.get(kind, ("PASS", None, False))
        failed = ["axi.il:3"] if status == "FAIL" else []
        return self.top, FormalResult(name, kind, depth, status, 0.01, Path("."), trace, failed,
                                      "", timed_out)

    def prove(self, geom, workdir, name, depth, timeout=None):
        return self._result("prove", name, depth)

    def bmc(self, geom, workdir, depth, name, dut=None):
        return self._result("bmc", name, depth)

    def cover(self, geom, workdir, depth, name):
        return self._result("cover", name, depth)


@pytest.fixture
def axi_target():
    return next(t for t in TARGETS.values() if "axi" in t.props)


@pytest.mark.parametrize("answers,result,kinds", [
    ({}, "proved", ["prove"]),
    ({"prove": ("UNKNOWN", None, False)}, "bounded", ["prove", "bmc"]),
    ({"prove": ("ERROR", None, True)}, "bounded", ["prove", "bmc"]),
    ({"prove": ("UNKNOWN", None, False), "bmc": ("FAIL", Path("b.vcd"), False)}, "FAIL",
     ["prove", "bmc"]),
    ({"prove": ("FAIL", Path("p.vcd"), False)}, "FAIL", ["prove"]),
])
def test_the_axi_rules_prove_then_fall_back_to_bmc_from_reset(monkeypatch, tmp_path, axi_target,
                                                               answers, result, kinds):
    fake = FakeAxi(answers)
    for f in ("prove", "bmc", "cover"):
        monkeypatch.setattr(fr.axi, f, getattr(fake, f))
    row = fr.check(axi_target, "axi", tmp_path)
    assert row.result == result and [c[0] for c in fake.calls] == kinds
    if "bmc" in kinds:
        assert fake.calls[1][1:] == ("axi_bmc", fr.AXI_BMC_DEPTH)
    assert row.lemmas == 3
    assert row.detail == ("" if result != "FAIL" else "rule at axi.il:3")


@pytest.mark.parametrize("status,word", [("PASS", "covered"), ("FAIL", "NOT COVERED")])
def test_the_axi_covers_are_covered_or_not(monkeypatch, tmp_path, axi_target, status, word):
    fake = FakeAxi({"cover": (status, None, False)})
    monkeypatch.setattr(fr.axi, "cover", fake.cover)
    assert fr.check(axi_target, "axi_cover", tmp_path).result == word
    geom = axi.geometry(axi_target.config["geometry"])
    assert fake.calls == [("cover", "axi_cover", axi.cover_depth(geom))]   # its own job name


@pytest.mark.parametrize("status,trace,word", [("FAIL", Path("m.vcd"), "fails as expected"),
                                               ("PASS", None, "NOT CAUGHT"),
                                               ("FAIL", None, "FAIL")])
def test_a_broken_axi_manager_must_fail_with_a_trace(monkeypatch, tmp_path, status, trace, word):
    fake = FakeAxi({"bmc": (status, trace, False)})
    monkeypatch.setattr(fr.axi, "bmc", fake.bmc)
    name = next(iter(axi.MUTANTS))
    row = fr.check_axi_mutant(name, tmp_path)
    assert row.result == word and row.unit == f"mutant axi_{name}"
    assert fake.calls == [("bmc", f"axi_{name}", fr.AXI_BMC_DEPTH)]


def _row(unit, prop, result="proved", trace=""):
    return fr.Row(unit, prop, result, 2, 1.0, 5, 0, "", trace)


def test_failures_are_reported_with_their_traces(capsys):
    rows = [_row("sincos", "hold"), _row("sincos", "order", "FAIL", "/w/order.vcd"),
            _row("mutant x", "hold", "NOT CAUGHT"), _row("sincos", "cover", "covered"),
            _row("sincos", "latency", "bounded"), _row("mutant y", "order", "fails as expected")]
    bad = fr.report_failures(rows)
    err = capsys.readouterr().err
    assert [r.prop for r in bad] == ["order", "hold"]
    assert "FAILED: sincos property order: FAIL" in err and "counterexample: /w/order.vcd" in err
    assert "FAILED: mutant x property hold: NOT CAUGHT" in err
    assert err.count("counterexample") == 1


def test_rows_are_ordered_as_the_targets_and_their_properties_are_listed():
    first, second = list(TARGETS)[:2]
    props = TARGETS[first].props
    rows = [_row(f"mutant {next(iter(MUTANTS))}", "hold"), _row(second, props[0]),
            _row(first, props[1]), _row("zzz unknown", "hold"), _row(first, props[0])]
    ordered = [(r.unit, r.prop) for r in fr._ordered(rows)]
    assert ordered == [(first, props[0]), (first, props[1]), (second, props[0]),
                       (f"mutant {next(iter(MUTANTS))}", "hold"), ("zzz unknown", "hold")]


def test_from_results_reprints_and_documents_a_saved_run_without_running(monkeypatch, tmp_path,
                                                                          capsys):
    monkeypatch.setattr(fr, "run", lambda *a, **k: pytest.fail("nothing may run"))
    out = tmp_path / "formal"
    out.mkdir()
    saved = [_row("sincos", "hold"), _row("sincos", "order", "bounded")]
    (out / "results.json").write_text(json.dumps([fr.asdict(r) for r in saved]))
    doc = tmp_path / "formal.md"
    rc = fr.main(["--from-results", "--out", str(out), "--doc", str(doc)])
    text = capsys.readouterr().out
    assert rc == 0 and f"wrote {doc}" in text and "2 checks" in text
    body = doc.read_text()
    assert "bounded" in body and "proved" in body
    (out / "results.json").write_text(json.dumps([fr.asdict(_row("sincos", "hold", "FAIL"))]))
    assert fr.main(["--from-results", "--out", str(out)]) == 1


def test_a_property_filter_picks_the_broken_units_of_that_property(monkeypatch, tmp_path):
    jobs = []

    class Runner:
        def __init__(self, scheduler, n):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *a):
            return False

        def run(self, js, desc, on_done):
            jobs.extend(j.args for j in js)

    monkeypatch.setattr(fr, "Runner", Runner)
    fr.run(["sincos"], ["hold"], True, tmp_path)
    kinds = [a[0] for a in jobs]
    assert ("target", "sincos", "hold") in jobs and kinds.count("target") == 1
    assert {a[1] for a in jobs if a[0] == "mutant"} == \
        {n for n, (_c, p) in MUTANTS.items() if p == "hold"}
    assert not any(a[0] == "axi_mutant" for a in jobs)
    jobs.clear()
    fr.run(["sincos"], ["axi"], True, tmp_path)
    assert [a for a in jobs if a[0] == "axi_mutant"] == \
        [("axi_mutant", n, "axi") for n in axi.MUTANTS]
    assert not any(a[0] == "target" for a in jobs)          # sincos has no axi property


def test_the_bank_properties_covers_run_two_cycles_past_its_margin(sby, tmp_path):
    """The bank property's own covers reach a bank swap seen through the unit: latency +
    BANK_MARGIN + 2, not the stream covers' latency + BMC_MARGIN."""
    target = next(t for t in TARGETS.values() if "bank_cover" in t.props)
    assert fr.check(target, "bank_cover", tmp_path).result == "covered"
    dut = target.unit()
    assert sby.calls[0][:3] == ("bank_cover", "cover", fr._cover_depth(dut, fr.BANK_MARGIN + 2))
    assert fr._cover_depth(dut, fr.BANK_MARGIN + 2) != fr._cover_depth(dut, fr.BMC_MARGIN)


def test_a_failure_names_every_failed_assertion_joined_by_semicolons(monkeypatch, tmp_path):
    def two_failures(top, workdir, name, mode="prove", depth=10, script=(), timeout=3600, **_):
        return FormalResult(name, mode, depth, "FAIL", 0.01, Path(workdir), tmp_path / "t.vcd",
                            ["model.il:7.1-7.9", "model.il:9.1-9.9"], "", False)
    monkeypatch.setattr(fr, "run_sby", two_failures)
    row = fr.check(TARGETS["sincos"], "hold", tmp_path)
    assert row.result == "FAIL" and row.trace == str(tmp_path / "t.vcd")
    # an unknown location is described as itself (StreamContract.describe)
    assert row.detail == "model.il:7.1-7.9; model.il:9.1-9.9"


@pytest.mark.parametrize("kind, name, prop", [("target", "sincos", "hold"),
                                              ("mutant", next(iter(MUTANTS)), None)])
def test_a_formal_job_checks_what_its_kind_names_and_returns_its_logs(sby, kind, name, prop):
    """formal_job runs the target's property or the broken unit named, in a temporary
    directory, and returns the row with the sby logs it kept (none here: the stand-in
    writes no files)."""
    out = fr.formal_job(kind, name, prop or MUTANTS[name][1])
    row = fr.Row(**out["row"])
    assert row.unit == (name if kind == "target" else f"mutant {name}")
    assert row.prop == (prop or MUTANTS[name][1])
    assert sby.calls[0][0] == (prop if kind == "target" else name)
    assert out["files"] == {} and out["log"] == ""


def test_bumprtl_formal_hands_every_flag_to_the_runner(monkeypatch):
    """`bumprtl formal` and `python -m bumprtl.gen.formal.run` take the same flags
    (add_arguments) and hand each to execute: every flag at a non-default value arrives."""
    from bumprtl.gen.cli import formal as cli_formal
    from bumprtl.gen.cli.main import main
    seen = []
    monkeypatch.setattr(cli_formal, "execute", lambda **kw: seen.append(kw) or 0)
    monkeypatch.setattr(fr, "execute", lambda **kw: seen.append(kw) or 0)
    argv = ["sincos", "--prop", "hold", "--prop", "order", "--no-mutants", "--quick", "-j", "3",
            "--job-timeout", "5", "--scheduler", "tcp://host:8786", "--out", "somewhere",
            "--merge", "--from-results", "--doc", "page.md"]
    assert main(["formal", *argv]) == 0
    assert fr.main(argv) == 0
    want = {"units": ["sincos"], "props": ["hold", "order"], "mutants": False, "quick": True,
            "jobs": 3, "job_timeout": 5.0, "scheduler": "tcp://host:8786", "out": Path("somewhere"),
            "merge": True, "from_results": True, "doc": Path("page.md")}
    assert seen == [want, want]


def test_a_broken_unit_of_the_bank_property_gets_the_memories_mapped(sby, tmp_path):
    """The bank property reads the colour table's memory: its broken units' BMC maps the
    memories (``memory_map``, ``opt -fast``), the others' runs add nothing to the script."""
    bank = next(n for n, (_c, prop) in MUTANTS.items() if prop == "bank")
    other = next(n for n, (_c, prop) in MUTANTS.items() if prop != "bank")
    sby.default = ("FAIL", tmp_path / "t.vcd", False, "")
    fr.check_mutant(bank, tmp_path)
    fr.check_mutant(other, tmp_path)
    assert sby.calls[0][3] == ("memory_map", "opt -fast") and sby.calls[1][3] == ()


def test_a_formal_job_keeps_the_sby_logs_and_the_trace_only(monkeypatch):
    """The files a job returns: every sby run's logfile.txt and the counterexample trace,
    by their path under the job's directory, nothing else the run left there."""
    def fake_sby(top, workdir, name, mode="prove", depth=10, script=(), timeout=3600, **_):
        run = Path(workdir) / name
        run.mkdir(parents=True)
        (run / "logfile.txt").write_text("the log\n")
        (run / "engine_0").mkdir()
        (run / "engine_0" / "trace.vcd").write_text("$date\n")
        (run / "engine_0" / "trace_tb.v").write_text("module tb;\n")
        (run / "model.il").write_text("attribute\n")
        return FormalResult(name, mode, depth, "FAIL", 0.01, run, run / "engine_0" / "trace.vcd",
                            ["model.il:7.1-7.9"], "", False)
    monkeypatch.setattr(fr, "run_sby", fake_sby)
    out = fr.formal_job("target", "sincos", "hold")
    assert sorted(out["files"]) == ["sincos/hold/engine_0/trace.vcd", "sincos/hold/logfile.txt"]
    assert out["row"]["trace"] == "sincos/hold/engine_0/trace.vcd"
    assert out["log"] == "==== sincos/hold/logfile.txt\nthe log\n"
