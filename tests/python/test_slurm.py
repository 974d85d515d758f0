"""SLURM: `make slurm` writes a job array of the figure set's runs and a figures job after it; here
they run on a real single-node SLURM: Debian's slurm-wlm and munge (`make deps`), started by this test as the
invoking user (root or not: SlurmUser and SlurmdUser are that user, proctrack/linuxproc and task/none need no
privilege) with its own configuration, munge key, socket, state, spool and logs under a temporary folder, and
stopped afterwards (also when the test fails). If SLURM cannot start (packages missing, a daemon failing), the
test fails with the reason; it does not skip.

Two ci cases of Fig. 4 at a tiny size (RUN_SET) run as a two-task array, each through the Make rule. Once a
run has written a checkpoint, its solver is paused (SIGSTOP, so that the interruption lands mid-run however
fast the machine) and
- task 0 is requeued with `scontrol requeue` (what preemption does: SLURM sends SIGCONT and SIGTERM to every
  process of the job);
- task 1's batch shell gets SIGUSR1 (`scancel --batch --signal=USR1`: what SLURM sends --signal-seconds before
  the time limit): the script passes SIGTERM to make and the solver and requeues the task itself.
Each task starts again, its run continues from its checkpoint (the run's log says so) and ends bit for bit
equal to an uninterrupted run of the same case through the same Make rule (every dataset and attribute of
result.h5 but the wall time, the peak memory and the write time); the figures job starts after both tasks have
ended and draws Fig. 4 from their results.
"""
import math
import os
import pathlib
import pwd
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np
import pytest

from conftest import ROOT

CASES = ["theta0_s21.4_e10_cv0", "theta30_s21.4_e10_cv0"]    # two cases of Fig. 4: the figures job draws it
RUN_SET = "threads=1 w_s_over_d=8 h_s_over_d=4 stop_da_over_d=1.5 frames_da_over_d=[0.5,1.5]"  # ~2 s a run
CHECKPOINT_EVERY = "0.2"                                       # s: a checkpoint soon after each run starts
RUN_ENV_ATTRS = {"wall_time_s", "peak_memory_mb", "written_utc"}   # attributes of the process, not the result
DAEMONS = ("munged", "mungekey", "slurmctld", "slurmd", "sbatch", "scontrol", "scancel", "sinfo")
OUTER = ("SLURM_", "SBATCH_", "SALLOC_", "SRUN_", "SQUEUE_", "MAKEFLAGS", "MFLAGS", "MAKELEVEL")
TIMEOUT = 240                                                  # s: the whole array and figures job
USER = pwd.getpwuid(os.geteuid()).pw_name                     # runs the daemons and the jobs
FINAL = {"COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY", "PREEMPTED", "BOOT_FAIL",
         "DEADLINE"}


def tail(path, n=15):
    try:
        return "\n".join(pathlib.Path(path).read_text(errors="replace").splitlines()[-n:])
    except OSError:
        return f"({path} not written)"


def free_ports(n):
    socks = [socket.socket() for _ in range(n)]
    for s in socks:
        s.bind(("127.0.0.1", 0))
    ports = [s.getsockname()[1] for s in socks]
    for s in socks:
        s.close()
    return ports


def pids_with_env(marker: bytes):
    """Processes whose environment holds `marker` (this cluster's SLURM_CONF): its daemons' and jobs' leftovers."""
    out = []
    for d in pathlib.Path("/proc").iterdir():
        if d.name.isdigit() and int(d.name) != os.getpid():
            try:
                if marker in (d / "environ").read_bytes().split(b"\0"):
                    out.append(int(d.name))
            except OSError:
                pass
    return out


class Cluster:
    """One slurmctld + slurmd node + munged, all under `root`; commands get SLURM_CONF through `env`."""

    def __init__(self, root: pathlib.Path):
        self.root, self.procs = root, {}
        self.conf = root / "slurm.conf"
        # nothing of an outer SLURM job or an outer make (`make test`) reaches this cluster or the jobs' make
        self.env = {k: v for k, v in os.environ.items() if not k.startswith(OUTER)} | {"SLURM_CONF": str(self.conf)}
        self.marker = f"SLURM_CONF={self.conf}".encode()

    def cmd(self, *args, check=True, timeout=30):
        r = subprocess.run([str(a) for a in args], capture_output=True, text=True, env=self.env, timeout=timeout)
        if check and r.returncode != 0:
            pytest.fail(f"`{' '.join(map(str, args))}` exited {r.returncode}: {r.stderr.strip()}")
        return r

    def start(self, name, *args):
        log = open(self.root / "log" / f"{name}.out", "w")
        self.procs[name] = subprocess.Popen([str(a) for a in args], stdout=log, stderr=subprocess.STDOUT,
                                            env=self.env, start_new_session=True)

    def alive_or_fail(self, name, what):
        if self.procs[name].poll() is not None:
            pytest.fail(f"SLURM cannot start on this machine: {name} exited {self.procs[name].returncode} {what}:\n"
                        + tail(self.root / "log" / f"{name}.out"))

    def jobs(self, job_id) -> list[dict]:
        """`scontrol show job` of a job (every task of an array), one dict of Key=Value fields per job."""
        r = self.cmd("scontrol", "-o", "show", "job", job_id)
        return [dict(re.findall(r"(\w+)=(\S*)", line)) for line in r.stdout.splitlines() if line.strip()]

    def stop(self):
        if "slurmctld" in self.procs and self.procs["slurmctld"].poll() is None:
            self.cmd("scancel", "--full", "--user", USER, check=False)
            for _ in range(50):
                if not self.cmd("squeue", "-h", check=False).stdout.strip():
                    break
                time.sleep(0.2)
        for name in ("slurmd", "slurmctld", "munged"):
            p = self.procs.get(name)
            if p and p.poll() is None:
                p.terminate()
                try:
                    p.wait(10)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait()
        for pid in pids_with_env(self.marker):     # slurmstepd and job processes outlive slurmd
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass


@pytest.fixture(scope="module")
def slurm(tmp_path_factory, request):
    missing = [d for d in DAEMONS if shutil.which(d) is None and not pathlib.Path("/usr/sbin", d).exists()]
    if missing:
        pytest.fail(f"SLURM cannot start: {', '.join(missing)} not installed: run `make deps` (slurm-wlm, munge)")
    root = tmp_path_factory.mktemp("slurm")
    for d in ("munge", "state", "spool", "log", "run"):
        (root / d).mkdir()
    (root / "munge").chmod(0o700)
    # munged wants every folder above its socket open to all (pytest's are not): a folder of its own in /tmp
    sock_dir = pathlib.Path(tempfile.mkdtemp(prefix="enamel-munge-"))
    sock_dir.chmod(0o755)
    request.addfinalizer(lambda: shutil.rmtree(sock_dir, ignore_errors=True))
    c = Cluster(root)
    request.addfinalizer(c.stop)

    key = root / "munge" / "munge.key"
    c.cmd(shutil.which("mungekey") or "/usr/sbin/mungekey", "--create", f"--keyfile={key}")
    key.chmod(0o400)
    sock = sock_dir / "munge.sock"
    c.start("munged", shutil.which("munged") or "/usr/sbin/munged", "--foreground", f"--socket={sock}",
            f"--key-file={key}", f"--pid-file={root / 'run' / 'munged.pid'}",
            f"--log-file={root / 'log' / 'munged.log'}", f"--seed-file={root / 'munge' / 'munged.seed'}")
    for _ in range(100):
        if sock.exists():
            break
        c.alive_or_fail("munged", "before creating its socket")
        time.sleep(0.1)
    else:
        pytest.fail("SLURM cannot start: munged made no socket in 10 s:\n" + tail(root / "log" / "munged.out"))

    host = socket.gethostname().split(".")[0]
    mem_mb = int(int(re.search(r"MemTotal:\s+(\d+)", pathlib.Path("/proc/meminfo").read_text()).group(1)) / 1024 * 0.8)
    ctld_port, d_port = free_ports(2)
    c.conf.write_text(f"""# written by tests/python/test_slurm.py
ClusterName=enameltest
SlurmctldHost={host}(127.0.0.1)
SlurmUser={USER}
SlurmdUser={USER}
SlurmctldPort={ctld_port}
SlurmdPort={d_port}
AuthType=auth/munge
CredType=cred/munge
# cred_expire: also how long a requeued job waits before it starts again (default 120 s)
AuthInfo=socket={sock},cred_expire=5
StateSaveLocation={root / 'state'}
SlurmdSpoolDir={root / 'spool'}
SlurmctldPidFile={root / 'run' / 'slurmctld.pid'}
SlurmdPidFile={root / 'run' / 'slurmd.pid'}
SlurmctldLogFile={root / 'log' / 'slurmctld.log'}
SlurmdLogFile={root / 'log' / 'slurmd.log'}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
MailProg=/bin/true
# the main scheduling loop every 2 s (default 60 s): it is what starts a requeued job once its wait is over
SchedulerParameters=sched_interval=2
MinJobAge=3600
KillWait=30
# both tasks at once even on a 1-core machine (the test pauses both runs before it interrupts them)
SlurmdParameters=config_overrides
NodeName={host} NodeAddr=127.0.0.1 CPUs=2 RealMemory={mem_mb} State=UNKNOWN
PartitionName=test Nodes={host} Default=YES MaxTime=INFINITE State=UP
""")
    c.start("slurmctld", shutil.which("slurmctld") or "/usr/sbin/slurmctld", "-D", "-f", c.conf)
    c.start("slurmd", shutil.which("slurmd") or "/usr/sbin/slurmd", "-D", "-f", c.conf, "-N", host)
    state = ""
    for _ in range(150):
        c.alive_or_fail("slurmctld", "while starting")
        c.alive_or_fail("slurmd", "while starting")
        state = c.cmd("sinfo", "-h", "-N", "-o", "%t", check=False).stdout.strip()
        if state == "idle":
            break
        time.sleep(0.2)
    else:
        pytest.fail(f"SLURM cannot start: node state '{state}' after 30 s:\n"
                    + c.cmd("scontrol", "show", "node", check=False).stdout
                    + tail(root / "log" / "slurmctld.out") + "\n" + tail(root / "log" / "slurmd.out"))
    return c


def solver_pid(out: pathlib.Path):
    """The pid of the solver writing to `out` (its --out argument), or None."""
    for d in pathlib.Path("/proc").iterdir():
        try:
            argv = (d / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if len(argv) > 3 and argv[0].endswith(b"enamel-dem") and argv[1] == b"run" and \
                any(a == b"--out" and b == str(out).encode() for a, b in zip(argv, argv[1:])):
            return int(d.name)
    return None


def wait_for(what, predicate, timeout=120, step=0.02):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        v = predicate()
        if v:
            return v
        time.sleep(step)
    pytest.fail(f"timed out after {timeout} s waiting for {what}")


def pause_after_checkpoint(run_dirs) -> list[int]:
    """Stop each run's solver (SIGSTOP) once it has written a checkpoint; their pids once all are stopped."""
    pids = [None] * len(run_dirs)

    def all_paused():
        for i, d in enumerate(run_dirs):
            if pids[i] is None:
                if (d / "result.h5").exists():
                    pytest.fail(f"{d.name} finished before it could be interrupted")
                pid = solver_pid(d)
                if pid and (d / "checkpoint.bin").exists():
                    os.kill(pid, signal.SIGSTOP)
                    pids[i] = pid
        return all(pids)
    wait_for("a checkpoint of every run", all_paused)
    return pids


def canonical(v):
    """A value as comparable bits: (dtype, shape, bytes) for numbers, the text for strings."""
    a = np.asarray(v)
    return (a.dtype.str, a.shape, a.tobytes()) if a.dtype.kind not in "OSU" else repr(v)


def datasets_and_attrs(path):
    """{name: bits} of every dataset and {name@attr: bits} of every attribute but the process's own."""
    items = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            for k, v in obj.attrs.items():
                if k not in RUN_ENV_ATTRS:
                    items[f"{name}@{k}"] = canonical(v)
            if isinstance(obj, h5py.Dataset):
                items[name] = canonical(obj[()])
        visit("/", f)
        f.visititems(visit)
    return items


def stamp(s: str) -> float:
    return time.mktime(time.strptime(s, "%Y-%m-%dT%H:%M:%S"))


def test_array_requeued_mid_run_resumes_bit_for_bit_then_figures(slurm, enamel, tmp_path, request):
    runs, ref, figs = tmp_path / "runs", tmp_path / "ref", tmp_path / "figs"
    make = ["make", "--no-print-directory", "-C", str(ROOT), "-o", str(enamel), f"ENAMEL={enamel}", "PRESET=ci",
            f"PYTHON={sys.executable}", f"RUN_SET={RUN_SET}", f"CHECKPOINT_EVERY={CHECKPOINT_EVERY}"]
    figure = (f"{sys.executable} -m figures.fig4_decussation --preset ci --runs {runs} --out {figs} "
              "--allow-missing")
    r = subprocess.run(make + [f"RUNS={runs}", f"CASES={' '.join(CASES)}", f"SLURM_THEN={figure}", "slurm"],
                       capture_output=True, text=True, env=slurm.env, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    scripts = runs / "ci" / "slurm"
    array_script = (scripts / "runs.sbatch").read_text()
    assert "#SBATCH --array=0-1" in array_script and "#SBATCH --requeue" in array_script
    assert re.search(r"#SBATCH --mem=\d+M", array_script), "memory from the solver's estimate"
    assert re.search(r"#SBATCH --time=\d+-\d\d:\d\d:00", array_script), "time from the solver's estimate"

    sub = subprocess.run(["bash", str(scripts / "submit.sh")], capture_output=True, text=True, env=slurm.env,
                         timeout=60)
    assert sub.returncode == 0, sub.stdout + sub.stderr
    array = re.search(r"^array (\d+):", sub.stdout, re.M).group(1)
    figures = re.search(r"^figures (\d+):", sub.stdout, re.M).group(1)

    # the uninterrupted runs, through the same Make rule, while SLURM works
    refs = [subprocess.Popen(make + [f"RUNS={ref}", str(ref / "ci" / c / "result.h5")], stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True, env=slurm.env, start_new_session=True)
            for c in CASES]
    request.addfinalizer(lambda: [os.killpg(p.pid, signal.SIGKILL) for p in refs if p.poll() is None])

    logs = [scripts / "logs" / f"run-{array}_{i}.out" for i in range(2)]
    dirs = [runs / "ci" / c for c in CASES]
    pids = pause_after_checkpoint(dirs)
    # task 0: requeued by SLURM (as by preemption); task 1: the warning before the time limit (SIGUSR1 to the
    # batch shell only). Each solver goes on at once, so that the signal finds it running.
    slurm.cmd("scontrol", "requeue", f"{array}_0")
    os.kill(pids[0], signal.SIGCONT)
    slurm.cmd("scancel", "--batch", "--signal=USR1", f"{array}_1")
    os.kill(pids[1], signal.SIGCONT)

    def all_final():
        jobs = slurm.jobs(array) + slurm.jobs(figures)
        return jobs if all(j["JobState"] in FINAL for j in jobs) and len(jobs) == 3 else None
    jobs = wait_for("the array and the figures job to end", all_final, timeout=TIMEOUT, step=1)
    tasks = sorted((j for j in jobs if j.get("ArrayJobId") == array), key=lambda j: int(j["ArrayTaskId"]))
    fig = next(j for j in jobs if j["JobId"] == figures)
    for ref_proc in refs:
        out, _ = ref_proc.communicate(timeout=TIMEOUT)
        assert ref_proc.returncode == 0, out

    for i, (task, log, d) in enumerate(zip(tasks, logs, dirs)):
        text = log.read_text()
        assert task["JobState"] == "COMPLETED" and task["ExitCode"] == "0:0", f"task {i}: {task}\n{text}"
        assert task["Restarts"] == "1", f"task {i} restarts {task['Restarts']}\n{text}"
        assert "start 1 " in text and "start 2 " in text, text
        run_log = (d / "log.txt").read_text()
        stop = re.search(r"interrupted after (\d+) steps.*signal 15", run_log)
        assert stop, f"task {i}'s solver was not stopped by SIGTERM:\n{run_log}\n{text}"
        m = re.search(r"resuming from checkpoint at step (\d+)", run_log)
        assert m, f"task {i}'s second start did not resume:\n{run_log}\n{text}"
        assert m.group(1) == stop.group(1), f"task {i} resumed from an older checkpoint than the signal's:\n{run_log}"
        assert not (d / "checkpoint.bin").exists(), "a completed run removes its checkpoint"
    assert "SIGTERM" in logs[0].read_text(), "task 0's batch shell saw SLURM's SIGTERM"
    t1 = logs[1].read_text()
    assert "time limit" in t1 and t1.index("requeueing") > t1.index("time limit"), "task 1 requeued itself"

    for c, d in zip(CASES, dirs):
        got, want = datasets_and_attrs(d / "result.h5"), datasets_and_attrs(ref / "ci" / c / "result.h5")
        assert sorted(got) == sorted(want), f"{c}: other datasets or attributes"
        differ = [k for k in want if got[k] != want[k]]
        assert not differ, f"{c}: the resumed run differs from the uninterrupted one in {differ[:5]}"

    fig_log = tail(scripts / "logs" / f"figures-{figures}.out")
    assert fig["JobState"] == "COMPLETED", f"{fig}\n{fig_log}"
    assert stamp(fig["StartTime"]) >= max(stamp(t["EndTime"]) for t in tasks), (fig, tasks)
    png = figs / "ci" / "fig4_decussation.png"
    assert png.exists(), fig_log
    assert png.stat().st_mtime >= max((d / "result.h5").stat().st_mtime for d in dirs)


def make_slurm(enamel, runs, *args):
    """`make slurm` (no cluster needed) with the jobs' runs under `runs`."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(OUTER)}
    return subprocess.run(["make", "--no-print-directory", "-C", str(ROOT), "-o", str(enamel), f"ENAMEL={enamel}",
                           f"PYTHON={sys.executable}", f"RUNS={runs}", *args, "slurm"],
                          capture_output=True, text=True, env=env, timeout=300)


def test_array_has_one_task_per_run_of_the_figure_set(enamel, tmp_path):
    r = make_slurm(enamel, tmp_path, "PRESET=reduced", "SLURM_MEM=2G", "SLURM_TIME=1:00:00",
                   "SLURM_PARTITION=long", "SLURM_SBATCH=--qos=low --nice=5")
    assert r.returncode == 0, r.stderr
    script = (tmp_path / "reduced" / "slurm" / "runs.sbatch").read_text()
    targets = re.findall(r"^  (\S+)/result\.h5   # task (\d+)$", script, re.M)
    mk = dict(re.findall(r"^(ALL_CASES|ALL_SLOW) := (.*)$", (ROOT / "build" / "figures.mk").read_text(), re.M))
    want = mk["ALL_CASES"].split() + [f"{c}_slow" for c in mk["ALL_SLOW"].split()]
    assert [pathlib.Path(t).name for t, _ in targets] == want
    assert [int(i) for _, i in targets] == list(range(len(want)))
    assert f"#SBATCH --array=0-{len(want) - 1}\n" in script
    for line in ("--mem=2G", "--time=1:00:00", "--partition=long", "--qos=low", "--nice=5", "--requeue",
                 "--open-mode=append", "--signal=B:USR1@300"):
        assert f"#SBATCH {line}\n" in script, line
    assert "--dependency=afterok:$array" in (tmp_path / "reduced" / "slurm" / "submit.sh").read_text()
    assert "figures-all" in (tmp_path / "reduced" / "slurm" / "figures.sbatch").read_text()


@pytest.mark.parametrize("args, message", [
    (["PRESET=nope"], "PRESET=nope is not a preset"),
    (["PRESET=ci", "CASES=theta99_nope"], "'theta99_nope' is not a run of the figure set"),
    (["PRESET=ci", "CASES="], "--cases given without any run"),
    (["PRESET=ci", "RUN_SET=nokey=1"], "unknown key 'nokey'"),
])
def test_bad_input_is_one_line(enamel, tmp_path, args, message):
    r = make_slurm(enamel, tmp_path, *args)
    assert r.returncode != 0
    lines = [line for line in r.stderr.splitlines() if not line.startswith("make: ***")]
    assert len(lines) == 1 and message in lines[0], r.stderr
    assert not (tmp_path / "ci" / "slurm").exists()


def test_time_is_twice_the_solvers_estimate_of_the_longest_run(enamel, tmp_path):
    """Without SLURM_TIME a task's time limit is 2x the longest run's `enamel-dem info --estimate` seconds (one
    core, whole run), in whole minutes; the half-rate twin's estimate is made at its rate_factor (about 2x)."""
    case = "theta30_s21.4_e10_cv0"
    r = make_slurm(enamel, tmp_path, "PRESET=converged", f"CASES={case} {case}_slow")
    assert r.returncode == 0, r.stderr
    script = (tmp_path / "converged" / "slurm" / "runs.sbatch").read_text()
    seconds = []
    for sets in ([], ["--set", "rate_factor=0.5"]):
        est = subprocess.run([str(enamel), "info", str(ROOT / "paper_cases" / f"{case}.toml"), "--preset", "converged",
                              *sets, "--estimate"], capture_output=True, text=True, timeout=300)
        assert est.returncode == 0, est.stderr
        seconds.append(float(re.search(r"^seconds (\S+)$", est.stdout, re.M).group(1)))
    assert 1.8 < seconds[1] / seconds[0] <= 2.0, seconds
    minutes = math.ceil(min(86400, max(600, 2 * max(seconds))) / 60)
    assert f"#SBATCH --time={minutes // 1440}-{minutes // 60 % 24:02d}:{minutes % 60:02d}:00\n" in script, script
    assert "bench" not in script
