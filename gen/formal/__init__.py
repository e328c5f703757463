"""Running the formal proofs: the jobs, the table and docs/formal.md (``bumprtl formal``).

The properties and the units they are checked on stay with the models in sim/formal/; SymbiYosys
itself is run by gen/tools/sby.py.
"""
