"""The command line stays in gen/cli/, read from the source of rtl/, sim/ and gen/ with ``ast``:

(a) no module imports another module's private name (``from bumprtl.x import _name``): what
    two modules share has a public name;
(b) no module outside gen/cli/ defines ``add_parser`` or takes an argparse Namespace (a
    parameter named ``args`` read as ``args.attr``): the library functions take typed
    arguments, and gen/cli/ turns the flags into them.

The ``*_is_caught`` tests run the checks on a small tree with one planted offence each.
"""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LAYERS = ("rtl", "sim", "gen")
CLI = ("gen", "cli")


def sources(root=ROOT):
    """``{path relative to root: ast tree}`` of every .py file of rtl/, sim/ and gen/."""
    return {p.relative_to(root): ast.parse(p.read_text(), str(p))
            for layer in LAYERS for p in sorted((root / layer).rglob("*.py"))}


def _module(rel):
    parts = list(rel.with_suffix("").parts)
    return ".".join(["bumprtl", *(parts[:-1] if parts[-1] == "__init__" else parts)])


def private_imports(trees):
    """``file:line: from module import _name`` for each private name imported from another
    module (relative imports resolved against the importing module's package)."""
    bad = []
    for rel, tree in trees.items():
        me = _module(rel)
        package = me.split(".") if rel.name == "__init__.py" else me.split(".")[:-1]
        for node in ast.walk(tree):
            if not isinstance(node, ast.ImportFrom):
                continue
            source = node.module or ""
            if node.level:
                base = package[:len(package) - node.level + 1]
                source = ".".join(base + ([node.module] if node.module else []))
            if not source.startswith("bumprtl") or source == me:
                continue
            for alias in node.names:
                if alias.name.startswith("_") and not alias.name.startswith("__"):
                    bad.append(f"{rel}:{node.lineno}: from {source} import {alias.name}")
    return bad


def _reads_namespace(func):
    params = [a.arg for a in (*func.args.posonlyargs, *func.args.args, *func.args.kwonlyargs)]
    return "args" in params and any(
        isinstance(n, ast.Attribute) and isinstance(n.value, ast.Name) and n.value.id == "args"
        for n in ast.walk(func))


def cli_outside_cli(trees):
    """``{file: [what]}`` of modules outside gen/cli/ defining ``add_parser`` or a function
    that reads ``args.attr`` from a parameter ``args``."""
    bad = {}
    for rel, tree in trees.items():
        if rel.parts[:2] == CLI:
            continue
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                if node.name == "add_parser":
                    bad.setdefault(str(rel), []).append(f"{node.lineno}: def add_parser")
                elif _reads_namespace(node):
                    bad.setdefault(str(rel), []).append(f"{node.lineno}: {node.name}(args)")
    return bad


def test_no_private_name_imported_across_modules():
    assert private_imports(sources()) == []


def test_the_command_line_lives_in_gen_cli():
    assert cli_outside_cli(sources()) == {}


def _tree(tmp_path, files):
    for name, text in files.items():
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    for layer in LAYERS:
        (tmp_path / layer).mkdir(exist_ok=True)
    return sources(tmp_path)


def test_a_private_import_is_caught(tmp_path):
    trees = _tree(tmp_path, {
        "gen/bench/a.py": "def _helper():\n    return 1\n",
        "gen/bench/b.py": "from bumprtl.gen.bench.a import _helper\nfrom .a import _helper as h\n",
        "gen/bench/c.py": "from bumprtl.gen.bench.a import __doc__\n",
    })
    assert private_imports(trees) == [
        "gen/bench/b.py:1: from bumprtl.gen.bench.a import _helper",
        "gen/bench/b.py:2: from bumprtl.gen.bench.a import _helper"]


def test_a_parser_or_namespace_outside_gen_cli_is_caught(tmp_path):
    trees = _tree(tmp_path, {
        "gen/bench/a.py": "def add_parser(sub):\n    pass\n",
        "gen/report/b.py": "def run(args):\n    return args.out\n",
        "gen/report/c.py": "def run(out, args=()):\n    return len(args)\n",
        "gen/cli/d.py": "def add_parser(sub):\n    pass\n\n\ndef run(args):\n    return args.out\n",
    })
    assert cli_outside_cli(trees) == {"gen/bench/a.py": ["1: def add_parser"],
                                      "gen/report/b.py": ["1: run(args)"]}
