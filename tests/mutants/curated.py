"""The standing mutation check (``make mutate``; ``python -m tests.mutants.curated`` from the
repository). Test tooling: it lives beside the tests, not in the product.

A curated list of small, realistic bugs (``tests/mutants/mutants.toml``) is put into the
code one at a time, and the tests that guard each one are run against it: a mutant the
guards do not fail *survived*, i.e. a bug of that kind would pass the suite.

Each mutant is a list of search/replace edits (``file``, the exact ``original`` text, its
``replacement``; more edits under ``[[mutant.also]]``, e.g. the same bug in the RTL and in
the golden model), one line saying what bug it models, and the pytest node ids or paths
that guard it. Search/replace pairs, not line-numbered patches, so a mutant keeps applying
while the code around it moves; a mutant whose ``original`` text no longer occurs exactly
once is an error that names the file and the text to update. A mutant that changes
nothing observable is listed with ``equivalent = "why"``: its text is still checked, its
guards are not run.

By default the working tree (git's tracked and untracked, non-ignored files) is first
copied to ``build/mutate/tree`` (``--copy DIR`` elsewhere) and the copy is mutated, so
other people may keep working in the tree; ``--in-place`` mutates the working tree itself.
For each mutant: apply it (every file's content hash recorded first), run its guards
(``pytest -x -q -n 0``, bytecode writing off so no stale ``.pyc`` outlives it), restore in
a ``finally`` and verify each file's content hash against the one recorded. ``--check``
reads the working tree and copies nothing. ``--jobs N`` or ``--scheduler tcp://HOST:PORT``
runs the baseline and each mutant as a job of bumprtl's job layer (gen/tools/jobs.py, Dask): the
tree travels with the job as a tar archive and each job mutates its own unpacked copy in a
temporary directory of its worker, so mutants run side by side, on this machine or a cluster.

Exit status: 0 when every mutant was killed, 1 when one survived, did not apply or its
guards failed on the unmutated code (the baseline run), 2 on a bad mutant list.
"""

import argparse
import hashlib
import io
import os
import shutil
import signal
import subprocess
import sys
import tarfile
import tempfile
import time
import tomllib
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import cloudpickle

from bumprtl.gen.tools.docs import made_at
from bumprtl.gen.tools.jobs import Job, Runner, SchedulerError, job_name, scheduler_address
from bumprtl.rtl.config import BumpError, Config

__all__ = ["Edit", "Mutant", "MutantError", "RestoreError", "Outcome", "ROOT", "DEFAULT_LIST",
           "load_mutants", "check_applies", "applied", "run_guards", "run_mutants", "markdown",
           "copy_tree", "main"]

ROOT = Path(__file__).resolve().parents[2]          # the repository (tests/mutants/curated.py)
DEFAULT_COPY = Path("build/mutate/tree")
DEFAULT_LIST = Path("tests/mutants/mutants.toml")
DEFAULT_TIMEOUT = 1800                               # seconds per mutant's guard run
_KEYS = {"id", "file", "original", "replacement", "models", "guards", "also", "equivalent"}
_EDIT_KEYS = {"file", "original", "replacement"}
# pytest exit codes: 0 all passed, 1 some failed, 2 interrupted (a collection error, e.g.
# the mutant broke an import), 3 internal error, 4 usage error (a guard path that does not
# exist), 5 no tests collected.
_KILLED = {1: "killed", 2: "killed (collection error)"}


class MutantError(BumpError):
    """A bad mutant list, or a mutant that no longer applies; the message names the mutant,
    the file and the text to update."""


class RestoreError(RuntimeError):
    """A mutated file whose content hash after restoring differs from before the mutant."""


@dataclass(frozen=True)
class Edit:
    """Replace ``original`` (which must occur exactly once) by ``replacement`` in ``file``
    (relative to the tree)."""
    file: str
    original: str
    replacement: str


@dataclass(frozen=True)
class Mutant:
    id: str
    models: str                        # one line: the bug this mutant models
    guards: tuple                      # pytest node ids or paths
    edits: tuple                       # Edit, applied in order
    equivalent: str | None = None      # why nothing observable changes (guards not run)


@dataclass
class Outcome:
    """What happened to one mutant: ``status`` is killed, killed (...), survived,
    equivalent, error; ``seconds`` the guard run's wall time."""
    mutant: Mutant
    status: str
    seconds: float = 0.0
    detail: str = ""
    log: str = field(default="", repr=False)

    @property
    def killed(self):
        return self.status.startswith("killed")


def _sha(data: bytes):
    return hashlib.sha256(data).hexdigest()


def _edit(entry, where):
    missing = _EDIT_KEYS - set(entry)
    if missing:
        raise MutantError(f"{where}: missing key(s) {', '.join(sorted(missing))}")
    unknown = set(entry) - _EDIT_KEYS
    if unknown:
        raise MutantError(f"{where}: unknown key(s) {', '.join(sorted(unknown))} "
                          f"(allowed: {', '.join(sorted(_EDIT_KEYS))})")
    for key in _EDIT_KEYS:
        if not isinstance(entry[key], str):
            raise MutantError(f"{where}: {key} must be a string")
    if not entry["original"]:
        raise MutantError(f"{where}: original must not be empty")
    if entry["original"] == entry["replacement"]:
        raise MutantError(f"{where}: replacement equals original (nothing is mutated)")
    return Edit(entry["file"], entry["original"], entry["replacement"])


def load_mutants(path=None, text=None):
    """The mutants of a TOML list (``path``, or its ``text``), validated: unique ids, a
    one-line ``models``, guards (unless ``equivalent``), edits with non-empty originals."""
    if text is None:
        path = Path(path or ROOT / DEFAULT_LIST)
        try:
            text = path.read_text()
        except OSError as e:
            raise MutantError(f"mutant list {path}: {e.strerror}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise MutantError(f"mutant list {path}: not valid TOML ({e})") from None
    unknown = set(data) - {"mutant"}
    if unknown:
        raise MutantError(f"mutant list {path}: unknown top-level key(s) {', '.join(sorted(unknown))}")
    mutants, seen = [], set()
    for n, entry in enumerate(data.get("mutant", [])):
        where = f"mutant {entry.get('id', f'#{n + 1}')!r}"
        bad = set(entry) - _KEYS
        if bad:
            raise MutantError(f"{where}: unknown key(s) {', '.join(sorted(bad))} "
                              f"(allowed: {', '.join(sorted(_KEYS))})")
        for key in ("id", "models"):
            if not isinstance(entry.get(key), str) or not entry[key].strip():
                raise MutantError(f"{where}: {key} must be a non-empty string")
        if "\n" in entry["models"].strip():
            raise MutantError(f"{where}: models must be one line")
        if entry["id"] in seen:
            raise MutantError(f"{where}: duplicate id")
        seen.add(entry["id"])
        equivalent = entry.get("equivalent")
        if equivalent is not None and (not isinstance(equivalent, str) or not equivalent.strip()):
            raise MutantError(f"{where}: equivalent must say why nothing observable changes")
        guards = entry.get("guards", [])
        if not isinstance(guards, list) or not all(isinstance(g, str) and g for g in guards):
            raise MutantError(f"{where}: guards must be a list of pytest node ids or paths")
        if not guards and equivalent is None:
            raise MutantError(f"{where}: no guards (a mutant that changes nothing observable "
                              f"says so with equivalent = \"why\")")
        also = entry.get("also", [])
        if not isinstance(also, list):
            raise MutantError(f"{where}: also must be an array of tables ([[mutant.also]])")
        own = {k: entry[k] for k in _EDIT_KEYS if k in entry}
        edits = [_edit(own, where)] + [_edit(e, f"{where}, also #{k + 1}")
                                         for k, e in enumerate(also)]
        mutants.append(Mutant(entry["id"], entry["models"].strip(), tuple(guards), tuple(edits),
                              equivalent.strip() if equivalent else None))
    if not mutants:
        raise MutantError(f"mutant list {path}: no [[mutant]] entries")
    return mutants


def _mutated_texts(mutant, root):
    """``{file: (old bytes, new text)}`` after all edits; raises MutantError when an
    original text does not occur exactly once (in the text as the earlier edits left it)."""
    texts = {}
    for edit in mutant.edits:
        path = Path(root) / edit.file
        if edit.file not in texts:
            try:
                data = path.read_bytes()
            except OSError:
                raise MutantError(f"mutant {mutant.id!r}: file {edit.file} does not exist "
                                  f"(update the mutant list)") from None
            texts[edit.file] = (data, data.decode())
        data, text = texts[edit.file]
        count = text.count(edit.original)
        if count != 1:
            what = "no longer occurs" if count == 0 else f"occurs {count} times"
            raise MutantError(f"mutant {mutant.id!r}: the original text {what} in {edit.file} "
                              f"(it must occur exactly once; update the mutant list): "
                              f"{edit.original.strip()[:120]!r}")
        texts[edit.file] = (data, text.replace(edit.original, edit.replacement))
    return texts


def check_applies(mutant, root=ROOT):
    """Raise MutantError unless every edit's original text occurs exactly once."""
    _mutated_texts(mutant, root)


@contextmanager
def applied(mutant, root=ROOT):
    """The mutant applied in place while the block runs. On the way out (also on an
    exception or Ctrl-C) each edit is undone (replacement back to original) and the file's
    content hash must equal the one recorded before. If it does not, the file was changed
    by someone else meanwhile: their edit is kept (the mutation undone around it, or the
    recorded content written back if they edited the mutated text itself) and RestoreError
    says so."""
    texts = _mutated_texts(mutant, root)
    before = {}
    try:
        for name, (data, text) in texts.items():
            path = Path(root) / name
            before[name] = (_sha(data), path.stat().st_mtime_ns, data)
            path.write_text(text)
            st = path.stat()
            if st.st_mtime_ns // 10**9 == before[name][1] // 10**9:
                # Python checks .pyc files by mtime in seconds: never let the mutant share it.
                os.utime(path, ns=(st.st_atime_ns, before[name][1] + 2 * 10**9))
        yield
    finally:
        problems = []
        for name, (sha, _, data) in before.items():
            path = Path(root) / name
            text = path.read_text()
            undone = True
            for edit in reversed([e for e in mutant.edits if e.file == name]):
                if text.count(edit.replacement) == 1:
                    text = text.replace(edit.replacement, edit.original)
                else:
                    undone = False
            if not undone:
                text = data.decode()          # the mutated text itself was edited
            path.write_text(text)
            if _sha(path.read_bytes()) != sha:
                problems.append(name)
        if problems:
            raise RestoreError(f"{', '.join(problems)}: content hash after restoring mutant "
                               f"{mutant.id!r} differs from before it (changed by someone else "
                               f"while the mutant was applied; their edit is kept)")


def run_guards(guards, root=ROOT, timeout=DEFAULT_TIMEOUT, env=None, extra=()):
    """Run pytest on ``guards`` in ``root``: ``(exit status or None on timeout, seconds,
    output)``. The child gets its own process group, killed on timeout or Ctrl-C."""
    argv = [sys.executable, "-m", "pytest", "-x", "-q", "-n", "0", "-p", "no:cacheprovider",
            *extra, *guards]
    child_env = dict(os.environ if env is None else env, PYTHONDONTWRITEBYTECODE="1")
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, cwd=root, env=child_env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=timeout)
        status = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        status = None
    except BaseException:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        raise
    return status, time.perf_counter() - t0, out


def _summary_line(out):
    lines = [ln for ln in out.strip().splitlines() if ln.strip()]
    failed = [ln for ln in lines if ln.startswith(("FAILED", "ERROR"))]
    return (failed or lines[-1:] or [""])[0][:160]


def run_mutant(mutant, root=ROOT, timeout=DEFAULT_TIMEOUT, env=None):
    """Apply ``mutant``, run its guards, restore: an :class:`Outcome`."""
    try:
        check_applies(mutant, root)
    except MutantError as e:
        return Outcome(mutant, "error", detail=str(e))
    if mutant.equivalent:
        return Outcome(mutant, "equivalent", detail=mutant.equivalent)
    with applied(mutant, root):
        status, seconds, out = run_guards(mutant.guards, root, timeout, env)
    if status is None:
        return Outcome(mutant, "killed (timeout)", seconds, f"guards still running after {timeout} s", out)
    if status == 0:
        return Outcome(mutant, "survived", seconds, _summary_line(out), out)
    if status in _KILLED:
        return Outcome(mutant, _KILLED[status], seconds, _summary_line(out), out)
    return Outcome(mutant, "error", seconds, f"pytest exit status {status}: {_summary_line(out)}", out)


def run_mutants(mutants, root=ROOT, timeout=DEFAULT_TIMEOUT, env=None, log_dir=None,
                progress=print):
    """Every mutant in turn, a progress line each; returns the outcomes."""
    outcomes = []
    width = max(len(m.id) for m in mutants)
    for n, mutant in enumerate(mutants, 1):
        progress(f"[{n}/{len(mutants)}] {mutant.id:<{width}} ...", end=" ", flush=True)
        outcome = run_mutant(mutant, root, timeout, env)
        outcomes.append(outcome)
        tail = f" {outcome.detail}" if outcome.status in ("survived", "error") else ""
        progress(f"{outcome.status} ({outcome.seconds:.1f} s){tail}", flush=True)
        if log_dir is not None and outcome.log:
            Path(log_dir).mkdir(parents=True, exist_ok=True)
            (Path(log_dir) / f"{mutant.id}.log").write_text(outcome.log)
    return outcomes


def kill_ratio(outcomes):
    """(killed, counted): equivalent mutants are not counted."""
    counted = [o for o in outcomes if o.status != "equivalent"]
    return sum(o.killed for o in counted), len(counted)


def markdown(outcomes, command, wall_s):
    """The results table of docs/mutation.md."""
    killed, counted = kill_ratio(outcomes)
    lines = [f"Generated by `{command}`: {killed} of {counted} mutants killed "
             f"({100 * killed / max(counted, 1):.0f} %), "
             f"{sum(o.status == 'equivalent' for o in outcomes)} listed as equivalent; "
             f"wall time {wall_s / 60:.1f} min.", "",
             made_at(Config(), "the default Config of the tree the mutants were applied to") + ".", "",
             "| mutant | models | guarding tests | result | seconds |", "|---|---|---|---|---|"]
    for o in outcomes:
        m = o.mutant
        guards = "<br>".join(f"`{g}`" for g in m.guards) or "—"
        result = o.status if o.status != "equivalent" else f"equivalent: {m.equivalent}"
        if o.status in ("survived", "error"):
            result += f" ({o.detail})"
        cell = lambda text: text.replace("|", "\\|")
        lines.append(f"| `{m.id}` | {cell(m.models)} | {guards} | {cell(result)} | {o.seconds:.1f} |")
    return "\n".join(lines)


BEGIN, END = "<!-- mutate:begin -->", "<!-- mutate:end -->"


def write_doc(path, table):
    """Put ``table`` between the BEGIN and END markers of ``path``."""
    path = Path(path)
    text = path.read_text() if path.exists() else f"# Mutation check\n\n{BEGIN}\n{END}\n"
    if BEGIN not in text or END not in text:
        text = text.rstrip("\n") + f"\n\n{BEGIN}\n{END}\n"
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    path.write_text(f"{head}{BEGIN}\n{table}\n{END}{tail}")


def tree_files(root=ROOT):
    """The files of the working tree: git's tracked and untracked, non-ignored files."""
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=root,
                         capture_output=True, text=True, check=True)
    return [f for f in out.stdout.split("\0") if f and (Path(root) / f).is_file()]


def copy_tree(dest, root=ROOT):
    """Copy the working tree to ``dest`` (emptied first) and make ``import bumprtl`` resolve
    there: ``dest/.mutate-path/bumprtl`` links to its rtl, gen, sim and constraints (as
    pyproject's package-dir maps them). Returns the environment that runs the copy."""
    dest, root = Path(dest).resolve(), Path(root).resolve()
    inside = dest == root or root in dest.parents
    if dest in root.parents or (inside and dest.relative_to(root).parts[:1] != ("build",)):
        raise MutantError(f"--copy {dest}: must be outside the tree or under its build/")
    if dest.exists():
        shutil.rmtree(dest)
    for name in tree_files(root):
        target = dest / name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(Path(root) / name, target)
    return _import_shim(dest, root)


def _import_shim(dest, root):
    """``import bumprtl`` resolving in the tree at ``dest`` (packages mapped as ``root``'s
    pyproject.toml maps them); returns the environment that runs it."""
    with open(Path(root) / "pyproject.toml", "rb") as f:
        mapping = tomllib.load(f)["tool"]["setuptools"]["package-dir"]
    shim = dest / ".mutate-path" / "bumprtl"
    shim.mkdir(parents=True)
    for pkg, folder in mapping.items():
        (shim / pkg.split(".", 1)[1]).symlink_to(dest / folder, target_is_directory=True)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(dest / ".mutate-path")] +
                                        ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    return env


def tree_archive(root=ROOT):
    """The working tree's files (:func:`tree_files`) as gzip'd tar bytes: what a mutant job
    carries to a worker that may not share this machine's filesystem."""
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w:gz") as tar:
        for name in tree_files(root):
            tar.add(Path(root) / name, arcname=name)
    return buf.getvalue()


def unpack_tree(archive, dest):
    """Unpack :func:`tree_archive`'s bytes into ``dest`` with ``import bumprtl`` resolving
    there (the same shim as :func:`copy_tree`); returns the environment that runs it."""
    dest = Path(dest).resolve()
    dest.mkdir(parents=True, exist_ok=True)
    with tarfile.open(fileobj=io.BytesIO(archive), mode="r:gz") as tar:
        tar.extractall(dest, filter="data")
    return _import_shim(dest, dest)


def mutant_job(archive, mutant, timeout, guards=()):
    """One mutant as a job of bumprtl's job layer (gen/tools/jobs.py): the tree unpacked in a
    temporary directory of the worker, the mutant applied there and its guards run; with
    ``mutant`` None, ``guards`` run on the unmutated tree (the baseline). Returns
    ``{"outcome": Outcome or (status, seconds, output), "log": pytest's output}``."""
    with tempfile.TemporaryDirectory(prefix="bumprtl-mutate-") as tmp:
        root = Path(tmp) / "tree"
        env = unpack_tree(archive, root)
        if mutant is None:
            status, seconds, out = run_guards(guards, root, timeout, env)
            return {"outcome": (status, seconds, out), "log": out}
        outcome = run_mutant(mutant, root, timeout, env)
    return {"outcome": outcome, "log": outcome.log}


def run_as_jobs(mutants, archive, args):
    """The baseline (unless ``--no-baseline``) and every mutant as jobs: a local cluster of
    ``args.jobs`` workers or ``args.scheduler``'s. Returns ``(baseline or None, outcomes)``;
    a job that fails (a worker lost each time, a timeout) is an ``error`` outcome."""
    if __name__ != "__main__":       # (__main__'s functions travel by value anyway)
        cloudpickle.register_pickle_by_value(sys.modules[__name__])   # workers need no tests/
    jobs = []
    if not args.no_baseline:
        guards = sorted({g for m in mutants if not m.equivalent for g in m.guards})
        jobs.append(Job("mutate-baseline", mutant_job, (archive, None, args.timeout * 4, guards)))
    jobs += [Job(job_name("mutate", m.id), mutant_job, (archive, m, args.timeout)) for m in mutants]
    with Runner(scheduler_address(args.scheduler), args.jobs) as runner:
        out = runner.run(jobs, desc="mutate")
    baseline = None
    if not args.no_baseline:
        o = out["mutate-baseline"]
        baseline = o.value["outcome"] if o.ok else (None, o.seconds, o.error)
    outcomes = []
    for m in mutants:
        o = out[job_name("mutate", m.id)]
        outcomes.append(o.value["outcome"] if o.ok else Outcome(m, "error", o.seconds, o.error))
    return baseline, outcomes


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m tests.mutants.curated",
                                description="Apply each curated mutant, run the tests that guard "
                                            "it, report killed or survived (make mutate).")
    p.add_argument("--list", type=Path, default=DEFAULT_LIST,
                   help=f"the mutant list, relative to the tree (default: {DEFAULT_LIST})")
    p.add_argument("-k", dest="select", action="append", default=[],
                   help="run only mutants whose id contains this text (repeatable)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--copy", type=Path, default=DEFAULT_COPY,
                       help=f"copy the working tree here and mutate the copy, so others may "
                            f"keep working in the tree (default: {DEFAULT_COPY})")
    where.add_argument("--in-place", action="store_true",
                       help="mutate the working tree itself (each file restored and its "
                            "content hash checked after each mutant)")
    where.add_argument("--jobs", type=int, default=None, metavar="N",
                       help="run the mutants as jobs of bumprtl's job layer on N local worker "
                            "processes, each mutating its own unpacked copy of the tree")
    where.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                       help="run the mutants as jobs on this Dask scheduler's workers (the tree "
                            "travels with each job; the workers need bumprtl's [dev] packages)")
    p.add_argument("--timeout", type=int, default=DEFAULT_TIMEOUT,
                   help=f"seconds per mutant's guard run (default: {DEFAULT_TIMEOUT})")
    p.add_argument("--no-baseline", action="store_true",
                   help="skip the run of every guard on the unmutated code")
    p.add_argument("--check", action="store_true",
                   help="only check that the list parses and every mutant applies")
    p.add_argument("--doc", type=Path, default=None,
                   help="write the results table into this markdown file (between markers)")
    p.add_argument("--logs", type=Path, default=Path("build/mutate/logs"),
                   help="pytest output of each mutant's run (default: build/mutate/logs)")
    args = p.parse_args(argv)
    # SIGTERM (a killed make) unwinds like Ctrl-C, so the mutated file is restored.
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    t0 = time.perf_counter()
    root, env = ROOT, None
    try:
        mutants = load_mutants(ROOT / args.list)
        if args.select:
            mutants = [m for m in mutants if any(s in m.id for s in args.select)]
            if not mutants:
                raise MutantError(f"-k {' '.join(args.select)}: no mutant id matches")
        if (args.jobs or args.scheduler) and not args.check:
            return _main_jobs(mutants, args, t0, argv)
        if not args.in_place and not args.check:
            env = copy_tree(args.copy)
            root = args.copy.resolve()
            print(f"mutating a copy of the tree in {root}")
    except MutantError as e:
        print(f"mutate: error: {e}", file=sys.stderr)
        return 2
    broken = []
    for m in mutants:
        try:
            check_applies(m, root)
        except MutantError as e:
            broken.append(str(e))
    if broken or args.check:
        for line in broken:
            print(f"mutate: error: {line}", file=sys.stderr)
        if not broken:
            print(f"{len(mutants)} mutants parse and apply")
        return 1 if broken else 0
    if not args.no_baseline:
        guards = sorted({g for m in mutants if not m.equivalent for g in m.guards})
        print(f"baseline: {len(guards)} guards on the unmutated code ...", end=" ", flush=True)
        status, seconds, out = run_guards(guards, root, args.timeout * 4, env)
        print(f"{'passed' if status == 0 else 'FAILED'} ({seconds:.1f} s)")
        if status != 0:
            print(out[-4000:], file=sys.stderr)
            print("mutate: error: the guards fail on the unmutated code; fix them first",
                  file=sys.stderr)
            return 1
    logs = args.logs if args.logs.is_absolute() else root / args.logs
    try:
        outcomes = run_mutants(mutants, root, args.timeout, env, logs)
    except RestoreError as e:
        print(f"\nmutate: error: {e}", file=sys.stderr)
        return 1
    return _finish(outcomes, args, t0, argv)


def _main_jobs(mutants, args, t0, argv):
    """main's --jobs / --scheduler path: every mutant a job (:func:`run_as_jobs`)."""
    if args.jobs is not None and args.jobs < 1:
        raise MutantError(f"--jobs must be >= 1, got {args.jobs}")
    try:
        scheduler_address(args.scheduler)
        baseline, outcomes = run_as_jobs(mutants, tree_archive(), args)
    except SchedulerError as e:
        print(f"mutate: error: {e}", file=sys.stderr)
        return 2
    if baseline is not None:
        status, seconds, out = baseline
        print(f"baseline: {'passed' if status == 0 else 'FAILED'} ({seconds:.1f} s)")
        if status != 0:
            print(out[-4000:], file=sys.stderr)
            print("mutate: error: the guards fail on the unmutated code; fix them first",
                  file=sys.stderr)
            return 1
    for o in outcomes:
        tail = f" {o.detail}" if o.status in ("survived", "error") else ""
        print(f"{o.mutant.id} {o.status} ({o.seconds:.1f} s){tail}")
    return _finish(outcomes, args, t0, argv)


def _finish(outcomes, args, t0, argv):
    wall = time.perf_counter() - t0
    killed, counted = kill_ratio(outcomes)
    given = sys.argv[1:] if argv is None else list(argv)
    command = "make mutate" + (f" MUTATE_ARGS=\"{' '.join(given)}\"" if given else "")
    table = markdown(outcomes, command, wall)
    print()
    print(table)
    if args.doc is not None:
        write_doc(ROOT / args.doc if not args.doc.is_absolute() else args.doc, table)
        print(f"wrote {args.doc}")
    bad = [o for o in outcomes if o.status in ("survived", "error")]
    print(f"\n{killed} of {counted} mutants killed; {len(bad)} survived or failed to run; "
          f"wall time {wall:.0f} s")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
