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
