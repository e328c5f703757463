"""The job layer against a real Dask scheduler: ``dask scheduler`` and two ``dask worker``
processes on 127.0.0.1 (each in its own process group, started in a temporary directory
that is not the client's, bounded in time and always torn down by the fixture).

make test: one formal check through ``--scheduler`` equals the local check. make fpga: a
small placement through ``--scheduler`` gives the local run's report byte for byte, and a
worker killed in the middle of its placement leaves the job to the other worker and the
report complete."""

import os
import signal
import socket
import subprocess
import sys
import time
from dataclasses import asdict
from pathlib import Path

import pytest
from distributed import Client

from bumprtl.gen.cli.main import main
from bumprtl.gen.formal.run import check
from bumprtl.gen.tools import jobs
from bumprtl.sim.formal.targets import TARGETS

BIN = Path(sys.executable).parent
START_TIMEOUT = 120              # seconds for the scheduler and both workers to come up


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _stop(proc):
    """SIGTERM to the process group, SIGKILL after 10 s."""
    if proc.poll() is not None:
        return
    try:
        os.killpg(proc.pid, signal.SIGTERM)
        proc.wait(10)
    except (ProcessLookupError, subprocess.TimeoutExpired):
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait(10)


class Cluster:
    def __init__(self, root):
        self.root = root
        self.address = f"tcp://127.0.0.1:{_free_port()}"
        self.procs = {}

    def start(self, name, argv):
        log = open(self.root / f"{name}.log", "w")
        env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}"}
        env.pop("BUMPRTL_SCHEDULER", None)
        self.procs[name] = subprocess.Popen(argv, cwd=self.root, stdout=log, stderr=subprocess.STDOUT,
                                            env=env, start_new_session=True)

    def worker_names(self):
        """{worker address: its name (w0, w1)} as the scheduler knows them."""
        with Client(self.address, timeout=30) as c:
            return {a: w["name"] for a, w in c.scheduler_info(n_workers=-1)["workers"].items()}


@pytest.fixture
def cluster(tmp_path):
    c = Cluster(tmp_path)
    host, port = c.address.removeprefix("tcp://").split(":")
    try:
        c.start("scheduler", [str(BIN / "dask"), "scheduler", "--host", host, "--port", port,
                              "--no-dashboard"])
        for n in range(2):
            c.start(f"w{n}", [str(BIN / "dask"), "worker", c.address, "--name", f"w{n}",
                              "--nthreads", "1", "--nworkers", "1", "--no-dashboard"])
        deadline = time.monotonic() + START_TIMEOUT
        while True:
            try:
                with Client(c.address, timeout=10) as client:
                    client.wait_for_workers(2, timeout=max(1, deadline - time.monotonic()))
                break
            except (OSError, TimeoutError):
                if time.monotonic() > deadline:
                    logs = {p.name: p.read_text()[-500:] for p in tmp_path.glob("*.log")}
                    pytest.fail(f"the cluster did not come up in {START_TIMEOUT} s: {logs}")
                time.sleep(1)
        yield c
    finally:
        for proc in reversed(list(c.procs.values())):
            _stop(proc)


def _comparable(row):
    return {k: v for k, v in asdict(row).items() if k not in ("seconds", "trace")}


def test_a_formal_check_through_the_scheduler_equals_the_local_check(cluster, tmp_path, monkeypatch):
    from bumprtl.gen.formal import run as formal_run
    monkeypatch.setattr(jobs, "LOG_DIR", tmp_path / "job_logs")
    # quiet: a proof of about a second (order takes 20 s); the job path is the same
    remote = formal_run.run(["sincos"], ["quiet"], mutants=False, root=tmp_path / "remote",
                            scheduler=cluster.address, log=lambda line: None)
    local = check(TARGETS["sincos"], "quiet", tmp_path / "local")
    assert [_comparable(r) for r in remote] == [_comparable(local)]
    assert remote[0].result == "proved"
    log = (tmp_path / "job_logs" / "formal-sincos-quiet.log").read_text()
    assert "worker tcp://127.0.0.1:" in log and "result ok" in log


SMALL = ["--unit", "scene_palette", "--samples", "1000"]


@pytest.mark.fpga
def test_a_placement_through_the_scheduler_equals_the_local_one(cluster, tmp_path, monkeypatch):
    monkeypatch.setattr(jobs, "LOG_DIR", tmp_path / "job_logs")
    outs = {}
    for where, extra in (("local", ["--jobs", "1"]), ("remote", ["--scheduler", cluster.address])):
        out = tmp_path / where / "report.md"
        assert main(["report", "fpga", *SMALL, "--out", str(out), "--work",
                     str(tmp_path / where / "cache"), *extra]) == 0
        outs[where] = (out.read_text(), (out.parent / "data" / "fpga.json").read_text())
    assert outs["remote"] == outs["local"]
    assert "| scene_palette | not placed" not in outs["remote"][0]


@pytest.mark.fpga
def test_a_worker_killed_mid_placement_leaves_the_job_to_the_other(cluster, tmp_path):
    out = tmp_path / "report.md"
    argv = [str(BIN / "bumprtl"), "report", "fpga", *SMALL, "--out", str(out), "--work",
            str(tmp_path / "cache"), "--scheduler", cluster.address]
    client = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              env={**os.environ, "BUMPRTL_PROGRESS": "0"}, cwd=tmp_path)
    killed = None
    try:
        with Client(cluster.address, timeout=30) as c:
            deadline = time.monotonic() + 300
            while killed is None and time.monotonic() < deadline and client.poll() is None:
                busy = [a for a, keys in c.processing().items() if any("place-" in str(k) for k in keys)]
                if busy:
                    time.sleep(3)                      # well inside the placement's tools
                    name = cluster.worker_names()[busy[0]]
                    os.killpg(cluster.procs[name].pid, signal.SIGKILL)
                    killed = name
                time.sleep(0.2)
        text, _ = client.communicate(timeout=900)
    finally:
        _stop(client) if client.poll() is None else None
    assert killed is not None, "no worker was seen running the placement"
    assert client.returncode == 0, text
    row = [ln for ln in out.read_text().splitlines() if ln.startswith("| scene_palette |")][0]
    assert "not placed" not in row, row
    survivor = {"w0": "w1", "w1": "w0"}[killed]
    log = (tmp_path / "build" / "jobs" / "place-LFE5U-85F-scene_palette-seed1.log").read_text()
    worker = log.splitlines()[1].split()[1]
    assert cluster.worker_names()[worker] == survivor


@pytest.mark.fpga
def test_bulk_shards_through_the_scheduler_equal_the_local_shards(cluster, tmp_path, monkeypatch):
    """A bulk regression in 2 shards (sim/tb/bulk_shards.py; sincos on Verilator, 2 x 1500
    vectors under two traffic patterns) on the cluster's workers, built in their own
    directory: the same pixels, every shard checked bit for bit, as the shards run here."""
    from bumprtl.gen.flow.units import emit_unit
    from bumprtl.rtl.config import Config
    from bumprtl.sim.tb.bulk_shards import run_bulk_shards

    monkeypatch.setattr(jobs, "LOG_DIR", tmp_path / "job_logs")
    v, j = emit_unit("sincos", Config(), tmp_path / "rtl")
    source, patterns = {"kind": "sincos", "n": 3000, "seed": 1}, ("no_stall", "both")
    remote = run_bulk_shards("verilator", v, j, patterns, source, 2, scheduler=cluster.address)
    local = run_bulk_shards("verilator", v, j, patterns, source, 2)
    assert remote["checked"] and local["checked"]
    assert remote["pixels"] == local["pixels"] == {"no_stall": 3000, "both": 3000}
    assert ([s["source"] for s in remote["shards"]] == [s["source"] for s in local["shards"]]
            == [{**source, "n": 1500}, {**source, "n": 1500, "seed": 1001}])
    assert [s["cycles"] for s in remote["shards"]] == [s["cycles"] for s in local["shards"]]
