"""Run records: a finished run's result.h5 reduced to a small JSON file that git keeps (records/<preset>/<run>.json,
enamel_results.paths), holding what the figures and the summary table read, so that they can be made when the
run's result file is gone.

    write_record(result_path, record_path)   record one result file (load_result's Result, plus the maps)
    load_record(path, case=None, full=False) the record as a Result (RecordResult), as load_result gives it
    load(path, case=None, full=False)        either, by the path's kind (what enamel_results.paths.find_result found)
    read_record(path)                        the record as a dict, checked; MalformedRecord naming it otherwise
    record_is_of(record, result_path)        whether a record was made from that result file (its sha256)

What a record holds (format 1, docs/results.md "Run records"):
  - the case name, its effective parameters and every /meta attribute (status, git_hash, preset, steps, dof,
    wall_time_s, stop_reason, warnings, case_toml, ...);
  - the R-curve (da, R) at full precision and R_init, R_ss, R_m, dR_m, da_max (/rcurve attributes); the broken
    rod elements at the last /history row and Delta_a/d at the first row with one (nan: none);
  - the maps' interfaces: every interface of the map tags (ply 1, ply 2, interlayer 1-2) at its midpoint, the
    slice's x (exact) and y as runs of equally spaced values per slice and tag, to 9 significant digits (within
    BACKGROUND_TOL = 1e-6 d of the file's, checked when written; far below a pixel); the /geometry attributes;
  - the maps of the frames the figures draw (the frame nearest each Delta_a/d of recorded_da(), chosen as
    Result.frame_near chooses): each interface's state (elastic, inelastic, failed) as runs over those interfaces
    in the order of y (a slice with none but elastic ones: []), and every deleted rod element (its two nodes' exact
    x, y and the ply of its first node); the frame's number, requested and reached Delta_a/d and step, and those of
    every frame the run wrote;
  - where it came from: the result file's name, size, CRC-32 (its seal) and sha256, and the solver commit;
    and content_sha256, the sha256 of the rest, so that an edited or damaged record is refused.
Left out: /history (but the two numbers above), every other frame, the interfaces of interlayer 2-1 (drawn in no
figure), damage, displacements, rod stresses and the rest of /geometry (node and element arrays, areas).
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import pathlib

import numpy as np

from enamel_results import cases, paper_values, paths
from enamel_results.results import (TAG_INTER12, TAG_PLY1, TAG_PLY2, DamagedResult, Frame, Geometry, MissingResult,
                                    Result, load_result, nearest_frame, params_of, seal_layout)

RECORD_KIND = "enamel-dem run record"
RECORD_FORMAT = 1
MAP_TAGS = (TAG_PLY1, TAG_PLY2, TAG_INTER12)  # the interface tags the process-zone maps draw (plotting.MAP_PANELS)
BACKGROUND_DIGITS = 9     # significant digits of the background's y values
BACKGROUND_TOL = 1e-6     # the background's y values are within this of the midpoints (d), checked when written
RUN_TOL = 1e-9            # equal spacing within a run of the background (d)
LEFT_OUT = ("/history but the broken rod elements at its last row and the advance at its first; the frames the "
            "figures do not draw; interlayer 2-1 interfaces; damage, displacements and rod stresses; the rest of "
            "/geometry")


class MalformedRecord(DamagedResult):
    """A record that is not one write_record wrote (unreadable, not JSON, a missing or wrong field, edited): one
    line naming it. A DamagedResult, so that the figures' loader reports it as it reports a damaged run."""

    def __init__(self, path, why: str):
        OSError.__init__(self, f"malformed record {path} ({why}): restore it from git or record the run again "
                               f"(`make records`)")
        self.path = pathlib.Path(path)
        self.why = why


class MissingFrame(SystemExit):
    """A map asked of a record at a Delta_a whose frame it does not hold (one line; exits as SystemExit does)."""


def recorded_da() -> list[float]:
    """The Delta_a/d of the maps the figures draw: each figure's snapshot (enamel_results.paper_values)."""
    pv = paper_values.paper_values()
    return sorted({paper_values.snapshot_da(fig, pv) for fig in cases.figure_list()})


# ------------------------------------------------------------------------------------------ JSON values
def to_json(v):
    """A value as JSON: numpy scalars and arrays as Python ones, a non-finite float as {"float": "nan"}."""
    if isinstance(v, dict):
        return {str(k): to_json(x) for k, x in v.items()}
    if isinstance(v, (list, tuple, np.ndarray)):
        return [to_json(x) for x in (v.tolist() if isinstance(v, np.ndarray) else v)]
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, float) and not math.isfinite(v):
        return {"float": repr(v)}
    return v


def from_json(v):
    """The inverse of to_json (a list stays a list)."""
    if isinstance(v, dict):
        if set(v) == {"float"}:
            return float(v["float"])
        return {k: from_json(x) for k, x in v.items()}
    if isinstance(v, list):
        return [from_json(x) for x in v]
    return v


def canonical(record: dict) -> bytes:
    """The bytes content_sha256 is taken of: the record without it, keys sorted, no spaces."""
    body = {k: v for k, v in record.items() if k != "content_sha256"}
    return json.dumps(body, sort_keys=True, separators=(",", ":"), allow_nan=False, ensure_ascii=False).encode()


def formatted(v, indent: str = "") -> str:
    """JSON laid out for reading and diffing: objects one key a line, a list of numbers on one line, a list of
    lists one inner list a line."""
    inner = indent + " "
    if isinstance(v, dict) and v:
        items = [f"{inner}{json.dumps(k)}: {formatted(x, inner)}" for k, x in v.items()]
        return "{\n" + ",\n".join(items) + "\n" + indent + "}"
    if isinstance(v, list) and v and all(isinstance(x, (list, dict)) for x in v):
        return "[\n" + ",\n".join(inner + formatted(x, inner) for x in v) + "\n" + indent + "]"
    return json.dumps(v, separators=(",", ":"), allow_nan=False, ensure_ascii=False)


# ------------------------------------------------------------------------------------------ writing
def file_source(path: pathlib.Path) -> dict:
    """The result file's name, size, seal CRC-32 and sha256."""
    seal = seal_layout()
    data = path.read_bytes()
    _, _, crc, _ = seal.struct.unpack_from(data[:seal.struct.size])
    try:
        shown = str(path.resolve().relative_to(paths.ROOT))
    except ValueError:
        shown = str(path)
    return {"file": shown, "bytes": len(data), "crc32": f"{crc:08x}", "sha256": hashlib.sha256(data).hexdigest()}


def slice_positions(g: Geometry) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(slice numbers present, their x, each interface's position in that list). Every interface of a slice has
    its midpoint at the slice's x (the solver's geometry); a file where that does not hold cannot be recorded."""
    numbers, pos = np.unique(g.iface_slice, return_inverse=True)
    x = np.full(numbers.size, np.nan)
    x[pos] = g.iface_midpoint[:, 0]
    if not np.array_equal(x[pos], g.iface_midpoint[:, 0]):
        raise ValueError("interfaces of one slice at different x: this geometry cannot be recorded")
    return numbers, x, pos


def equal_runs(y: np.ndarray) -> list:
    """Sorted values as runs of equal spacing, flat: [start, step, count, ...] (a lone value: step 0, count 1)."""
    out, i = [], 0
    while i < y.size:
        j = i + 1
        if j < y.size:
            step = y[j] - y[i]
            while j + 1 < y.size and abs(y[j + 1] - y[j] - step) <= RUN_TOL:
                j += 1
            out += [float(f"{y[i]:.{BACKGROUND_DIGITS}g}"), float(f"{step:.{BACKGROUND_DIGITS}g}"), j - i + 1]
            i = j + 1
        else:
            out += [float(f"{y[i]:.{BACKGROUND_DIGITS}g}"), 0.0, 1]
            i = j
    return out


def expand_runs(flat: list) -> np.ndarray:
    """The values of equal_runs' runs."""
    parts = [start + step * np.arange(count) for start, step, count in zip(flat[0::3], flat[1::3], flat[2::3])]
    return np.concatenate(parts) if parts else np.zeros(0)


def slice_groups(g: Geometry, pos: np.ndarray, nslices: int) -> dict:
    """{tag: [per slice position: its interfaces of that tag, in increasing y]} for the map tags."""
    out = {}
    for tag in MAP_TAGS:
        idx = np.flatnonzero(g.iface_tag == tag)
        idx = idx[np.argsort(g.iface_midpoint[idx, 1], kind="stable")]
        out[str(tag)] = [idx[pos[idx] == k] for k in range(nslices)]
    return out


def background(g: Geometry, groups: dict) -> dict:
    """{tag: [per slice: equal_runs of the y of its interfaces]}; checks the expansion against the midpoints
    (BACKGROUND_TOL)."""
    out = {}
    for tag, per_slice in groups.items():
        out[tag] = []
        for k, idx in enumerate(per_slice):
            y = g.iface_midpoint[idx, 1]
            flat = equal_runs(y)
            if y.size and np.max(np.abs(expand_runs(flat) - y)) > BACKGROUND_TOL:
                raise ValueError(f"the background of tag {tag}, slice {k} is not within {BACKGROUND_TOL} d")
            out[tag].append(flat)
    return out


def state_runs(states: np.ndarray) -> list:
    """Interface states in the background's order as runs, flat: [state, count, ...]; [] when all are elastic."""
    if not np.any(states):
        return []
    cut = np.flatnonzero(np.diff(states)) + 1
    starts = np.concatenate(([0], cut))
    counts = np.diff(np.concatenate((starts, [states.size])))
    return [int(v) for pair in zip(states[starts], counts) for v in pair]


def frame_map(g: Geometry, f: Frame, groups: dict) -> dict:
    """One frame's map: per map tag and slice, the states of its interfaces in the background's order (equal y:
    the lower state first) as state_runs; the deleted rod elements (ply of the first node, both nodes' x, y)."""
    states = {}
    for tag, per_slice in groups.items():
        states[tag] = []
        for idx in per_slice:
            st, y = f.iface_state[idx], g.iface_midpoint[idx, 1]
            states[tag].append(state_runs(st[np.lexsort((st, y))]))
    bn = g.beam_nodes[f.beam_broken > 0]
    X = g.node_position
    rods = {"ply": g.node_ply[bn[:, 0]], "x0": X[bn[:, 0], 0], "y0": X[bn[:, 0], 1], "x1": X[bn[:, 1], 0],
            "y1": X[bn[:, 1], 1]}
    return {"index": f.index, "target_da_over_d": f.target_da, "da_over_d": f.da, "step": f.step,
            "states": states, "broken_rod_elements": rods}


def record_of(r: Result, source: dict, frames_da=None) -> dict:
    """The record (without content_sha256) of a Result loaded with full=True from the file `source` describes."""
    g = r.geometry
    numbers, slice_x, pos = slice_positions(g)
    groups = slice_groups(g, pos, numbers.size)
    chosen = []
    for da in (recorded_da() if frames_da is None else frames_da):
        f = r.frame_near(da)
        if all(f.index != c.index for c in chosen):
            chosen.append(f)
    rc = {"da_over_d": r.da, "R_over_Gamma": r.R, "R_init_over_Gamma": r.R_init, "R_ss_over_Gamma": r.R_ss,
          "R_m_over_Gamma": r.R_m, "dR_m_over_Gamma": r.dR_m, "da_max_over_d": r.da_max}
    maps = {"geometry_attrs": g.attrs, "slices": numbers, "slice_x": slice_x,
            "written_frames": [[f.index, f.target_da, f.da, f.step] for f in r.frames],
            "frames": [frame_map(g, f, groups) for f in chosen],
            "background": background(g, groups)}
    return to_json({"record": RECORD_KIND, "format": RECORD_FORMAT, "case": r.case,
                    "solver_commit": r.meta.get("git_hash", ""), "source": source, "left_out": LEFT_OUT,
                    "params": r.params, "meta": r.meta, "rcurve": rc,
                    "history": {"broken_rod_elements": r.broken_rods,
                                "da_first_rod_fracture_over_d": r.da_first_rod_fracture},
                    "maps": maps})


def write_record(result_path, record_path, case: str | None = None, frames_da=None) -> dict:
    """Record one result file (checked against its seal) into record_path, written whole or not at all; returns
    the record. `frames_da`: the Delta_a/d of the maps (default: the figures', recorded_da())."""
    result_path, record_path = pathlib.Path(result_path), pathlib.Path(record_path)
    r = load_result(result_path, case=case, full=True)
    record = record_of(r, file_source(result_path), frames_da)
    record["content_sha256"] = hashlib.sha256(canonical(record)).hexdigest()
    record_path.parent.mkdir(parents=True, exist_ok=True)
    tmp = record_path.with_name(record_path.name + ".tmp")
    tmp.write_text(formatted(record) + "\n", encoding="utf-8")
    tmp.replace(record_path)
    return record


# ------------------------------------------------------------------------------------------ reading
# The fields read_record checks: (path, type); "[]" marks a list whose items have the type.
SCHEMA = (
    ("case", str), ("solver_commit", str), ("params", dict), ("meta", dict),
    ("source.file", str), ("source.bytes", int), ("source.crc32", str), ("source.sha256", str),
    ("rcurve.da_over_d", "[]number"), ("rcurve.R_over_Gamma", "[]number"),
    ("rcurve.R_init_over_Gamma", "number"), ("rcurve.R_ss_over_Gamma", "number"), ("rcurve.R_m_over_Gamma", "number"),
    ("rcurve.dR_m_over_Gamma", "number"), ("rcurve.da_max_over_d", "number"),
    ("history.broken_rod_elements", int), ("history.da_first_rod_fracture_over_d", "number"),
    ("maps.geometry_attrs", dict), ("maps.slices", "[]int"), ("maps.slice_x", "[]number"),
    ("maps.written_frames", "[]list"), ("maps.frames", "[]dict"), ("maps.background", dict),
)
FRAME_SCHEMA = (("index", int), ("target_da_over_d", "number"), ("da_over_d", "number"), ("step", int),
                ("states", dict), ("broken_rod_elements.ply", "[]int"), ("broken_rod_elements.x0", "[]number"),
                ("broken_rod_elements.y0", "[]number"), ("broken_rod_elements.x1", "[]number"),
                ("broken_rod_elements.y1", "[]number"))
TYPES = {"number": (int, float), "int": int, "list": list, "dict": dict}


def is_kind(x, want) -> bool:
    """Whether x is of type `want` (a bool is no number; a number may be to_json's non-finite {"float": ...})."""
    if want == TYPES["number"] and isinstance(x, dict):
        return set(x) == {"float"} and x["float"] in ("nan", "inf", "-inf")
    return not isinstance(x, bool) and isinstance(x, want)


def field(record: dict, dotted: str):
    """record["a"]["b"] for "a.b"; KeyError naming the field when it is missing."""
    v = record
    for part in dotted.split("."):
        if not isinstance(v, dict) or part not in v:
            raise KeyError(dotted)
        v = v[part]
    return v


def check_fields(record: dict, schema, where: str = "") -> None:
    """ValueError naming the first field of `schema` that is missing or of the wrong type."""
    for dotted, kind in schema:
        try:
            v = field(record, dotted)
        except KeyError:
            raise ValueError(f"no field {where}{dotted}") from None
        many = isinstance(kind, str) and kind.startswith("[]")
        want = TYPES[kind[2:] if many else kind] if isinstance(kind, str) else kind
        items = v if many and isinstance(v, list) else [v]
        if (many and not isinstance(v, list)) or not all(is_kind(x, want) for x in items):
            name = kind.lstrip("[]") if isinstance(kind, str) else kind.__name__
            raise ValueError(f"field {where}{dotted} is not {'a list of ' if many else ''}{name}")


def same_lengths(group: dict, names, where: str) -> None:
    """ValueError unless the lists group[name] for `names` have one length."""
    if len({len(group[n]) for n in names}) > 1:
        raise ValueError(f"the lists {', '.join(names)} of {where} differ in length")


def check_maps(maps: dict) -> None:
    """ValueError naming what in a record's maps is malformed (fields, types, lengths, tags, the states' counts)."""
    same_lengths(maps, ("slices", "slice_x"), "maps")
    if any(len(w) != 4 for w in maps["written_frames"]):
        raise ValueError("maps.written_frames holds an entry that is not [index, target, Delta_a, step]")
    tags = sorted(str(t) for t in MAP_TAGS)
    counts = {}
    for tag, per_slice in maps["background"].items():
        if not isinstance(per_slice, list) or len(per_slice) != len(maps["slices"]) or \
                any(not isinstance(flat, list) or len(flat) % 3 for flat in per_slice):
            raise ValueError(f"maps.background.{tag} is not one list of runs per slice")
        counts[tag] = [sum(flat[2::3]) for flat in per_slice]
    if sorted(counts) != tags:
        raise ValueError(f"maps.background is not of the interface tags {', '.join(tags)}")
    for n, f in enumerate(maps["frames"]):
        check_fields(f, FRAME_SCHEMA, f"maps.frames[{n}].")
        same_lengths(f["broken_rod_elements"], ("ply", "x0", "y0", "x1", "y1"), f"maps.frames[{n}].broken_rod_elements")
        if sorted(f["states"]) != tags:
            raise ValueError(f"maps.frames[{n}].states is not of the interface tags {', '.join(tags)}")
        for tag, per_slice in f["states"].items():
            if not isinstance(per_slice, list) or len(per_slice) != len(counts[tag]) or any(
                    not isinstance(flat, list) or (flat and sum(flat[1::2]) != c)
                    for flat, c in zip(per_slice, counts[tag])):
                raise ValueError(f"maps.frames[{n}].states.{tag} does not give one state to each interface of "
                                 f"maps.background.{tag}")


def check_record(record) -> None:
    """ValueError saying what is wrong with a parsed record (kind, format, content_sha256, fields, lengths)."""
    if not isinstance(record, dict) or record.get("record") != RECORD_KIND:
        raise ValueError(f"not an {RECORD_KIND!r}")
    if record.get("format") != RECORD_FORMAT:
        raise ValueError(f"format {record.get('format')!r}, this reader knows {RECORD_FORMAT}")
    want = record.get("content_sha256")
    if want != hashlib.sha256(canonical(record)).hexdigest():
        raise ValueError("its content does not match its content_sha256: edited or damaged")
    check_fields(record, SCHEMA)
    same_lengths(record["rcurve"], ("da_over_d", "R_over_Gamma"), "rcurve")
    check_maps(record["maps"])


def read_record(path) -> dict:
    """A record file, parsed and checked (check_record): FileNotFoundError when it is absent, MalformedRecord
    naming it when it is anything but a record write_record wrote."""
    path = pathlib.Path(path)
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise MalformedRecord(path, f"{type(e).__name__}: {str(e).splitlines()[0] if str(e) else 'unreadable'}") from e
    try:
        check_record(record)
    except (ValueError, KeyError, TypeError) as e:
        raise MalformedRecord(path, str(e)) from e
    return record


def record_is_of(record: dict, result_path) -> bool:
    """Whether `record` was made from this result file (the same sha256)."""
    data = pathlib.Path(result_path).read_bytes()
    return record["source"]["sha256"] == hashlib.sha256(data).hexdigest()


@dataclasses.dataclass
class WrittenFrame:
    """A frame the run wrote (a record holds the maps of some of them)."""
    index: int
    target_da: float
    da: float
    step: int


@dataclasses.dataclass
class RecordResult(Result):
    """A Result read from a record: the same fields as load_result's; with full=True its geometry and frames are
    the maps' (geometry: the map tags' interfaces and the deleted rod elements only; frames: the recorded ones,
    without damage, displacements or stresses). frame_near chooses among every frame the run wrote, as the run's
    Result would, and says so when the record does not hold that one."""
    written_frames: list | None = None

    def frame_near(self, da: float) -> Frame:
        want = nearest_frame(self.written_frames, da)
        for f in self.frames:
            if f.index == want.index:
                return f
        held = ", ".join(f"{f.target_da:g}" for f in self.frames)
        raise MissingFrame(f"{self.path}: the frame nearest Delta_a/d = {da:g} (written at {want.target_da:g}) is not "
                           f"in this record, which holds the maps at Delta_a/d = {held}; draw it from the run")


def rcurve_array(values: list) -> np.ndarray:
    return np.asarray(from_json(values), dtype=np.float64)


def load_record(path, case: str | None = None, full: bool = False) -> RecordResult:
    """A record as the Result load_result gives of its run (the same R-curve, numbers, params and meta); `full`
    builds the maps' geometry and frames. MalformedRecord naming the file when it is not a record."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise MissingResult(path)
    rec = read_record(path)
    try:
        res = result_of_record(path, rec, case)
        if full:
            res.geometry, res.frames = map_geometry(rec["maps"])
    except (KeyError, ValueError, TypeError, IndexError) as e:
        raise MalformedRecord(path, f"it cannot be read as a run: {type(e).__name__}: {e}") from e
    return res


def result_of_record(path: pathlib.Path, rec: dict, case: str | None) -> RecordResult:
    """The RecordResult of a checked record, without its maps."""
    rc, h = from_json(rec["rcurve"]), from_json(rec["history"])
    meta = from_json(rec["meta"])
    case = case or rec["case"]
    params = from_json(rec["params"]) if case == rec["case"] else params_of(case, meta)  # as load_result(path, case)
    written = [WrittenFrame(int(i), float(t), float(d), int(s)) for i, t, d, s in rec["maps"]["written_frames"]]
    res = RecordResult(path=path, case=case, params=params, meta=meta,
                       da=rcurve_array(rec["rcurve"]["da_over_d"]), R=rcurve_array(rec["rcurve"]["R_over_Gamma"]),
                       R_init=float(rc["R_init_over_Gamma"]), R_ss=float(rc["R_ss_over_Gamma"]),
                       R_m=float(rc["R_m_over_Gamma"]), dR_m=float(rc["dR_m_over_Gamma"]),
                       da_max=float(rc["da_max_over_d"]), broken_rods=int(h["broken_rod_elements"]),
                       da_first_rod_fracture=float(h["da_first_rod_fracture_over_d"]), written_frames=written)
    return res


def map_geometry(maps: dict) -> tuple[Geometry, list[Frame]]:
    """The Geometry and Frames the process-zone maps need (plotting.draw_process_zone), from a record's maps: every
    interface of the map tags at the background's midpoints, each frame's states from its runs, and the union of the
    frames' deleted rod elements as two-node elements."""
    slices, slice_x = np.asarray(maps["slices"], dtype=np.int32), np.asarray(maps["slice_x"], dtype=np.float64)
    tag, k, y = [], [], []
    for t, per_slice in maps["background"].items():
        for n, flat in enumerate(per_slice):
            ys = expand_runs(flat)
            tag.append(np.full(ys.size, int(t), dtype=np.int32))
            k.append(np.full(ys.size, n, dtype=np.int64))
            y.append(ys)
    k = np.concatenate(k)
    mid = np.zeros((k.size, 3))
    mid[:, 0], mid[:, 1] = slice_x[k], np.concatenate(y)
    rods = {}
    for f in maps["frames"]:
        b = f["broken_rod_elements"]
        for e in zip(b["ply"], b["x0"], b["y0"], b["x1"], b["y1"]):
            rods.setdefault(tuple(e), len(rods))
    X = np.zeros((2 * len(rods), 3))
    X[:, :2] = np.asarray([[x0, y0, x1, y1] for _, x0, y0, x1, y1 in rods], dtype=np.float64).reshape(-1, 2)
    geometry = Geometry(node_position=X, node_ply=np.repeat(np.asarray([e[0] for e in rods], dtype=np.int32), 2),
                        beam_nodes=np.arange(2 * len(rods), dtype=np.int32).reshape(-1, 2), beam_strength=None,
                        iface_nodes=None, iface_tag=np.concatenate(tag), iface_midpoint=mid, iface_zshift=None,
                        iface_area=None, iface_slice=slices[k], attrs=from_json(maps["geometry_attrs"]))
    frames = []
    for f in maps["frames"]:
        state = np.concatenate([np.repeat(np.asarray(flat[0::2], dtype=np.uint8), flat[1::2]) if flat else
                                np.zeros(sum(bg[2::3]), dtype=np.uint8)
                                for t, per_slice in maps["background"].items()
                                for flat, bg in zip(f["states"][t], per_slice)])
        broken = np.zeros(len(rods), dtype=np.uint8)
        b = f["broken_rod_elements"]
        broken[[rods[e] for e in zip(b["ply"], b["x0"], b["y0"], b["x1"], b["y1"])]] = 1
        frames.append(Frame(index=f["index"], target_da=f["target_da_over_d"], da=f["da_over_d"], step=f["step"],
                            iface_state=state, iface_damage=None, beam_broken=broken, node_displacement=None,
                            beam_stress=None))
    return geometry, frames


def load(path, case: str | None = None, full: bool = False) -> Result:
    """A run's Result from its result file or its record, whichever `path` is (enamel_results.paths.find_result)."""
    return load_record(path, case, full) if paths.is_record(path) else load_result(path, case, full)
