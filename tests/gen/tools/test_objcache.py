"""gen/tools/objcache.py: a Verilator run-time source compiles once, then comes from the cache
until the command, the source or a header it read changes; every other compile runs the
compiler unchanged."""

import os
import stat
import subprocess
import sys


def _setup(tmp_path):
    root = tmp_path / "verilator"
    (root / "include").mkdir(parents=True)
    (root / "include" / "lib.h").write_text("#define LIB_VALUE 41\n")
    (root / "include" / "lib.cpp").write_text('#include "lib.h"\nint lib_value() { return LIB_VALUE; }\n')
    build = tmp_path / "build"
    build.mkdir()
    (build / "design.cpp").write_text("int design() { return 1; }\n")
    log = tmp_path / "calls.log"
    cc = tmp_path / "countcc"                     # the compiler, counting its runs
    cc.write_text(f'#!/bin/sh\necho x >> "{log}"\nexec g++ "$@"\n')
    cc.chmod(cc.stat().st_mode | stat.S_IEXEC)
    env = dict(os.environ, VERILATOR_ROOT=str(root), BUMPRTL_OBJCACHE=str(tmp_path / "cache"))
    return root, build, cc, log, env


def _compile(cc, src, obj, build, env):
    cmd = [sys.executable, "-m", "bumprtl.gen.tools.objcache", str(cc), "-Os", "-MMD", "-c", "-o", obj, str(src)]
    subprocess.run(cmd, cwd=build, env=env, check=True)
    return (build / obj).read_bytes()


def _calls(log):
    return len(log.read_text().split()) if log.exists() else 0


def test_runtime_source_compiles_once_until_a_header_changes(tmp_path):
    root, build, cc, log, env = _setup(tmp_path)
    src = root / "include" / "lib.cpp"
    first = _compile(cc, src, "lib.o", build, env)
    assert _calls(log) == 1 and (build / "lib.d").is_file()
    (build / "lib.o").unlink()
    (build / "lib.d").unlink()
    assert _compile(cc, src, "lib.o", build, env) == first and _calls(log) == 1   # from the cache
    assert (build / "lib.d").read_text().startswith("lib.o:")
    (root / "include" / "lib.h").write_text("#define LIB_VALUE 42\n")          # a header changed
    assert _compile(cc, src, "lib.o", build, env) != first and _calls(log) == 2
    _compile(cc, src, "lib.o", build, {**env, "BUMPRTL_OBJCACHE": ""})         # no cache: compile
    assert _calls(log) == 3


def test_other_sources_always_compile(tmp_path):
    _, build, cc, log, env = _setup(tmp_path)
    for n in (1, 2):
        _compile(cc, build / "design.cpp", "design.o", build, env)
        assert _calls(log) == n
    assert not (tmp_path / "cache").exists()


# In-process cases (the compiler stood in by a function writing the object and its
# dependency file): which commands are library compiles, a failed compile, a header
# from the build directory, a torn cache entry.

def _fake_compiler(monkeypatch, headers, status=0):
    from bumprtl.gen.tools import objcache
    calls = []

    def call(cmd):
        calls.append(cmd)
        obj = __import__("pathlib").Path(cmd[cmd.index("-o") + 1])
        if status == 0:
            obj.write_bytes(b"object %d" % len(calls))
            obj.with_suffix(".d").write_text(f"{obj.name}: {cmd[-1]} \\\n " + " ".join(headers) + "\n")
        return status

    monkeypatch.setattr(objcache.subprocess, "call", call)
    monkeypatch.setattr(objcache.os, "execvp", lambda *a: (_ for _ in ()).throw(
        AssertionError(f"exec {a}")))
    return objcache, calls


def test_only_an_explicit_object_of_a_runtime_source_is_a_library_compile(tmp_path, monkeypatch):
    from bumprtl.gen.tools.objcache import _library_compile
    root = tmp_path / "verilator"
    (root / "include").mkdir(parents=True)
    src = str(root / "include" / "verilated.cpp")
    monkeypatch.setenv("VERILATOR_ROOT", str(root))
    assert _library_compile(["g++", "-c", "-o", "v.o", src]) == \
        (root / "include" / "verilated.cpp", __import__("pathlib").Path("v.o"))
    assert _library_compile(["g++", "-o", "v.o", src]) is None             # no -c: a link
    assert _library_compile(["g++", "-c", src, "-o"]) is None              # -o without a name
    assert _library_compile(["g++", "-c", "-o", "v.o", "include/verilated.cpp"]) is None
    assert _library_compile(["g++", "-c", "-o", "v.o", str(tmp_path / "design.cpp")]) is None
    assert _library_compile(["g++", "-c", "-o", "v.o", str(root / "include" / "x.h")]) is None
    monkeypatch.delenv("VERILATOR_ROOT")
    assert _library_compile(["g++", "-c", "-o", "v.o", src]) is None


def test_headers_of_a_dependency_file_with_continuations():
    from bumprtl.gen.tools.objcache import _headers
    assert _headers("a.o: /s/a.cpp \\\n /i/a.h \\\n /i/b.h\n") == ["/s/a.cpp", "/i/a.h", "/i/b.h"]


def _lib(tmp_path, monkeypatch):
    root = tmp_path / "verilator"
    (root / "include").mkdir(parents=True)
    src = root / "include" / "lib.cpp"
    src.write_text("int x;\n")
    header = root / "include" / "lib.h"
    header.write_text("#define X 1\n")
    monkeypatch.setenv("VERILATOR_ROOT", str(root))
    monkeypatch.setenv("BUMPRTL_OBJCACHE", str(tmp_path / "cache"))
    obj = tmp_path / "lib.o"
    return ["g++", "-MMD", "-c", "-o", str(obj), str(src)], obj, header


def test_a_failed_compile_returns_its_status_and_caches_nothing(tmp_path, monkeypatch):
    cmd, obj, header = _lib(tmp_path, monkeypatch)
    objcache, calls = _fake_compiler(monkeypatch, [str(header)], status=3)
    assert objcache.main(cmd) == 3 and not (tmp_path / "cache").exists()


def test_a_header_from_the_build_directory_is_never_cached(tmp_path, monkeypatch):
    """A relative header is the build directory's (the design's Vtop.h): another design's
    build would find a file of that name, so the compile is never served from the cache."""
    cmd, obj, header = _lib(tmp_path, monkeypatch)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "Vtop.h").write_text("// the design's header\n")
    objcache, calls = _fake_compiler(monkeypatch, [str(header), "Vtop.h"])
    assert objcache.main(cmd) == 0 and objcache.main(cmd) == 0 and len(calls) == 2
    assert not any((tmp_path / "cache").glob("*/manifest.json"))


def test_a_torn_entry_is_compiled_again_and_replaced(tmp_path, monkeypatch):
    cmd, obj, header = _lib(tmp_path, monkeypatch)
    objcache, calls = _fake_compiler(monkeypatch, [str(header)])
    assert objcache.main(cmd) == 0 and len(calls) == 1
    [entry] = (tmp_path / "cache").iterdir()
    (entry / "manifest.json").write_text("{not json")
    obj.unlink()
    assert objcache.main(cmd) == 0 and len(calls) == 2 and obj.read_bytes() == b"object 2"
    obj.unlink()
    assert objcache.main(cmd) == 0 and len(calls) == 2 and obj.read_bytes() == b"object 2"
    assert [p.name for p in (tmp_path / "cache").iterdir()] == [entry.name]   # no .tmp- left
