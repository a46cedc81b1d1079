"""A second engine agrees: one specimen run to rest in LAMMPS and in poro2d from the same state.

Both start from the specimen's centres and radii, at rest, with no contact history, the
plate fixed where it stands (see ``poro2d.interop.agreement``); each cycles until its
maximum unbalanced-force ratio is below ``--ratio``. Prints the wall forces per metre,
the mean contact force and the coordination number of both, and their differences;
``--json`` writes them with the provenance::

    python benchmarks/lammps_agreement.py paper-out/criterion --ratio 1e-8 --json agreement.json
"""

from __future__ import annotations

import argparse
import sys

from poro2d.console import OutputConsole, Table
from poro2d.interop.agreement import QUANTITIES, compare
from poro2d.interop.settled import RestCase
from poro2d.interop.specimen_data import from_checkpoint
from poro2d.io_utils import Provenance, write_json


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("specimen", help="checkpoint (.npz) or a folder holding specimen.npz")
    ap.add_argument("--ratio", type=float, default=1e-8, help="stop ratio of both codes")
    ap.add_argument("--max-steps", type=int, default=2_000_000)
    ap.add_argument("--workdir", default=None, help="keep LAMMPS' files here")
    ap.add_argument("--json", default=None, help="write the results to this file")
    args = ap.parse_args(argv)

    spec = from_checkpoint(args.specimen)
    r = compare(RestCase(spec, args.ratio, args.max_steps), workdir=args.workdir)
    ours, theirs = r.poro2d, r.lammps
    t = Table(title=f"{spec.n} disks, G = {r.weight_n_per_m:.4g} N/m, stop ratio {args.ratio:g}")
    for col in ("quantity", "poro2d", "LAMMPS", "|diff| / poro2d", "|diff| / G"):
        t.add_column(col, justify="right")
    for key, label in QUANTITIES:
        relg = r.rel_to_weight.get(key)
        t.add_row(
            label, f"{getattr(ours, key):.6g}", f"{getattr(theirs, key):.6g}", f"{r.rel_diff[key]:.2e}",
            "" if relg is None else f"{relg:.2e}",
        )  # fmt: skip
    t.add_row("steps to rest", str(ours.steps), str(theirs.steps), "", "")
    t.add_row("seconds", f"{ours.seconds:.1f}", f"{theirs.seconds:.1f}", "", "")
    console = OutputConsole()
    console.print(t)
    console.print(f"LAMMPS {theirs.lammps_version}")
    if args.json:
        write_json(args.json, dict(r.to_dict(), specimen=spec.source, provenance=Provenance.now().to_dict()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
