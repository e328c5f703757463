"""The job layer (gen/tools/jobs.py) without a scheduler process: its local cluster in threads of
this process (LOCAL_PROCESSES = False), so each test runs in a second or two. The real
scheduler and worker processes are tests/gen/test_cluster.py's."""

import subprocess
import sys
import time
from types import SimpleNamespace

import pytest

from bumprtl.gen.cli.main import main
from bumprtl.gen.tools import jobs


def _sleeper(seconds):
    """A job whose tool (a child process) runs ``seconds``."""
    subprocess.run([sys.executable, "-c", f"import time; time.sleep({seconds})"], check=True)
    return {"slept": seconds, "log": "slept"}


def _fails():
    raise ValueError("no such thing\nsecond line")


@pytest.fixture
def threads(monkeypatch, tmp_path):
    monkeypatch.setattr(jobs, "LOCAL_PROCESSES", False)
    monkeypatch.setattr(jobs, "LOG_DIR", tmp_path / "job_logs")     # not build/jobs: tests run side by side
    return tmp_path


def test_values_errors_timeouts_and_logs(threads):
    """A value, an exception (its first line) and a timeout (the tool process killed, the
    job's error names it); every job has its log with its worker and result."""
    t0 = time.perf_counter()
    with jobs.Runner(None, 2, log_dir=threads / "jobs", progress=False) as r:
        out = r.run([jobs.Job("ok", _sleeper, (0,)), jobs.Job("bad", _fails),
                     jobs.Job("slow", _sleeper, (60,), timeout=1.0)])
    assert time.perf_counter() - t0 < 40                  # the 60 s tool did not run out
    assert out["ok"].ok and out["ok"].value == {"slept": 0}
    assert out["bad"].error == "ValueError: no such thing"
    assert out["slow"].error == "timeout after 1 s"
    log = (threads / "jobs" / "ok.log").read_text()
    assert "result ok" in log and log.endswith("slept")
    assert "result error: ValueError: no such thing" in (threads / "jobs" / "bad.log").read_text()
    assert "Traceback" in (threads / "jobs" / "bad.log").read_text()


def test_a_tool_missing_on_a_worker_names_the_worker_and_the_tool(threads, monkeypatch, capsys):
    """bumprtl formal with the solver missing where the job runs: the row says which tool
    and which worker, the table is still printed, exit 1."""
    from bumprtl.gen.formal import run as formal_run
    from bumprtl.gen.tools import sby

    monkeypatch.setattr(sby, "_bin_dirs", lambda: [str(threads / "nothing")])
    monkeypatch.setenv("PATH", str(threads / "nothing"))
    assert formal_run.main(["sincos", "--prop", "order", "--no-mutants", "--out",
                            str(threads / "f")]) == 1
    text = capsys.readouterr()
    line = [ln for ln in text.out.splitlines() if ln.startswith("sincos ")][0]
    assert "ERROR" in line and "worker " in line and "yowasp-sby not found" in line, line
    assert "| sincos | order | ERROR |" in text.out


@pytest.mark.parametrize("command", [["report", "fpga", "--unit", "scene_palette"],
                                     ["formal", "sincos", "--prop", "order", "--no-mutants"]])
def test_a_misspelled_or_unreachable_scheduler_is_one_line_exit_2(command, capsys, monkeypatch, tmp_path):
    monkeypatch.setattr(jobs, "CONNECT_TIMEOUT", 2)
    out = ["--out", str(tmp_path / ("r.md" if command[0] == "report" else "f"))]
    assert main(command + out + ["--scheduler", "tpc://127.0.0.1:8786"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--scheduler must be tcp://HOST:PORT" in err[0] and "tpc://" in err[0]
    assert main(command + out + (["--work", str(tmp_path / "c")] if command[0] == "report" else [])
                + ["--scheduler", "tcp://127.0.0.1:9"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "tcp://127.0.0.1:9: cannot reach the scheduler" in err[0], err


def test_the_environment_names_the_scheduler(monkeypatch):
    monkeypatch.setenv(jobs.ENV, "tcp://10.0.0.1:8786")
    assert jobs.scheduler_address(None) == "tcp://10.0.0.1:8786"
    assert jobs.scheduler_address("tcp://h:1") == "tcp://h:1"          # the flag wins
    monkeypatch.setenv(jobs.ENV, "10.0.0.1")
    with pytest.raises(jobs.SchedulerError, match="BUMPRTL_SCHEDULER must be tcp://HOST:PORT"):
        jobs.scheduler_address(None)


def test_runner_says_where_its_jobs_run_without_starting_a_cluster():
    local = jobs.Runner(None, 3)
    assert "3 workers" in local.where and "scheduler" not in local.where
    assert "1 worker" in jobs.Runner(None, 1).where and "workers" not in jobs.Runner(None, 1).where
    assert "tcp://10.0.0.5:8786" in jobs.Runner("tcp://10.0.0.5:8786", 2).where


def _answer():
    return 42


def test_jobs_given_a_timeout_that_finish_in_time_keep_their_value_or_error(threads):
    """A timeout that does not run out changes nothing: the value (any value, not only a
    dict with a log) or the exception's first line comes back as without one."""
    with jobs.Runner(None, 2, log_dir=threads / "jobs", progress=False) as r:
        out = r.run([jobs.Job("ok", _sleeper, (0,), timeout=60.0),
                     jobs.Job("plain", _answer, (), timeout=60.0),
                     jobs.Job("bad", _fails, (), timeout=60.0)])
    assert out["ok"].ok and out["ok"].value == {"slept": 0}
    assert out["plain"].ok and out["plain"].value == 42
    assert not out["bad"].ok and out["bad"].error == "ValueError: no such thing"


class _Future:
    """A finished future whose result raises ``exc``."""

    def __init__(self, exc):
        self.exc = exc

    def result(self):
        raise self.exc


def test_a_job_without_a_result_is_an_error_outcome_named_after_it(monkeypatch, tmp_path, capsys):
    """A job whose future was cancelled (the scheduler went away), whose worker died each
    time, or whose result raised anything else has an Outcome of its own name with a
    one-line error, a log file of that name and one line on stderr; the others keep
    theirs."""
    import distributed
    from distributed.client import FutureCancelledError
    from distributed.scheduler import KilledWorker
    runner = jobs.Runner(None, 1, log_dir=tmp_path, progress=False)
    futures = iter([_Future(FutureCancelledError("k", None)),
                    _Future(KilledWorker("k", SimpleNamespace(address="tcp://w:1"), 3)),
                    _Future(RuntimeError("boom\nsecond line"))])
    monkeypatch.setattr(runner, "submit", lambda job: next(futures))
    monkeypatch.setattr(distributed, "as_completed", lambda fs: fs)
    done = []
    out = runner.run([jobs.Job(n, _fails) for n in ("gone", "killed", "raised")], on_done=done.append)
    assert list(out) == ["gone", "killed", "raised"] and [o.name for o in done] == list(out)
    assert out["gone"].error == "cancelled (the scheduler went away)"
    assert out["killed"].error.startswith("its worker died each time it ran it")
    assert out["raised"].error == "RuntimeError: boom"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gone.log", "killed.log", "raised.log"]
    assert "result error: RuntimeError: boom" in (tmp_path / "raised.log").read_text()
    err = capsys.readouterr().err
    assert "job gone failed: cancelled (the scheduler went away)" in err


def test_progress_follows_the_argument_then_the_environment(monkeypatch):
    monkeypatch.delenv("BUMPRTL_PROGRESS", raising=False)
    assert jobs.Runner(None, 1).progress is True
    assert jobs.Runner(None, 1, progress=False).progress is False
    monkeypatch.setenv("BUMPRTL_PROGRESS", "0")
    assert jobs.Runner(None, 1).progress is False
    assert jobs.Runner(None, 1, progress=True).progress is True
