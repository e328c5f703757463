"""bumprtl: the generator, flows, benches and reports (the command line is gen/cli/main.py)."""

__version__ = "0.2.0"
