"""Heavy jobs on Dask ``distributed``: placements, proofs, sweeps, on this machine or a cluster.

One job layer for every command that runs many long tool runs (``report fpga``, ``report
table1``, ``bench sweep --fpga``, ``bumprtl formal``). By default a command starts a
``LocalCluster`` of one single-threaded worker process per job slot (``processes=True,
threads_per_worker=1``) and closes it when it ends; ``--scheduler tcp://HOST:PORT`` (or
``BUMPRTL_SCHEDULER``) sends the same jobs to a running scheduler instead.

A job travels: it carries its inputs (Verilog text, constraint text, a target's name) and
runs its tools in a worker-local temporary directory, so workers need not share a
filesystem with the client; it returns what the report needs (parsed tool results, log
text, small files). The client keeps the caches under ``build/`` and writes each job's log
to ``build/jobs/<job>.log``.

A job function returns a value; when that value is a dict with a ``"log"`` entry, the text
goes to the job's log file and the rest is the result. An exception in a job (a failing
tool, a tool missing on that worker, a timeout) is the job's error, one line, never the end
of the run: the report writes the failed rows with the reason. A worker that dies mid-job
(killed, out of memory) is the scheduler's business: it reschedules the job on another
worker (up to ``distributed.scheduler.allowed-failures`` times).

This module is in the tool layer (gen/tools/, below sim/: sim/tb/bulk_shards.py runs its
shards here; docs/scale.md). Dask ``distributed`` and ``psutil`` (the extras that run jobs:
[fpga], [formal], [bench]) are imported by the functions that use them, never at import
time: every command's parser, ``--help`` included, imports this module in a core install.
"""

import logging
import os
import re
import sys
import threading
import time
import traceback
import uuid
from dataclasses import dataclass, field
from pathlib import Path

from tqdm import tqdm

from bumprtl.rtl.config import BumpError

__all__ = ["Job", "Outcome", "Runner", "SchedulerError", "ENV", "LOG_DIR", "add_arguments",
           "scheduler_address", "job_name"]

ENV = "BUMPRTL_SCHEDULER"
LOG_DIR = Path("build/jobs")
CONNECT_TIMEOUT = 10          # seconds to reach a --scheduler before giving up
# LocalCluster workers are processes (a tool run holds the GIL-free CPU of one core each);
# tests that monkeypatch a job's function set this to False (threads in this process).
LOCAL_PROCESSES = True
ADDRESS = re.compile(r"^(tcp|tls)://[A-Za-z0-9._\-\[\]:]+:\d{1,5}$")


class SchedulerError(BumpError):
    """A misspelled or unreachable scheduler: one line, exit 2."""


@dataclass
class Job:
    """One unit of work: ``fn(*args)`` on a worker. ``name`` is unique in a run and names
    the log file (``build/jobs/<name>.log``); ``timeout`` (seconds) ends it with an error
    and kills the tool processes it started."""
    name: str
    fn: object
    args: tuple = ()
    timeout: float | None = None


@dataclass
class Outcome:
    name: str
    value: object = None
    error: str | None = None          # one line: why the job has no value
    worker: str = ""
    seconds: float = 0.0
    log: str = ""
    meta: dict = field(default_factory=dict)

    @property
    def ok(self):
        return self.error is None


def job_name(*parts):
    """A file-name-safe job name from ``parts``."""
    return re.sub(r"[^A-Za-z0-9_.+-]+", "_", "-".join(str(p) for p in parts)).strip("_")


def scheduler_address(flag=None):
    """``--scheduler`` or ``BUMPRTL_SCHEDULER`` (None: a LocalCluster); a malformed address
    is a :class:`SchedulerError` naming the parameter."""
    address = flag or os.environ.get(ENV) or None
    if address is None:
        return None
    source = "--scheduler" if flag else ENV
    if not ADDRESS.match(address):
        raise SchedulerError(f"{source} must be tcp://HOST:PORT (or tls://HOST:PORT), got {address!r}")
    return address


def add_arguments(p):
    """The ``--scheduler`` flag (the local worker count stays each command's ``--jobs``)."""
    p.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                   help=f"run the jobs on this Dask scheduler (default: ${ENV}, else a local "
                        "cluster of one single-threaded worker process per job)")


class _Timeout(Exception):
    pass


def _worker_address():
    from distributed import get_worker  # optional dependency

    try:
        return get_worker().address
    except ValueError:
        return "local"


def _call(fn, args, timeout):
    """``fn(*args)`` with a timeout: on expiry the tool processes this worker started
    (its children) are killed and :class:`_Timeout` is raised. (A worker runs one job at a
    time, so its children are this job's; in the tests' in-process cluster they are every
    job's of the test process.)"""
    if not timeout:
        return fn(*args)
    box = {}

    def target():
        try:
            box["value"] = fn(*args)
        except BaseException as e:          # noqa: BLE001 - re-raised in the caller
            box["error"] = e

    t = threading.Thread(target=target, daemon=True)
    t.start()
    t.join(timeout)
    if t.is_alive():
        import psutil  # optional dependency

        for child in psutil.Process().children(recursive=True):
            try:
                child.kill()
            except psutil.Error:
                pass
        t.join(5)
        raise _Timeout(f"timeout after {timeout:g} s")
    if "error" in box:
        raise box["error"]
    return box["value"]


def execute(fn, args, timeout=None):
    """What runs on the worker: ``fn(*args)`` turned into a plain dict (value or error,
    log text, worker address, seconds). Exceptions become the job's error line."""
    t0 = time.time()
    worker = _worker_address()
    out = {"worker": worker, "host": os.uname().nodename, "log": ""}
    try:
        value = _call(fn, args, timeout)
        if isinstance(value, dict) and "log" in value:
            value = dict(value)
            out["log"] = value.pop("log") or ""
        out["value"] = value
    except _Timeout as e:
        out["error"] = str(e)
    except Exception as e:                  # noqa: BLE001 - the job's error, reported per row
        text = (str(e).strip().splitlines() or [""])[0]
        if getattr(e, "tool", None):        # ToolMissing / FormalToolMissing: which worker lacks it
            out["error"] = f"worker {worker} ({out['host']}): {text}"
        elif isinstance(e, BumpError) or (isinstance(e, RuntimeError) and type(e) is not RuntimeError):
            out["error"] = text             # the tool's own one-line reason
        else:
            out["error"] = f"{type(e).__name__}: {text}".rstrip(": ")
        out["log"] = traceback.format_exc()
    out["seconds"] = time.time() - t0
    return out


class Runner:
    """``with Runner(scheduler, workers) as r: outcomes = r.run(jobs)``.

    ``scheduler``: an address (already checked by :func:`scheduler_address`) or None for a
    LocalCluster of ``workers`` single-threaded worker processes, started here and closed
    on exit."""

    def __init__(self, scheduler=None, workers=1, log_dir=None, progress=None):
        self.address = scheduler
        self.workers = max(1, int(workers or 1))
        self.log_dir = Path(log_dir or LOG_DIR)
        self.progress = (os.environ.get("BUMPRTL_PROGRESS", "1") != "0") if progress is None else progress
        self.cluster = self.client = None

    def __enter__(self):
        if self.address:
            from distributed import Client  # optional dependency

            try:
                self.client = Client(self.address, timeout=CONNECT_TIMEOUT)
            except (OSError, TimeoutError) as e:
                reason = str(e).splitlines()[0] if str(e) else type(e).__name__
                raise SchedulerError(f"--scheduler {self.address}: cannot reach the scheduler "
                                     f"({reason})") from None
        return self

    def _local(self):
        """The LocalCluster, started at the first job (a run whose results are all cached
        starts none)."""
        if self.client is None:
            from distributed import Client, LocalCluster  # optional dependency

            self.cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1,
                                        processes=LOCAL_PROCESSES, dashboard_address=None,
                                        silence_logs=logging.ERROR,
                                        scheduler_kwargs={"dashboard_address": ":0"})
            self.client = Client(self.cluster)
        return self.client

    def __exit__(self, *exc):
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()
        return False

    @property
    def where(self):
        """``local cluster (N workers)`` or ``scheduler ADDRESS``."""
        if not self.address:
            return f"local cluster ({self.workers} worker{'s' if self.workers != 1 else ''})"
        return f"scheduler {self.address}"

    def submit(self, job):
        return self._local().submit(execute, job.fn, job.args, job.timeout, pure=False,
                                  key=f"{job.name}-{uuid.uuid4().hex[:8]}")

    def run(self, jobs, desc="jobs", on_done=None):
        """Run ``jobs`` (an iterable of :class:`Job`; each is submitted as soon as it is
        produced, so the client's own preparation overlaps the workers'), with a progress
        bar; returns ``{name: Outcome}``. ``on_done(outcome)`` is called as each ends."""
        from distributed import as_completed  # optional dependency
        from distributed.client import FutureCancelledError  # optional dependency
        from distributed.scheduler import KilledWorker  # optional dependency

        futures, outcomes, names = {}, {}, set()
        for job in jobs:
            if job.name in names:
                raise ValueError(f"two jobs named {job.name!r}")
            names.add(job.name)
            futures[self.submit(job)] = job.name
        with tqdm(total=len(futures), desc=desc, unit="job", disable=not self.progress,
                  file=sys.stderr) as bar:
            for fut in as_completed(list(futures)) if futures else ():
                name = futures[fut]
                try:
                    out = fut.result()
                    outcome = Outcome(name, out.get("value"), out.get("error"), out["worker"],
                                      out["seconds"], out["log"], {"host": out.get("host")})
                except KilledWorker as e:
                    outcome = Outcome(name, error=f"its worker died each time it ran it ({e})")
                except FutureCancelledError:
                    outcome = Outcome(name, error="cancelled (the scheduler went away)")
                except Exception as e:          # noqa: BLE001 - the job's row says why
                    outcome = Outcome(name, error=f"{type(e).__name__}: {e}".splitlines()[0])
                self._log(outcome)
                if not outcome.ok:              # one line per failed job; its row says it too
                    bar.write(f"job {name} failed" + (f" on {outcome.worker}" if outcome.worker
                                                      else "") + f": {outcome.error}", file=sys.stderr)
                outcomes[name] = outcome
                if on_done is not None:
                    on_done(outcome)
                bar.update()
        return outcomes

    def _log(self, o):
        self.log_dir.mkdir(parents=True, exist_ok=True)
        head = (f"job {o.name}\nworker {o.worker or '?'} ({o.meta.get('host') or '?'})\n"
                f"seconds {o.seconds:.1f}\nresult {'ok' if o.ok else 'error: ' + o.error}\n\n")
        (self.log_dir / f"{o.name}.log").write_text(head + (o.log or ""))
