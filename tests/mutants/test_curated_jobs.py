"""The curated mutants as jobs (tests/mutants/curated.py --jobs / --scheduler): the tree a
job carries unpacks into a copy of the working tree's files, and ``import bumprtl``
resolves to the copy, not to the working tree."""

import io
import subprocess
import sys
import tarfile
from pathlib import Path

from tests.mutants import curated


def test_the_archived_tree_unpacks_and_imports_from_the_copy(tmp_path):
    archive = curated.tree_archive()
    env = curated.unpack_tree(archive, tmp_path / "tree")
    with tarfile.open(fileobj=io.BytesIO(archive), mode="r:gz") as tar:
        members = [m for m in tar.getmembers() if m.isfile()]
        assert {m.name for m in members} >= {"pyproject.toml", "rtl/config.py", "tests/mutants/mutants.toml"}
        assert all((tmp_path / "tree" / m.name).read_bytes() == tar.extractfile(m).read()
                   for m in members)
    out = subprocess.run([sys.executable, "-c", "import bumprtl.rtl.config as c; print(c.__file__)"],
                         env=env, cwd=tmp_path, capture_output=True, text=True, check=True)
    assert Path(out.stdout.strip()).resolve().is_relative_to((tmp_path / "tree").resolve()), out.stdout
