#!/usr/bin/env python3
"""Run records (enamel_results/records.py): write, check, bring up to date, and draw the figures from them.

    python3 -m pipeline.records write RESULT_H5 RECORD_JSON [--da X ...]    record one result file
    python3 -m pipeline.records check RECORD_JSON [--result RESULT_H5]       is it a record, and of that file?
    python3 -m pipeline.records update --preset P [--runs R] [--records D]   `make records`
    python3 -m pipeline.records figures --preset P [--runs R] [--records D] [--out O]   `make figures-recorded`
    python3 -m pipeline.records publish --preset P [--runs R] [--records D] [--docs DIR]  `make publish`

update records every completed run of the figure set (runs/P/<run>/result.h5) that has no record in
records/P/<run>.json, or whose record is of another, older run (its sha256 differs and its /meta written_utc is
earlier); a record of a newer run than the one there is kept, with a warning. A malformed record of a run that is
there, or a damaged result file, stops it before anything is written (one line naming each).
figures makes every figure (and the summary table) whose cases all have a run or a record, from those, running
nothing, and lists the missing cases of the others (half-rate twins are optional: a figure without them is drawn
without them, as the figure scripts do).
publish draws as figures does, then copies each figure made and the summary into DIR/P/ (default docs/figures/P/)
as small committed files: each PNG reduced to a 256-colour palette and refused above PUBLISHED_PNG_BYTES, the
summary.md as it is, and an index.md saying when, from which solver commits, and for each figure the runs it
was drawn from, the twins it lacks or the cases still missing. A figure not made leaves its earlier copy out.
"""
from __future__ import annotations

import argparse
import os
import pathlib
import subprocess
import sys
import time

from enamel_results import cases, paths, records
from enamel_results.results import (EXIT_DAMAGED, EXIT_MISSING, DamagedResult, MissingResult, load_result,
                                    verify_result_file)
from pipeline.make_rules import figure_set


def figure_runs() -> list[tuple[str, bool]]:
    """Every run of the figure set once: (case, slow), the cases first, then the half-rate twins."""
    _, all_cases, all_slow = figure_set()  # the list Make runs
    return [(c, False) for c in all_cases] + [(c, True) for c in all_slow]


def kb(path: pathlib.Path) -> str:
    return f"{path.stat().st_size / 1000:.0f} kB"


def cmd_write(a) -> int:
    t = time.monotonic()
    records.write_record(a.result, a.record, frames_da=a.da)
    print(f"record: {a.result} -> {a.record} ({kb(a.record)}, {time.monotonic() - t:.1f} s)")
    return 0


def cmd_check(a) -> int:
    rec = records.read_record(a.record)
    print(f"record: {a.record}: a record of {rec['case']} ({rec['meta'].get('status')}, solver {rec['solver_commit']}, "
          f"from {rec['source']['file']}, sha256 {rec['source']['sha256'][:12]})")
    if a.result is not None:
        if not records.record_is_of(rec, a.result):
            print(f"record: {a.record} is not a record of {a.result} (another sha256)", file=sys.stderr)
            return 1
        print(f"record: {a.record} is a record of {a.result}")
    return 0


def plan_update(a) -> tuple[list, list, list, list]:
    """(to write [(result, record, why)], up to date [record], kept [line], bad [a damaged result file's or a
    malformed record's DamagedResult]) for every completed run of the figure set."""
    todo, fresh, kept, bad = [], [], [], []
    for case, slow in figure_runs():
        result = paths.result_file(a.preset, case, slow=slow, runs=a.runs)
        record = paths.record_file(a.preset, case, slow=slow, records=a.records)
        if not result.is_file():
            continue
        try:
            verify_result_file(result)
        except DamagedResult as e:
            bad.append(e)
            continue
        if not record.is_file():
            todo.append((result, record, "no record"))
            continue
        try:
            rec = records.read_record(record)
        except records.MalformedRecord as e:
            bad.append(e)
            continue
        if records.record_is_of(rec, result):
            fresh.append(record)
            continue
        ours, theirs = load_result(result).meta.get("written_utc", ""), rec["meta"].get("written_utc", "")
        if str(ours) >= str(theirs):
            todo.append((result, record, f"its record is of an older run (written {theirs})"))
        else:
            kept.append(f"records: kept {record}: it is of a newer run (written {theirs}) than {result} ({ours})")
    return todo, fresh, kept, bad


def cmd_update(a) -> int:
    todo, fresh, kept, bad = plan_update(a)
    if bad:  # one line per damaged result file or malformed record of a run that is there, before anything is written
        for e in bad:
            print(f"records: {e}", file=sys.stderr)
        return EXIT_DAMAGED
    for line in kept:
        print(line, file=sys.stderr)
    for n, (result, record, why) in enumerate(todo, 1):
        t = time.monotonic()
        records.write_record(result, record)
        print(f"records: [{n}/{len(todo)}] {record} from {result} ({why}; {kb(record)}, "
              f"{time.monotonic() - t:.1f} s)", flush=True)
    runs = figure_runs()
    done = sum(paths.record_file(a.preset, c, slow=slow, records=a.records).is_file() for c, slow in runs)
    print(f"records: {len(todo)} written, {len(fresh)} up to date, {len(kept)} kept, in {a.records / a.preset}/: "
          f"{done} of the figure set's {len(runs)} runs are recorded (a run of {a.runs / a.preset}/ without "
          f"result.h5 is not finished: nothing to record)")
    return 0


def available(a, case: str, slow: bool = False) -> bool:
    """Whether a run has its result file or its record (paths.find_result)."""
    return paths.find_result(a.preset, case, slow=slow, runs=a.runs, records=a.records).is_file()


def solver_commits(a, runs: list[tuple[str, bool]]) -> str:
    """'c09beab (40), e22f90a (3)': the solver commits of the runs and records there (/meta git_hash)."""
    count = {}
    for case, slow in runs:
        p = paths.find_result(a.preset, case, slow=slow, runs=a.runs, records=a.records)
        if p.is_file():
            try:
                commit = str(records.load(p).meta.get("git_hash", "unknown"))
            except DamagedResult:
                continue
            count[commit] = count.get(commit, 0) + 1
    return ", ".join(f"{c} ({n})" for c, n in sorted(count.items(), key=lambda kv: -kv[1])) or "none"


PUBLISHED_PNG_BYTES = 400_000   # the most a published figure may weigh (docs/ is in git)


def draw_figures(a) -> list[dict]:
    """Each figure (and the summary table) drawn where its cases all have a run or a record: a dict per job with
    its name, module, status ('made', 'failed', 'missing'), cases, and the missing cases or twins."""
    figures = cases.figure_list()
    jobs = [(f"figures.{stem}", fig, figures[fig]) for fig, stem in cases.figure_scripts().items()]
    everything = {"cases": list(dict.fromkeys(c for e in figures.values() for c in e.get("cases", []))),
                  "slow": list(dict.fromkeys(c for e in figures.values() for c in e.get("slow", [])))}
    jobs.append(("figures.summary_table", "summary table", everything))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(paths.ROOT), os.environ.get("PYTHONPATH")])))
    done = []
    for module, name, table in jobs:
        job = dict(name=name, module=module, cases=list(table.get("cases", [])),
                   missing=[c for c in table.get("cases", []) if not available(a, c)],
                   no_twin=[c for c in table.get("slow", []) if not available(a, c, slow=True)])
        done.append(job)
        if job["missing"]:
            job["status"] = "missing"
            print(f"figures-recorded: {name}: not made, {len(job['missing'])} of {len(job['cases'])} cases have "
                  f"neither a run nor a record: {' '.join(job['missing'])}")
            continue
        cmd = [sys.executable, "-m", module, "--preset", a.preset, "--runs", str(a.runs), "--records", str(a.records)]
        cmd += ["--out", str(a.out)] if a.out is not None else []
        print(f"figures-recorded: {name}: from {len(job['cases'])} runs and records" +
              (f" (without the half-rate twin of {' '.join(job['no_twin'])})" if job["no_twin"] else ""), flush=True)
        job["status"] = "made" if subprocess.run(cmd, cwd=paths.ROOT, env=env).returncode == 0 else "failed"
    return done


def cmd_figures(a) -> int:
    jobs = draw_figures(a)
    made, failed = (sum(j["status"] == s for j in jobs) for s in ("made", "failed"))
    print(f"figures-recorded: {made} of {len(jobs)} made in {paths.figure_dir(a.preset, a.out)}/"
          + (f", {failed} failed" if failed else "") + f"; solver commits of the runs and records: "
          f"{solver_commits(a, figure_runs())}")
    return 1 if failed else 0


def palette_png(source: pathlib.Path, target: pathlib.Path) -> int:
    """The figure reduced to a 256-colour palette (the figures' few flat colours survive it), written to target;
    its size in bytes."""
    from PIL import Image
    with Image.open(source) as im:
        im.convert("RGB").quantize(colors=256, method=Image.Quantize.MEDIANCUT,
                                   dither=Image.Dither.NONE).save(target, optimize=True)
    return target.stat().st_size


def published_name(job: dict) -> str:
    """The file a drawing job publishes: its figure's PNG, or the summary table's summary.md."""
    stem = job["module"].split(".")[-1]
    return "summary.md" if stem == "summary_table" else f"{stem}.png"


def publish_index(a, jobs: list[dict], published: list[str]) -> str:
    """docs/figures/P/index.md: when and from what the published figures were drawn, and what is still missing."""
    lines = [f"# The `{a.preset}` figure set as published", "",
             f"Drawn {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} by `make publish PRESET={a.preset}` "
             f"(`python3 -m pipeline.records publish`) from the runs and records there; solver commits (runs): "
             f"{solver_commits(a, figure_runs())}. Each figure is the one `make figures-recorded` draws, reduced to a "
             f"256-colour palette.", "", "| figure | file | drawn from |", "|---|---|---|"]
    for j in jobs:
        if j["status"] == "made":
            name = published_name(j)
            file = f"[{name}]({name})" if name in published else "-"
            twins = f"; without the half-rate twin of {', '.join(j['no_twin'])}" if j["no_twin"] else ""
            lines.append(f"| {j['name']} | {file} | {len(j['cases'])} runs and records{twins} |")
        elif j["status"] == "missing":
            lines.append(f"| {j['name']} | not drawn | {len(j['cases']) - len(j['missing'])} of {len(j['cases'])} "
                         f"runs and records; missing: {', '.join(j['missing'])} |")
        else:
            lines.append(f"| {j['name']} | not drawn | its script failed (run `make figures-recorded`) |")
    lines += ["", f"<!-- generated by: make publish PRESET={a.preset} (python3 -m pipeline.records publish) -->"]
    return "\n".join(lines) + "\n"


def cmd_publish(a) -> int:
    jobs = draw_figures(a)
    source, target = paths.figure_dir(a.preset, a.out), a.docs / a.preset
    target.mkdir(parents=True, exist_ok=True)
    published, too_big = [], []
    for j in jobs:
        name = published_name(j)
        if j["status"] != "made":
            (target / name).unlink(missing_ok=True)   # an earlier copy would disagree with the index
            continue
        if name.endswith(".md"):
            (target / name).write_bytes((source / name).read_bytes())
            published.append(name)
            continue
        size = palette_png(source / name, target / name)
        if size > PUBLISHED_PNG_BYTES:
            (target / name).unlink()
            too_big.append(f"{name} ({size / 1000:.0f} kB)")
        else:
            published.append(name)
    (target / "index.md").write_text(publish_index(a, jobs, published))
    print(f"publish: {len(published)} files in {target}/ ({', '.join(published) or 'none'}) and index.md")
    if too_big:
        print(f"publish: refused above {PUBLISHED_PNG_BYTES / 1000:.0f} kB after the palette: {', '.join(too_big)}",
              file=sys.stderr)
    return 1 if too_big or any(j["status"] == "failed" for j in jobs) else 0


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    w = sub.add_parser("write", help="record one result file")
    w.add_argument("result", type=pathlib.Path, help="a completed run's result.h5")
    w.add_argument("record", type=pathlib.Path, help="the record to write (.json)")
    w.add_argument("--da", type=float, action="append", default=None,
                   help="Delta_a/d of a map to hold (the frame nearest it; repeatable; default: the figures' %s)"
                        % ", ".join(f"{x:g}" for x in records.recorded_da()))
    c = sub.add_parser("check", help="check a record (and that it is of a result file)")
    c.add_argument("record", type=pathlib.Path)
    c.add_argument("--result", type=pathlib.Path, default=None, help="the result.h5 it should be a record of")
    for name, text in (("update", "record every completed run of a preset that has no record or an older one"),
                       ("figures", "make every figure whose cases all have a run or a record, running nothing"),
                       ("publish", "draw as figures does, then copy the figures made and the summary into "
                                   "DOCS/PRESET/ as small files, with an index")):
        p = sub.add_parser(name, help=text, description=text)
        p.add_argument("--preset", required=True, help="ci | reduced | converged | paper")
        p.add_argument("--runs", type=pathlib.Path, default=paths.RUNS, help=f"root of the runs (default {paths.RUNS})")
        p.add_argument("--records", type=pathlib.Path, default=paths.RECORDS,
                       help=f"root of the records (default {paths.RECORDS})")
        if name in ("figures", "publish"):
            p.add_argument("--out", type=pathlib.Path, default=None,
                           help=f"root of the figures instead of {paths.FIGURES_OUT}; files go to OUT/PRESET/")
        if name == "publish":
            p.add_argument("--docs", type=pathlib.Path, default=paths.ROOT / "docs" / "figures",
                           help="root of the published copies (default docs/figures); files go to DOCS/PRESET/")
    return ap


def main(argv=None) -> int:
    a = parser().parse_args(argv)
    if a.command == "write" and a.record.suffix != paths.RECORD_SUFFIX:
        print(f"records: {a.record}: a record's name ends in {paths.RECORD_SUFFIX}", file=sys.stderr)
        return 2
    try:
        return {"write": cmd_write, "check": cmd_check, "update": cmd_update, "figures": cmd_figures,
                "publish": cmd_publish}[a.command](a)
    except (FileNotFoundError, MissingResult) as e:
        print(f"records: no such file: {getattr(e, 'filename', None) or e.path}", file=sys.stderr)
        return EXIT_MISSING
    except DamagedResult as e:  # a damaged result file or a malformed record: one line naming it
        print(f"records: {e}", file=sys.stderr)
        return EXIT_DAMAGED


if __name__ == "__main__":
    sys.exit(main())
