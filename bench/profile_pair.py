"""Two solver binaries' step profiles, interleaved, on the `paper` preset's case: the speed-up as a ratio.

    python3 -m bench.profile_pair --against OLD/enamel-dem [--binary build/enamel-dem] [--rounds 3]
        [--threads 2] [--steps 20] [--out bench/profile_pair.md]

Runs `enamel-dem profile` (the case and knobs of `make bench`'s profile: bench.run_bench.PROFILE_CASE and
PROFILE_SETS) with the old binary, then the new one, `--rounds` times in turn, so both are measured in the same
minutes on the same machine; the wall times of this machine swing by up to 2x, a ratio of interleaved medians
does not. Writes a Markdown page: per round each binary's s/step, DOF-updates/s per core and its phases' s/step,
then the medians and the ratios new/old.

Reads both forms of the profile: the phases of the real step in ms/step (solvers since the step's phase timers,
docs/solver.md) and, for older binaries, the kernels in s/step ("advance", "interfaces", "nodes", "check and
rest"; the rows in parentheses, kernels timed alone for comparison, are not parts of the step and are not read).
A phase one binary has and the other has not gets no ratio.
"""
from __future__ import annotations

import argparse
import datetime
import math
import pathlib
import re
import statistics
import subprocess
import sys

from bench.run_bench import PROFILE_CASE, PROFILE_SETS, machine
from enamel_results import paths

HEAD = re.compile(r"(\d+) DOF, (\d+) thread\(s\), .*?: ([0-9.eE+-]+) (ms|s)/step, ([0-9.]+) M DOF-updates/s")
TABLE_HEAD = re.compile(r"^\| (?:kernel|phase) \| (ms|s)/step \|", re.M)
HEADER_KEYS = ("dof", "threads", "s_per_step", "mdofs_per_core")


def profile_args(binary: str, threads: int, steps: int, preset: str = "paper") -> list[str]:
    args = [binary, "profile", str(paths.PAPER_CASES / f"{PROFILE_CASE}.toml"), "--preset", preset,
            "--steps", str(steps)]
    for k, v in dict(PROFILE_SETS, threads=threads).items():
        args += ["--set", f"{k}={v}"]
    return args


def parse(text: str) -> dict:
    """{'dof', 'threads', 's_per_step', 'mdofs_per_core', phase: s/step} from one profile's Markdown (either form:
    the module's docstring)."""
    m = HEAD.search(text)
    if not m:
        raise ValueError(f"no profile header in:\n{text}")
    per_unit = {"ms": 1e-3, "s": 1.0}
    out = {"dof": int(m[1]), "threads": int(m[2]), "s_per_step": float(m[3]) * per_unit[m[4]],
           "mdofs_per_core": float(m[5])}
    table = TABLE_HEAD.search(text)
    if not table:
        raise ValueError(f"no profile table in:\n{text}")
    for line in text[table.end():].splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("| ") and len(cells) > 2 and not cells[0].startswith("("):
            out[cells[0]] = float(cells[1]) * per_unit[table[1]]
    return out


def phases(rounds: list[tuple[dict, dict]]) -> list[str]:
    """The parts of the step any round's profile has, in the order they first appear (the step itself left out)."""
    seen = {}
    for pair in rounds:
        for p in pair:
            seen.update((k, None) for k in p if k not in HEADER_KEYS and k != "step")
    return list(seen)


def medians(rounds: list[tuple[dict, dict]]) -> dict:
    """{'old': {key: median}, 'new': {key: median}} over the rounds' (old, new) parses, for s/step, DOF-updates/s
    per core and each part of the step (a round whose profile lacks a part is left out of its median; a binary
    none of whose profiles has it gets no median for it)."""
    keys = ("s_per_step", "mdofs_per_core", *phases(rounds))
    return {name: {k: statistics.median(pair[j][k] for pair in rounds if k in pair[j])
                   for k in keys if any(k in pair[j] for pair in rounds)}
            for j, name in enumerate(("old", "new"))}


def ratios(med: dict) -> dict:
    """new / old of the medians, per key of either: of times for s_per_step and the phases (< 1: faster), of speeds
    for mdofs_per_core (the speed-up); NaN where one binary has no median or the old one is 0 (an old profile's
    "check and rest" was step - advance, clipped at 0 when a round's advance took longer than its step)."""
    keys = dict.fromkeys([*med["old"], *med["new"]])
    return {k: med["new"][k] / med["old"][k] if med["new"].get(k) is not None and med["old"].get(k) else math.nan
            for k in keys}


def version(binary: str) -> str:
    return subprocess.run([binary, "--version"], capture_output=True, text=True).stdout.strip()


def report(old: str, new: str, rounds: list[tuple[dict, dict]], threads: int) -> str:
    vo, vn = version(old), version(new)
    parts = phases(rounds)
    lines = [f"# Two binaries' profiles, interleaved ({datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC; "
             f"{machine()})", "",
             f"`python3 -m bench.profile_pair`: `paper` preset, {PROFILE_CASE}, {rounds[0][0]['dof']} DOF, "
             f"{threads} thread(s), lumped (bench.run_bench.PROFILE_SETS); old = {vo}, new = {vn}; "
             f"{len(rounds)} rounds, old then new in each. Times in s/step.", "",
             "| round | binary | s/step | M DOF-updates/s per core | " + " | ".join(parts) + " |",
             "|---|---|---|---|" + "---|" * len(parts)]
    for i, pair in enumerate(rounds, 1):
        for name, p in zip(("old", "new"), pair):
            lines.append(f"| {i} | {name} | {p['s_per_step']:.4g} | {p['mdofs_per_core']:.1f} | "
                         + " | ".join(f"{p.get(k, math.nan):.4g}" for k in parts) + " |")
    med = medians(rounds)
    ratio = ratios(med)
    lines += ["", "| median | old | new | new / old (time) |", "|---|---|---|---|"]
    for k in ("s_per_step", *parts):
        lines.append(f"| {k} | {med['old'].get(k, math.nan):.4g} | {med['new'].get(k, math.nan):.4g} | {ratio[k]:.3f} |")
    speedup = ratio["mdofs_per_core"]
    lines += ["", f"**DOF-updates/s per core: {med['old']['mdofs_per_core']:.1f} M (old) -> "
                  f"{med['new']['mdofs_per_core']:.1f} M (new), {speedup:.2f}x** (medians of the rounds).", "",
              "<!-- generated by: python3 -m bench.profile_pair -->", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--against", required=True, help="the old binary")
    ap.add_argument("--binary", default=str(paths.SOLVER), help="the new binary (default: the build's)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=20, help="steps timed per profile round (enamel-dem profile --steps)")
    ap.add_argument("--out", type=pathlib.Path, default=pathlib.Path(__file__).parent / "profile_pair.md")
    a = ap.parse_args(argv)
    rounds = []
    for i in range(a.rounds):
        pair = []
        for b in (a.against, a.binary):
            proc = subprocess.run(profile_args(b, a.threads, a.steps), capture_output=True, text=True)
            if proc.returncode != 0:
                print(f"profile_pair: {b} failed (exit {proc.returncode}): {proc.stderr.strip()}", file=sys.stderr)
                return proc.returncode
            pair.append(parse(proc.stdout))
            print(f"round {i + 1}: {b}: {pair[-1]['s_per_step']:.4g} s/step", file=sys.stderr)
        rounds.append(tuple(pair))
    a.out.write_text(report(a.against, a.binary, rounds, a.threads))
    print(a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
