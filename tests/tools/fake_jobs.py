"""A stand-in for gen/tools/jobs.Runner in tests that check what a command submits and what
it does with each job's outcome, without a Dask cluster."""

from types import SimpleNamespace

__all__ = ["fake_runner", "outcome"]


def outcome(value=None, error=None):
    """A job's outcome as the code reads it (``ok``, ``error``, ``value``)."""
    return SimpleNamespace(ok=error is None, error=error, value=value)


def fake_runner(answer):
    """A class to monkeypatch in place of ``Runner``: used as ``with Runner(address,
    workers) as r: r.run(jobs)``, it answers each job with ``answer(job)`` (an
    :func:`outcome`) in submission order. The class records ``address``, ``workers`` and
    every job it was given (``jobs``)."""

    class FakeRunner:
        jobs = []
        address = workers = None

        def __init__(self, address, workers, progress=True):
            FakeRunner.address, FakeRunner.workers = address, workers

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def run(self, jobs, desc=None):
            out = {}
            for job in jobs:
                FakeRunner.jobs.append(job)
                out[job.name] = answer(job)
            return out

    return FakeRunner
