"""Two solver binaries' kernel profiles, interleaved, on the `paper` preset's case: the speed-up as a ratio.

    python3 -m bench.profile_pair --against OLD/enamel-dem [--binary build/enamel-dem] [--rounds 3]
        [--threads 2] [--steps 20] [--out bench/profile_pair.md]

Runs `enamel-dem profile` (the case and knobs of `make bench`'s profile: bench.run_bench.PROFILE_CASE and
PROFILE_SETS) with the old binary, then the new one, `--rounds` times in turn, so both are measured in the same
minutes on the same machine; the wall times of this machine swing by up to 2x, a ratio of interleaved medians
does not. Writes a Markdown page: per round each binary's s/step, DOF-updates/s per core and its kernels' s/step,
then the medians and the ratios new/old.
"""
from __future__ import annotations

import argparse
import datetime
import pathlib
import re
import statistics
import subprocess
import sys

from bench.run_bench import PROFILE_CASE, PROFILE_SETS, machine
from enamel_results import paths

HEAD = re.compile(r"(\d+) DOF, (\d+) thread\(s\), (\d+) steps per kernel.*?: ([0-9.eE+-]+) s/step, ([0-9.]+) M DOF-updates/s")
KERNELS = ("step", "advance", "interfaces", "nodes", "check and rest")
MEDIAN_KEYS = ("s_per_step", "mdofs_per_core", *KERNELS[1:])


def profile_args(binary: str, threads: int, steps: int, preset: str = "paper") -> list[str]:
    args = [binary, "profile", str(paths.PAPER_CASES / f"{PROFILE_CASE}.toml"), "--preset", preset,
            "--steps", str(steps)]
    for k, v in dict(PROFILE_SETS, threads=threads).items():
        args += ["--set", f"{k}={v}"]
    return args


def parse(text: str) -> dict:
    """{'dof', 'threads', 's_per_step', 'mdofs_per_core', kernel: s/step} from one profile's Markdown."""
    m = HEAD.search(text)
    if not m:
        raise ValueError(f"no profile header in:\n{text}")
    out = {"dof": int(m[1]), "threads": int(m[2]), "s_per_step": float(m[4]), "mdofs_per_core": float(m[5])}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) > 2 and cells[0] in KERNELS:
            out[cells[0]] = float(cells[1])
    return out


def medians(rounds: list[tuple[dict, dict]]) -> dict:
    """{'old': {key: median}, 'new': {key: median}} over the rounds' (old, new) parses, for s/step, DOF-updates/s
    per core and each kernel but the step (a round whose profile lacks a kernel is left out of its median)."""
    return {name: {k: statistics.median(pair[j][k] for pair in rounds if k in pair[j]) for k in MEDIAN_KEYS}
            for j, name in enumerate(("old", "new"))}


def ratios(med: dict) -> dict:
    """new / old of the medians, per key: of times for s_per_step and the kernels (< 1: faster), of speeds for
    mdofs_per_core (the speed-up); NaN where the old median is 0 ("check and rest" is step - advance, clipped at 0
    when a round's advance took longer than its step)."""
    return {k: med["new"][k] / med["old"][k] if med["old"][k] else float("nan") for k in MEDIAN_KEYS}


def version(binary: str) -> str:
    return subprocess.run([binary, "--version"], capture_output=True, text=True).stdout.strip()


def report(old: str, new: str, rounds: list[tuple[dict, dict]], threads: int) -> str:
    vo, vn = version(old), version(new)
    lines = [f"# Two binaries' profiles, interleaved ({datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC; "
             f"{machine()})", "",
             f"`python3 -m bench.profile_pair`: `paper` preset, {PROFILE_CASE}, {rounds[0][0]['dof']} DOF, "
             f"{threads} thread(s), lumped (bench.run_bench.PROFILE_SETS); old = {vo}, new = {vn}; "
             f"{len(rounds)} rounds, old then new in each.", "",
             "| round | binary | s/step | M DOF-updates/s per core | " + " | ".join(KERNELS[1:]) + " |",
             "|---|---|---|---|" + "---|" * (len(KERNELS) - 1)]
    for i, pair in enumerate(rounds, 1):
        for name, p in zip(("old", "new"), pair):
            lines.append(f"| {i} | {name} | {p['s_per_step']:.4g} | {p['mdofs_per_core']:.1f} | "
                         + " | ".join(f"{p.get(k, float('nan')):.4g}" for k in KERNELS[1:]) + " |")
    med = medians(rounds)
    ratio = ratios(med)
    lines += ["", "| median | old | new | new / old (time) |", "|---|---|---|---|"]
    for k in ("s_per_step", *KERNELS[1:]):
        lines.append(f"| {k} | {med['old'][k]:.4g} | {med['new'][k]:.4g} | {ratio[k]:.3f} |")
    speedup = ratio["mdofs_per_core"]
    lines += ["", f"**DOF-updates/s per core: {med['old']['mdofs_per_core']:.1f} M (old) -> "
                  f"{med['new']['mdofs_per_core']:.1f} M (new), {speedup:.2f}x** (medians of the rounds).", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--against", required=True, help="the old binary")
    ap.add_argument("--binary", default=str(paths.SOLVER), help="the new binary (default: the build's)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=20, help="steps per kernel and profile round (enamel-dem profile)")
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
