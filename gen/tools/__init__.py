"""Running the external tools: the layer below sim/ and the rest of gen/.

The toolchain lookup (``toolchain``), the Verilator compile cache (``objcache``), the job
layer on Dask (``jobs``), the one Yosys runner (``yosys``), SymbiYosys (``sby``), the
generated pages' marked sections and their ``Made at:`` record (``docs``). These modules import nothing of
bumprtl but ``rtl/`` and each other, so the testbenches and proofs of ``sim/`` may use
them while ``sim/`` still imports nothing else of ``gen/`` (tests/test_import_graph.py,
docs/architecture.md, Layers).
"""
