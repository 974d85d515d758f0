"""The command line the figure scripts share (--preset, --runs, --out, --allow-missing, --da) and the loading of
a figure's runs with one clear line when a result file is missing or damaged."""
from __future__ import annotations

import argparse
import pathlib
import sys

from enamel_results import paths
from enamel_results.paper_values import DEFAULT_SNAPSHOT_DA
from enamel_results.results import EXIT_DAMAGED, EXIT_MISSING, DamagedResult, MissingResult, load_result


def argument_parser(description: str, maps: bool = False) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=description,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--preset", default="reduced",
                   help="preset whose results are read: runs/PRESET/<case>/result.h5 (default: reduced)")
    p.add_argument("--runs", type=pathlib.Path, default=None,
                   help=f"root of the result files instead of {paths.RUNS} (tests)")
    p.add_argument("--out", type=pathlib.Path, default=None,
                   help=f"root of the output instead of {paths.FIGURES_OUT}; files go to OUT/PRESET/")
    p.add_argument("--allow-missing", action="store_true",
                   help="draw what exists and skip missing result files (default: a missing file is an error)")
    if maps:
        p.add_argument("--da", type=float, default=None,
                       help="Delta_a/d of the process-zone maps: the frame written nearest this advance "
                            "(default: the paper's, or %g)" % DEFAULT_SNAPSHOT_DA)
    return p


def fail_missing(script: str, missing: list[pathlib.Path], preset: str) -> None:
    """One clear line on stderr naming the missing file and the command that produces it; exit non-zero."""
    script = pathlib.Path(script).name
    more = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
    print(f"{script}: missing result file {missing[0]}{more}: run `{paths.make_command(preset)}` to produce it",
          file=sys.stderr)
    sys.exit(EXIT_MISSING)


def fail_damaged(script: str, damaged: list, preset: str) -> None:
    """One line on stderr per damaged result file ("damaged result ...: rerun"), then exit non-zero."""
    for e in damaged:
        print(f"{pathlib.Path(script).name}: {e} (`{paths.make_command(preset)}` reruns it)", file=sys.stderr)
    sys.exit(EXIT_DAMAGED)


def load_cases(script: str, args, cases: list[str], full: bool = False, slow: bool = False) -> dict:
    """{case: Result} for the cases that exist; a missing file ends the script unless --allow-missing
    (slow twins are optional: missing ones are skipped silently); a damaged one ends it with a line saying
    "damaged result ...: rerun" (skipped with that line as a warning under --allow-missing)."""
    out, missing, damaged = {}, [], []
    for c in cases:
        p = paths.result_file(args.preset, c, slow=slow, runs=args.runs)
        try:
            out[c] = load_result(p, case=c, full=full)
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
            fail_missing(script, missing, args.preset)
    if not out and not slow:
        if damaged:
            fail_damaged(script, damaged, args.preset)
        fail_missing(script, missing, args.preset)
    return out
