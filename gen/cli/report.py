"""``bumprtl report KIND``: reports recounted from our netlists and placements.

Each kind lives in its own module of gen/report/ with ``add_parser(subparsers)``; register
it in REPORTS.
"""

from bumprtl.gen.flow.quiet import quiet_commands
from bumprtl.gen.report import fpga, integration, table1, timing

# kind -> module of gen/report/ providing add_parser(subparsers), in `--help` order.
REPORTS = {
    "table1": table1,
    "fpga": fpga,
    "timing": timing,
    "integration": integration,
}


def add_parser(sub):
    p = sub.add_parser("report", help="Table 1 recount and FPGA cost reports",
                       description="Reports: `table1` (Lee et al. Table 1 recounted from Yosys "
                                   "netlists, docs/table1.md) and `fpga` (ECP5 LUT/FF/DSP/BRAM/Fmax, "
                                   "docs/report.md), `timing` (docs/timing.md) and `integration` "
                                   "(docs/integration.md's generated blocks).")
    kinds = p.add_subparsers(dest="kind", metavar="KIND")
    kinds.required = True
    for module in REPORTS.values():
        module.add_parser(kinds)
    quiet_commands(kinds, "build/report")     # Yosys', nextpnr's output to build/report/KIND.log
