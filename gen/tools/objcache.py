"""A compile cache for the Verilator run-time library, run by make as ``$(OBJCACHE)``.

Every Verilator build of a testbench compiles the same run-time sources (verilated.cpp,
verilated_vpi.cpp, verilated_dpi.cpp, verilated_threads.cpp: most of a small build's CPU)
with the same flags. Verilator's makefiles put ``$(OBJCACHE)`` in front of every compile
command; gen/tools/toolchain.py's :func:`tool_env` sets it to ``python -m bumprtl.gen.tools.objcache``.
A compile of a source under ``$VERILATOR_ROOT/include`` is served from the cache directory
``$BUMPRTL_OBJCACHE`` when the compile command, the source and every header it read (the
``-MMD`` dependency file, by content) are the ones cached; any other compile (the design's
own C++, cocotb's main, which includes the design's header) runs the compiler unchanged.
"""

import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

__all__ = ["main"]


def _sha(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _library_compile(cmd):
    """``(source, object)`` when ``cmd`` compiles a Verilator run-time source to an
    explicit ``-o`` object, else None."""
    root = os.environ.get("VERILATOR_ROOT")
    if not root or "-c" not in cmd or "-o" not in cmd or cmd.index("-o") + 1 >= len(cmd):
        return None
    src = Path(cmd[-1])
    include = Path(root, "include").resolve()
    if src.suffix != ".cpp" or not src.is_absolute() or include not in src.resolve().parents:
        return None
    return src, Path(cmd[cmd.index("-o") + 1])


def _key(cmd, src):
    compiler = shutil.which(cmd[0]) or cmd[0]
    st = os.stat(compiler)
    text = json.dumps([cmd, compiler, st.st_size, st.st_mtime_ns, _sha(src)])
    return hashlib.sha256(text.encode()).hexdigest()


def _headers(dep_text):
    """The prerequisites of a make dependency file (``obj: src h1 h2 ...``)."""
    body = dep_text.replace("\\\n", " ").split(":", 1)[1]
    return [w for w in body.split() if w != "\\"]


def _fresh(entry):
    manifest = json.loads((entry / "manifest.json").read_text())
    return all(Path(h).is_file() and _sha(h) == digest for h, digest in manifest.items())


def main(cmd):
    found = _library_compile(cmd)
    cache = os.environ.get("BUMPRTL_OBJCACHE")
    if found is None or not cache:
        os.execvp(cmd[0], cmd)
    src, obj = found
    dep = obj.with_suffix(".d")
    entry = Path(cache) / _key(cmd, src)
    try:
        if _fresh(entry):
            for cached, out in ((entry / "object.o", obj), (entry / "depend.d", dep)):
                tmp = out.with_name(out.name + ".objcache")
                shutil.copyfile(cached, tmp)
                os.replace(tmp, out)
            return 0
    except (OSError, ValueError):
        pass                                    # no entry, or a torn one: compile
    status = subprocess.call(cmd)
    if status != 0 or not dep.is_file():
        return status
    headers = _headers(dep.read_text())
    if all(Path(h).is_absolute() for h in headers):   # nothing from the build directory
        try:
            _store(entry, obj, dep, headers)
        except OSError:
            pass                                # a cache that cannot be written: no cache
    return 0


def _store(entry, obj, dep, headers):
    """Write the entry in a temporary directory and rename it into place (concurrent
    builds: the first rename wins, the others drop their copy)."""
    entry.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=entry.parent, prefix=".tmp-"))
    try:
        shutil.copyfile(obj, tmp / "object.o")
        shutil.copyfile(dep, tmp / "depend.d")
        (tmp / "manifest.json").write_text(json.dumps({h: _sha(h) for h in headers}))
        shutil.rmtree(entry, ignore_errors=True)
        os.replace(tmp, entry)
    except OSError:
        pass
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
