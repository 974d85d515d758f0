"""The stop for a separated specimen (case keys stop_load_fraction, stop_load_transits; docs/model.md, Loading,
damping, measurements): a small theta30 case with weak rods (sigma_ru/sigma0 = 7.1) whose crack runs until the
grip load has fallen to a few percent of its peak stops with stop_reason "separated: ...", and with the key at 0
it does not (8 x 4 d, ~5-10 s a run)."""
import h5py
import numpy as np

from conftest import PAPER_CASES

SETS = ["w_s_over_d=8", "h_s_over_d=4", "stop_da_over_d=1e3", "threads=1"]


def run_case(run, out, extra):
    args = ["run", PAPER_CASES / "theta30_s7.1_e10_cv0.toml", "--preset", "ci", "--out", out, "--quiet"]
    for s in SETS + extra:
        args += ["--set", s]
    r = run(*args, timeout=600)
    assert r.returncode == 0, r.stderr
    with h5py.File(out / "result.h5") as f:
        h = f["history"]
        meta = dict(f["meta"].attrs)
        meta["h_s"] = f["geometry"].attrs["h_s"]
        meta["w_s"] = f["geometry"].attrs["w_s"]
        meta["h_e"] = f["geometry"].attrs["h_e"]
        return (meta, h["load"][:], h["time"][:], h["da_over_d"][:], h["step"][:])


def test_separated_specimen_stops_with_its_own_reason_and_the_key_switches_it_off(run, tmp_path):
    meta, load, time, da, steps = run_case(run, tmp_path / "on", [])
    assert meta["status"] == "completed"
    assert meta["stop_reason"].startswith("separated: the grip load stayed below stop_load_fraction = 0.05")
    peak = load.max()
    transit = meta["h_s"] / meta["c_d_over_cr"]
    # the rows of the last transit time before the stop: all below 5% of the peak, with the crack started
    last = time >= time[-1] - transit
    assert np.all(load[last] < 0.05 * peak) and np.all(da[last] > 0)
    assert meta["a0_effective"] + da[-1] < meta["w_s"] - 2 * meta["h_e"]  # before the far-edge stop
    # switched off: the same run goes on past that step (to the far edge or the step limit)
    off, *_ = run_case(run, tmp_path / "off", ["stop_load_fraction=0", f"max_steps={int(steps[-1]) + 5000}"])
    assert off["status"] == "completed"
    assert "stop_load_fraction" not in off["stop_reason"]
    assert off["steps"] > steps[-1], off["stop_reason"]
    print(meta["stop_reason"], "| off:", off["stop_reason"])
