"""No silent wrong result: damaged checkpoints and result files are refused with one line, a full disk at each of
the three writes (partial result, checkpoint, final result) ends the run with one line and an exit code and keeps
the previous files, and a resume continues across result-neutral keys only."""
import os
import pathlib
import random
import resource
import shutil
import signal
import subprocess
import time
import struct
import types
import zlib

import pytest

from conftest import ROOT, checkpoint_stamp
from enamel_results import cli, paths, results

CASE = ROOT / "paper_cases" / "theta30_s7.1_e10_cv0.toml"   # rods and interfaces break (about 2 s)
SETS = ["w_s_over_d=12", "h_s_over_d=6", "stop_da_over_d=3", "threads=1"]
EXIT = results.EXIT_CODES
DAMAGES = 20  # damaged checkpoints, and damaged result files


def args_for(out, *extra, sets=SETS):
    a = ["run", CASE, "--preset", "ci", "--out", out, "--quiet"]
    for s in sets:
        a += ["--set", s]
    return [str(x) for x in a + list(extra)]


def interrupted_run(enamel, out, checkpoints=1, extra=()):
    """Run in `out` until it has written `checkpoints` checkpoints, then SIGINT it: a checkpoint and a partial
    result stay."""
    p = subprocess.Popen([str(enamel), *args_for(out, "--checkpoint-every", "0.1", *extra)], stderr=subprocess.PIPE,
                         text=True)
    deadline, seen, last = time.time() + 300, 0, None
    while seen < checkpoints and p.poll() is None and time.time() < deadline:
        stamp = checkpoint_stamp(out)
        if stamp not in (None, last):
            seen, last = seen + 1, stamp
        time.sleep(0.01)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=300)
    assert p.returncode == EXIT["interrupted"], err
    return out / "checkpoint.bin"


@pytest.fixture(scope="module")
def checkpoint(enamel, tmp_path_factory):
    return interrupted_run(enamel, tmp_path_factory.mktemp("interrupted") / "run")


@pytest.fixture(scope="module")
def completed(run, tmp_path_factory):
    out = tmp_path_factory.mktemp("completed") / "run"
    r = run(*args_for(out))
    assert r.returncode == 0, r.stderr
    return out / "result.h5"


def damaged_copies(data: bytes, header_bytes: int, rng: random.Random):
    """DAMAGES damaged versions of `data`: truncations and 32-byte overwrites, half at random offsets of the
    first `header_bytes` and half in the rest."""
    out = []
    for i in range(DAMAGES):
        in_header = i % 2 == 0
        lo, hi = (0, header_bytes) if in_header else (header_bytes, len(data) - 1)
        at = rng.randrange(lo, hi)
        if i % 4 < 2:
            out.append((f"truncated at {at}", data[:at]))
        else:
            junk = bytes(rng.randrange(256) for _ in range(32))
            if junk == data[at:at + 32]:
                junk = bytes(b ^ 0xFF for b in junk)
            out.append((f"overwritten at {at}", (data[:at] + junk + data[at + 32:])[:len(data)]))
    return out


def test_damaged_checkpoints_are_refused(enamel, checkpoint, tmp_path):
    data = checkpoint.read_bytes()
    header = data.index(b"checkpoint_interval_s = ") + 30  # magic, version, build, the case's TOML text
    rng = random.Random(20261203)
    for n, (what, bad) in enumerate(damaged_copies(data, header, rng)):
        out = tmp_path / f"d{n}"
        out.mkdir()
        (out / "checkpoint.bin").write_bytes(bad)
        for mode in ("--resume", "--restart") if n % 5 == 0 else ("--resume",):
            r = subprocess.run([str(enamel), *args_for(out, mode)], capture_output=True, text=True, timeout=300)
            lines = r.stderr.strip().splitlines()
            assert len(lines) == 1, f"{what}, {mode}: {r.stderr}"
            if r.returncode == EXIT["checkpoint_invalid"]:  # the version field now reads as an earlier format's
                assert "format version" in lines[0], f"{what}: {lines[0]}"
            else:
                assert r.returncode == EXIT["checkpoint_damaged"], f"{what}, {mode}: exit {r.returncode}: {r.stderr}"
                assert "is damaged" in lines[0] and "delete it to start the run from step 0" in lines[0], lines[0]
            assert str(out / "checkpoint.bin") in lines[0], lines[0]
            # only the run directory's lock file (taken before the checkpoint is read: docs/solver.md)
            assert sorted(p.name for p in out.iterdir()) == [".lock", "checkpoint.bin"], f"{what}: it wrote files"


def test_damaged_result_files_are_refused(completed, tmp_path, capsys):
    data = completed.read_bytes()
    assert results.load_result(completed).completed
    rng = random.Random(20261204)
    header = 4096  # the seal's user block, HDF5's superblock and root group
    for n, (what, bad) in enumerate(damaged_copies(data, header, rng)):
        p = tmp_path / f"d{n}" / "result.h5"
        p.parent.mkdir()
        p.write_bytes(bad)
        with pytest.raises(results.DamagedResult) as e:
            results.load_result(p, full=True)
        message = str(e.value)
        assert len(message.splitlines()) == 1 and str(p) in message and "rerun" in message, f"{what}: {message}"
    # the figures' loader says "damaged result ... rerun" in one line and exits with its status, no traceback
    runs = tmp_path / "runs"
    target = paths.result_file("ci", "theta30_s7.1_e10_cv0", runs=runs)
    target.parent.mkdir(parents=True)
    target.write_bytes(data[:len(data) // 2])
    args = types.SimpleNamespace(preset="ci", runs=runs, allow_missing=False)
    with pytest.raises(SystemExit) as e:
        cli.load_cases("fig_test.py", args, ["theta30_s7.1_e10_cv0"])
    assert e.value.code == results.EXIT_DAMAGED
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "damaged result" in err[0] and "rerun" in err[0] and str(target) in err[0], err


def test_result_resolver_order(tmp_path):
    assert paths.run_result(tmp_path) is None
    for kind in ("failed", "partial", "completed"):
        (tmp_path / paths.RESULT_NAMES[kind]).write_bytes(b"")
        assert paths.run_result(tmp_path).name == paths.RESULT_NAMES[kind]
    assert paths.run_result(tmp_path, kinds=("failed",)).name == "result.failed.h5"


# --- a full disk at each write -------------------------------------------------------------------------------

def limited_run(enamel, out, extra, file_limit=None):
    """The run with a per-file size limit (RLIMIT_FSIZE: `ulimit -f`, for any user)."""
    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (file_limit, file_limit))
    return subprocess.run([str(enamel), *args_for(out, *extra)], capture_output=True, text=True, timeout=300,
                          preexec_fn=limit if file_limit else None)


def check_clean_full_disk(r, out, which: str):
    errors = [line for line in r.stderr.strip().splitlines() if "error" in line]
    assert r.returncode == EXIT["disk_full"], f"exit {r.returncode} (a signal is negative): {r.stderr}"
    assert len(errors) == 1 and f"cannot write {which}" in errors[0] and " bytes): " in errors[0], r.stderr
    assert r.stderr.strip().endswith(errors[0]), r.stderr
    assert not list(out.glob("*.tmp")), f"temporary file left: {list(out.iterdir())}"


# Sizes of this case's files (checked in the tests): the partial result at the start ~110 kB, checkpoints growing
# from ~110 kB to ~390 kB with the history, the final result ~430 kB.
LIMITS = {"partial": 50_000, "checkpoint": 200_000, "final": 300_000}


def full_disk_case(enamel, base, which, run_limited, stage=None):
    """Run the case in base/which so that `which` write is the first that does not fit; run_limited(out, extra)
    runs it. The resumed case's checkpoint is made in `stage` (default: base) and copied in."""
    out = base / which
    if which == "partial":  # a resumed run: its checkpoint must survive the failed first write
        staged = interrupted_run(enamel, (stage or base) / "staged")
        out.mkdir()
        shutil.copy(staged, out / "checkpoint.bin")
        good = staged.read_bytes()
        r = run_limited(out, ["--resume"])
        check_clean_full_disk(r, out, "result file")
        assert "result.partial.h5.tmp" in r.stderr
        assert (out / "checkpoint.bin").read_bytes() == good
    elif which == "checkpoint":  # checkpoints grow with the history: a later one fails, the earlier one stays
        r = run_limited(out, ["--checkpoint-every", "0.05"])
        check_clean_full_disk(r, out, "checkpoint")
        assert (out / "checkpoint.bin").exists(), "the previous checkpoint was not kept"
        assert results.load_result(out / "result.partial.h5").status == "running"
        copy = shutil.copytree(out, (stage or base) / "resumed")  # with room to continue
        resumed = subprocess.run([str(enamel), *args_for(copy, "--resume")], capture_output=True, text=True,
                                 timeout=300)
        assert resumed.returncode == 0 and "resuming from checkpoint" in resumed.stderr, resumed.stderr
    else:
        r = run_limited(out, ["--checkpoint-every", "0"])
        check_clean_full_disk(r, out, "result file")
        assert "result.h5.tmp" in r.stderr and not (out / "result.h5").exists()
        assert results.load_result(out / "result.partial.h5").status == "running"


@pytest.mark.parametrize("which", ["partial", "checkpoint", "final"])
def test_file_size_limit_at_each_write(enamel, tmp_path, which):
    full_disk_case(enamel, tmp_path, which, lambda out, extra: limited_run(enamel, out, extra, LIMITS[which]))


# tmpfs sizes: a checkpoint fits and the partial result beside it does not; the partial result, a checkpoint and
# the next one's temporary file do not; the partial and the final result do not.
TMPFS_KB = {"partial": 180, "checkpoint": 320, "final": 400}


@pytest.mark.parametrize("which", ["partial", "checkpoint", "final"])
def test_full_file_system_at_each_write(enamel, tmp_path, which):
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root; test_file_size_limit_at_each_write covers the same writes")
    mount = tmp_path / "tmpfs"
    mount.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={TMPFS_KB[which]}k", "tmpfs", str(mount)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here (a container without CAP_SYS_ADMIN?): {r.stderr.strip()}")
    try:
        full_disk_case(enamel, mount, which, lambda out, extra: limited_run(enamel, out, extra), stage=tmp_path)
    finally:
        subprocess.run(["umount", str(mount)], capture_output=True)


# --- resume identity ------------------------------------------------------------------------------------------

def test_resume_continues_across_result_neutral_keys_only(enamel, tmp_path):
    out = tmp_path / "run"
    interrupted_run(enamel, out, extra=["--set", "checkpoint_interval_s=1"])
    saved = (out / "checkpoint.bin").read_bytes()
    neutral = [s for s in SETS if not s.startswith("threads")] + ["threads=2", "checkpoint_interval_s=7"]
    # threads sleep at barriers (as in test_threads.py): on a machine whose cores are busy, two spinning threads
    # made this 3 s run take 180 s or more; the test is about the resume, not the speed
    r = subprocess.run([str(enamel), *args_for(out, "--resume", sets=neutral)], capture_output=True, text=True,
                       timeout=300, env={**os.environ, "OMP_WAIT_POLICY": "passive"})
    assert r.returncode == 0 and "resuming from checkpoint at step" in r.stderr, r.stderr
    for changed in ("zeta=0.25", "cv=0.1", "dt_factor=0.09"):
        (out / "checkpoint.bin").write_bytes(saved)
        r = subprocess.run([str(enamel), *args_for(out, "--resume", "--force", sets=SETS + [changed])],
                           capture_output=True, text=True, timeout=300)
        assert "starting from step 0" in r.stderr and "different case" in r.stderr, f"{changed}: {r.stderr}"


# --- the blow-up guard -----------------------------------------------------------------------------------------

def state_vectors(data: bytes) -> dict:
    """{name: (offset of the first value, count)} of the checkpoint's state vectors (checkpoint.cpp transferFields:
    magic, version, build, case, 7 scalars, then q, v, a, vHalf; the lumped scheme of the ci preset steps vHalf)."""
    at = 8 + 4
    for _ in range(2):  # build fingerprint, case TOML
        (n,) = struct.unpack_from("<Q", data, at)
        at += 8 + n
    at += 7 * 8
    out = {}
    for name in ("q", "v", "a", "vHalf"):
        (n,) = struct.unpack_from("<Q", data, at)
        out[name] = (at + 8, n)
        at += 8 + 8 * n
    return out


def reseal_checkpoint(data: bytes) -> bytes:
    """The checkpoint with its CRC-32 recomputed: a state damaged before it was written (memory, a bug), which
    the checksum cannot see and the guard must."""
    body = data[:-12]
    return body + struct.pack("<I", zlib.crc32(body)) + data[-8:]


@pytest.mark.parametrize("name, value", [("q", 1e30), ("vHalf", 1e100), ("vHalf", -1e50), ("q", float("nan"))])
def test_a_blown_up_state_fails_the_guard(enamel, checkpoint, tmp_path, name, value):
    data = bytearray(checkpoint.read_bytes())
    first, n = state_vectors(bytes(data))[name]
    for i in range(n // 2, n // 2 + 4):
        struct.pack_into("<d", data, first + 8 * i, value)
    out = tmp_path / "run"
    out.mkdir()
    (out / "checkpoint.bin").write_bytes(reseal_checkpoint(bytes(data)))
    r = subprocess.run([str(enamel), *args_for(out, "--resume")], capture_output=True, text=True, timeout=300)
    assert "resuming from checkpoint" in r.stderr, r.stderr
    assert r.returncode == EXIT["run_unstable"], f"exit {r.returncode}: {r.stderr}"
    assert not (out / "result.h5").exists() and (out / "result.failed.h5").exists()
    assert results.load_result(out / "result.failed.h5").status == "failed"
    assert any(w in r.stderr for w in ("energy balance error", "non-finite state", "kinetic / strain energy",
                                       "negative beyond round-off")), r.stderr


def test_a_deliberate_edit_is_resealed_and_read(completed, tmp_path):
    import h5py
    p = tmp_path / "result.h5"
    shutil.copy(completed, p)
    with h5py.File(p, "r+") as f:
        f["meta"].attrs["status"] = "interrupted"
    with pytest.raises(results.DamagedResult):
        results.load_result(p)
    results.seal_result_file(p)
    assert results.load_result(p).status == "interrupted"
