"""``bumprtl formal``: SymbiYosys proofs of the stream contract (sim/formal/, docs/formal.md)."""

from bumprtl.gen.formal.run import add_arguments, execute


def run(args):
    return execute(units=args.units, props=args.props, mutants=args.mutants, quick=args.quick,
                   jobs=args.jobs, job_timeout=args.job_timeout, scheduler=args.scheduler,
                   out=args.out, merge=args.merge, from_results=args.from_results, doc=args.doc)


def add_parser(sub):
    p = sub.add_parser("formal", help="prove the stream contract of every unit and scene pipeline",
                       description="k-induction (BMC where it does not close) of the stream "
                                   "contract with SymbiYosys: payload held under stall, every "
                                   "pixel once and in order, latency without bubbles, i.ready "
                                   "while a credit is free, no output without input, the credit "
                                   "loop's invariant (no FIFO overflow), the palette's double "
                                   "buffer; broken units must fail. Prints the "
                                   "proof table; exit 1 and the counterexample trace on failure.")
    add_arguments(p)
    p.set_defaults(func=run)
