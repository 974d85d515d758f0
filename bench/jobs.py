"""Bench runs on a machine's cores, each one a run that can stop and continue.

- `Job` and `run_jobs`: solver processes, longest first, never more cores than given, each one's wall time and its
  own CPU time (os.wait4).
- A run's record, RECORD in its folder: its command, the solver binary's SHA-256 and one entry per piece (one
  solver process: when it started, wall and CPU seconds, exit status, machine). A run whose result is complete
  and whose record names the same command and binary is not run again (`prepare`); one of another command or
  binary starts over. Its cost is the sum over its pieces (`totals`).
- `run_resumable`: the jobs with their records; Ctrl-C or SIGTERM is passed on to every running solver (each writes
  its checkpoint and stops), its piece is recorded, nothing more starts, and KeyboardInterrupt says so. The same
  command continues (the solver's --resume).

Used by `make bench` (bench/run_bench.py) and `make bench-converged` (bench/converged_cost.py).
"""
from __future__ import annotations

import dataclasses
import datetime
import hashlib
import json
import math
import os
import pathlib
import platform
import signal
import subprocess
import time

from bench import records
from enamel_results import paths, results

RECORD = "cost.json"   # in each run's folder: its command, the binary's digest and its pieces


@dataclasses.dataclass
class Job:
    case: str                # the case, or "cost" for the cost-growth runs
    variant: str             # the variant's name, or (cost) the integrator
    args: list
    cores: int
    out: pathlib.Path
    expected_s: float = 0.0  # for ordering: longest first
    wall_s: float = math.nan
    cpu_s: float = math.nan
    returncode: int = -1
    pid: int = 0             # while it runs

    @property
    def key(self) -> str:
        return f"{self.case} / {self.variant} ({self.out.name})"


def machine() -> str:
    cpu = records.cpu_model()
    mem = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2 ** 30
    return f"{cpu}, {os.cpu_count()} cores, {mem:.0f} GiB, {platform.system()} {platform.release()}"


def run_jobs(jobs: list[Job], cores: int, log=print, on_done=None, stop=None, log_mode="w") -> None:
    """Run the jobs, longest first, never using more than `cores` cores; records wall, CPU and peak memory of
    each (os.wait4 gives the child's own CPU time; its maxrss would count the forking Python's pages, so peak
    memory comes from the solver's /meta/peak_memory_mb). on_done(job) is called as each ends; once stop()
    is true no further job starts (those running are waited for). Each job's output goes to OUT/bench.log,
    opened with log_mode ("a": a resumed run keeps the log of its earlier pieces)."""
    pending = sorted(jobs, key=lambda j: -j.expected_s)
    running = {}   # pid -> (job, start, popen)
    free = cores
    t_all = time.perf_counter()
    while running or (pending and not (stop and stop())):
        started = True
        while started and not (stop and stop()):
            started = False
            for j in pending:
                if j.cores <= free or (not running and j.cores > cores):
                    j.out.mkdir(parents=True, exist_ok=True)
                    with open(j.out / "bench.log", log_mode) as logf:
                        p = subprocess.Popen(j.args, stdout=logf, stderr=subprocess.STDOUT)
                    j.pid = p.pid
                    running[p.pid] = (j, time.perf_counter(), p)
                    free -= j.cores
                    pending.remove(j)
                    started = True
                    break
        if not running:
            break
        pid, status, ru = os.wait4(-1, 0)
        if pid not in running:
            continue
        j, t0, p = running.pop(pid)
        p.returncode = os.waitstatus_to_exitcode(status)
        j.returncode, j.pid = p.returncode, 0
        j.wall_s = time.perf_counter() - t0
        j.cpu_s = ru.ru_utime + ru.ru_stime
        free += j.cores
        log(f"[{time.perf_counter() - t_all:7.0f} s] {j.key}: exit {j.returncode}, {j.wall_s:.1f} s wall, "
            f"{j.cpu_s:.1f} s CPU")
        if on_done:
            on_done(j)


# ------------------------------------------------------------------------------------------------- records
def binary_digest(binary: pathlib.Path) -> str:
    """The SHA-256 of a solver binary: a rebuilt solver at the same path is another solver."""
    return hashlib.sha256(pathlib.Path(binary).read_bytes()).hexdigest()


def read_record(out: pathlib.Path) -> dict:
    try:
        return json.loads((out / RECORD).read_text())
    except (OSError, ValueError):
        return {}


def completed(out: pathlib.Path) -> bool:
    try:
        return results.load_result(out / paths.RESULT_NAMES["completed"]).completed
    except (results.MissingResult, OSError):
        return False


def done(out: pathlib.Path) -> bool:
    """A complete result whose record has its pieces."""
    return _done(read_record(out), completed(out))


def _done(rec: dict, complete: bool) -> bool:
    """done() of a record and a result's completeness already read."""
    return complete and bool(rec.get("pieces"))


def prepare(out: pathlib.Path, command: list[str], digest: str) -> bool:
    """Whether the run in `out` must (still) run. A complete result with a record of this command and binary is
    done; a record of another command or binary, or a complete result without its pieces (its cost unknown), is
    started over: record, results and checkpoint removed. Otherwise (a stopped run) it continues."""
    rec, complete = read_record(out), completed(out)
    same = rec.get("command") == command and rec.get("solver_sha256") == digest
    if same and _done(rec, complete):
        return False
    if not same or complete:
        for name in (RECORD, *paths.RESULT_NAMES.values(), "checkpoint.bin"):
            (out / name).unlink(missing_ok=True)
    return True


def add_piece(job: Job, command: list[str], digest: str) -> None:
    """Append one piece (one solver process) to the run's record: when, how long, its CPU time, exit, machine."""
    rec = read_record(job.out)
    if rec.get("command") != command or rec.get("solver_sha256") != digest:
        rec = {"command": command, "solver_sha256": digest, "pieces": []}
    start = datetime.datetime.now(datetime.timezone.utc) - datetime.timedelta(seconds=job.wall_s)
    rec["pieces"].append(dict(started_utc=start.strftime("%Y-%m-%d %H:%M"), cpu_s=job.cpu_s, wall_s=job.wall_s,
                              exit=job.returncode, machine=machine()))
    (job.out / RECORD).write_text(json.dumps(rec, indent=1) + "\n")


def totals(out: pathlib.Path) -> dict:
    """A run's cost over its pieces: wall and CPU seconds summed, the number of pieces, the last piece's exit
    status, the first piece's start (UTC) and the machines."""
    pieces = read_record(out).get("pieces", [])
    return dict(wall_s=sum(p["wall_s"] for p in pieces), cpu_s=sum(p["cpu_s"] for p in pieces),
                pieces=len(pieces), exit=pieces[-1]["exit"] if pieces else -1,
                started_utc=pieces[0]["started_utc"] if pieces else "",
                machines=sorted({p["machine"] for p in pieces}))


# ----------------------------------------------------------------------------------------------------- runs
def run_resumable(todo: list[tuple[Job, list[str]]], cores: int, log=print) -> list[Job]:
    """Each (job, command) whose run must still run (`prepare`; the command's first word is the solver binary;
    job.args may wrap the command, e.g. in nice), `cores` at once, each piece recorded as it ends. Ctrl-C /
    SIGTERM: every running solver is sent the signal (it writes its checkpoint and stops), its piece is
    recorded, nothing more starts, and KeyboardInterrupt is raised. Returns the jobs that ran."""
    commands, digests = {}, {}
    for job, command in todo:
        job.out.mkdir(parents=True, exist_ok=True)
        if command[0] not in digests:
            digests[command[0]] = binary_digest(command[0])
        digest = digests[command[0]]
        if prepare(job.out, command, digest):
            commands[str(job.out)] = (command, digest)
        else:
            log(f"{job.key}: complete, not run again")
    jobs = [job for job, _ in todo if str(job.out) in commands]
    stopping = []

    def forward(signum, frame):
        stopping.append(signum)
        for j in jobs:
            if j.pid:
                os.kill(j.pid, signum)
    previous = {s: signal.signal(s, forward) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        run_jobs(jobs, cores, log=log, on_done=lambda j: add_piece(j, *commands[str(j.out)]),
                 stop=lambda: bool(stopping), log_mode="a")
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
    if stopping:
        raise KeyboardInterrupt("stopped at a checkpoint: the same command continues")
    return jobs
