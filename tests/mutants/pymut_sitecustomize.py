"""Installed as ``sitecustomize.py`` at the top of the copy mutmut runs (tests/mutants/pymut.py).

The cocotb benches of sim/tb run inside a simulator's embedded Python, a process of its
own whose ``PYTHONPATH`` is the test's ``sys.path`` (cocotb_tools.runner), so it imports
the mutated copy and starts with this module. While mutmut records which tests reach each
function (``MUTANT_UNDER_TEST=stats``) its trampolines call ``record_trampoline_hit``,
which reads mutmut's configuration from the working directory: the simulator's build
directory has none, the hit raises and every bench fails the record. Here each hit is
appended to the file ``PYMUT_SIM_HITS`` names instead (each name once a process); the pytest plugin
(tests/mutants/pymut_sim.py) credits them to the test that started the simulator.
Outside the record this module does nothing.
"""

import os


def _install():
    path = os.environ.get("PYMUT_SIM_HITS")
    if os.environ.get("MUTANT_UNDER_TEST") != "stats" or not path:
        return
    try:
        import mutmut.mutation.trampoline as trampoline
    except ImportError:         # not under mutmut
        return

    seen = set()

    def hit(name, caller=None):
        # each name once a process: a bench calls the golden model's functions per pixel,
        # millions of hits, and an append each made files of tens of MB
        if name not in seen:
            seen.add(name)
            with open(path, "a") as f:
                f.write(name + "\n")
    trampoline.record_trampoline_hit = hit


_install()
