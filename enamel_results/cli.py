"""The command line the figure scripts share (--preset, --runs, --records, --out, --allow-missing, --da) and the
loading of a figure's runs, each from its result file or else its record (enamel_results.paths.find_result), with
one clear line when both are missing or the one found is damaged."""
from __future__ import annotations

import argparse
import pathlib
import sys

from enamel_results import paths
from enamel_results.paper_values import DEFAULT_SNAPSHOT_DA
from enamel_results.records import load
from enamel_results.results import EXIT_DAMAGED, EXIT_MISSING, DamagedResult, MissingResult


def argument_parser(description: str, maps: bool = False) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=description,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--preset", default="reduced",
                   help="preset whose results are read: runs/PRESET/<case>/result.h5 (default: reduced)")
    p.add_argument("--runs", type=pathlib.Path, default=None,
                   help=f"root of the result files instead of {paths.RUNS} (tests)")
    p.add_argument("--records", type=pathlib.Path, default=None,
                   help=f"root of the run records read where a run's result file is not there (RECORDS/PRESET/"
                        f"<run>.json; default: {paths.RECORDS} without --runs, none with --runs)")
    p.add_argument("--out", type=pathlib.Path, default=None,
                   help=f"root of the output instead of {paths.FIGURES_OUT}; files go to OUT/PRESET/")
    p.add_argument("--allow-missing", action="store_true",
                   help="draw what exists and skip missing result files (default: a missing file is an error)")
    if maps:
        p.add_argument("--da", type=float, default=None,
                       help="Delta_a/d of the process-zone maps: the frame written nearest this advance "
                            "(default: the paper's, or %g)" % DEFAULT_SNAPSHOT_DA)
    return p


def records_root(args) -> pathlib.Path | None:
    """Where a figure script looks for records: --records, else records/ unless --runs names other runs (a test's
    or a scratch runs tree never mixes with the committed records)."""
    if getattr(args, "records", None) is not None:
        return args.records
    return paths.RECORDS if getattr(args, "runs", None) is None else None


def fail_missing(script: str, missing: list[pathlib.Path], preset: str, records: pathlib.Path | None = None) -> None:
    """One clear line on stderr naming the missing file (and where its record was looked for) and the command that
    produces it; exit non-zero."""
    script = pathlib.Path(script).name
    more = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
    where = f" and no record in {records / preset}" if records is not None else ""
    print(f"{script}: missing result file {missing[0]}{more}{where}: run `{paths.make_command(preset)}` to "
          f"produce it", file=sys.stderr)
    sys.exit(EXIT_MISSING)


def fail_damaged(script: str, damaged: list, preset: str) -> None:
    """One line on stderr per damaged result file ("damaged result ...: rerun"), then exit non-zero."""
    for e in damaged:
        print(f"{pathlib.Path(script).name}: {e} (`{paths.make_command(preset)}` reruns it)", file=sys.stderr)
    sys.exit(EXIT_DAMAGED)


def load_cases(script: str, args, cases: list[str], full: bool = False, slow: bool = False) -> dict:
    """{case: Result} for the cases whose result file or record exists (paths.find_result: the run's result.h5
    when it is there, else its record); a missing one ends the script unless --allow-missing (slow twins are
    optional: missing ones are skipped silently); a damaged one ends it with a line saying "damaged result ...:
    rerun" or "malformed record ..." (skipped with that line as a warning under --allow-missing)."""
    out, missing, damaged = {}, [], []
    records = records_root(args)
    for c in cases:
        p = paths.find_result(args.preset, c, slow=slow, runs=args.runs, records=records)
        try:
            out[c] = load(p, case=c, full=full)
        except MissingResult:
            missing.append(p)
        except DamagedResult as e:
            damaged.append(e)
    if damaged:
        if not args.allow_missing:
            fail_damaged(script, damaged, args.preset)
        for e in damaged:
            print(f"{pathlib.Path(script).name}: warning: skipping {e}", file=sys.stderr)
    if missing and not slow:
        if args.allow_missing:
            for p in missing:
                print(f"{pathlib.Path(script).name}: warning: skipping missing {p}", file=sys.stderr)
        else:
            fail_missing(script, missing, args.preset, records)
    if not out and not slow:
        if damaged:
            fail_damaged(script, damaged, args.preset)
        fail_missing(script, missing, args.preset, records)
    return out
