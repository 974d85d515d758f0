"""Load one result.h5 written by enamel-dem (solver/lib/io/output.cpp defines the layout): /meta, /rcurve,
/history, and with full=True /geometry and every /frames/<n>.

Normalisation everywhere: crack advance Delta_a by the rod spacing d, crack resistance R by the interface
fracture energy Gamma_i, rod strength by the interface strength sigma0.
"""
from __future__ import annotations

import dataclasses
import functools
import math
import pathlib
import struct
import tomllib
import zlib

import h5py
import numpy as np

from enamel_results.cases import params_from_name
from enamel_results import constants
from enamel_results.constants import EXIT


# Size convergence (docs/results.md): no specimen smaller than the paper's 200 x 200 d has been shown to give its
# R-curve by the phase-averaged measure (at 80 and 100 d one configuration of theta30 (21.4, 10) is 12 and 10 % below
# the 200 d run's), so only the paper's size is labelled size-converged: it is the size reference itself, at the
# default G and tip reading.
CONVERGED_SIZE_OVER_D = 200.0
CONVERGED_H_E_OVER_D = 0.3
CONVERGED_G = 9.0
CONVERGED_TIP = "cut"


def size_converged(r: "Result") -> bool:
    """Whether r's specimen is as large as the size shown converged, at that mesh and at the G and tip reading where
    it was shown (a run without the reading's key is older than it: its tip was the intact reading)."""
    p = r.params
    return (float(p["w_s_over_d"]) >= CONVERGED_SIZE_OVER_D and float(p["h_s_over_d"]) >= CONVERGED_SIZE_OVER_D
            and float(p["h_e_over_d"]) <= CONVERGED_H_E_OVER_D
            and float(p["Gamma_k_over_sigma0sq"]) == CONVERGED_G
            and str(p.get("crisscross_at_tip", "intact")) == CONVERGED_TIP)


def convergence_label(results) -> str:
    """One phrase for a set of runs: size-converged, or not and why (the sizes and G they ran at)."""
    rs = list(results)
    if not rs:
        return "no runs"
    if all(size_converged(r) for r in rs):
        return "size-converged"
    sizes = sorted({(float(r.params["w_s_over_d"]), float(r.params["h_s_over_d"])) for r in rs})
    gs = sorted({float(r.params["Gamma_k_over_sigma0sq"]) for r in rs})
    size_text = ", ".join(f"{w:g} x {h:g} d" for w, h in sizes)
    g_text = ", ".join(f"{g:g}" for g in gs)
    return (f"NOT size-converged ({size_text}, G = {g_text}; the size reference is "
            f"{CONVERGED_SIZE_OVER_D:g} x {CONVERGED_SIZE_OVER_D:g} d at G = {CONVERGED_G:g}, {CONVERGED_TIP} tip)")


EXIT_CODES = EXIT   # {name: status}, read from the solver's one definition (enamel_results.constants)
EXIT_MISSING = EXIT_CODES["missing_file"]      # a result file is missing
EXIT_DAMAGED = EXIT_CODES["result_damaged"]    # a result file is truncated or fails its checksum



@dataclasses.dataclass(frozen=True)
class SealLayout:
    """The seal enamel-dem writes at the start of the result file's HDF5 user block (solver/lib/io/output.hpp
    ResultSeal), as the solver declares it (enamel_results.constants.RESULT_SEAL): magic, format, CRC-32
    (zlib.crc32) of the whole file with the crc field's bytes as zeros, the file's size."""
    struct: struct.Struct       # the fields in order, little-endian, no padding
    magic: bytes
    format: int
    crc_offset: int             # where the crc field's 4 bytes are
    userblock_bytes: int


@functools.lru_cache(maxsize=None)
def seal_layout() -> SealLayout:
    """The solver's seal layout (read from the solver once)."""
    seal = constants.RESULT_SEAL
    order = {"little": "<", "big": ">"}[seal["byte_order"]]
    layout = struct.Struct(order + "".join(f["struct"] for f in seal["fields"]))
    names = [f["name"] for f in seal["fields"]]
    offsets = {f["name"]: f["offset"] for f in seal["fields"]}
    if layout.size != seal["bytes"] or names[0] != "magic" or names[1:] != ["format", "crc", "file_bytes"]:
        raise ValueError(f"the solver's result seal {seal} is not one this reader knows (magic, format, crc, "
                         f"file_bytes; {layout.size} bytes)")
    return SealLayout(layout, seal["magic"].encode("ascii"), seal["format"], offsets["crc"], seal["userblock_bytes"])


# Interface tags (/geometry/iface_tag; solver/lib/geometry/geometry.hpp InterfaceTag).
TAG_PLY1, TAG_PLY2, TAG_INTER12, TAG_INTER21 = 0, 1, 2, 3


class MissingResult(Exception):
    def __init__(self, path: pathlib.Path):
        super().__init__(str(path))
        self.path = pathlib.Path(path)


class DamagedResult(OSError):
    """A result file that is not the one the solver wrote (truncated, overwritten, not HDF5): one line naming it.
    An OSError, as h5py raises for an unreadable file, so that callers that catch those catch it too."""

    def __init__(self, path: pathlib.Path, why: str):
        super().__init__(f"damaged result {path} ({why}): rerun the case (delete the file first)")
        self.path = pathlib.Path(path)
        self.why = why


def verify_result_file(path) -> None:
    """Raise DamagedResult unless `path` carries the solver's seal and its size and CRC-32 match."""
    path = pathlib.Path(path)
    seal = seal_layout()
    with open(path, "rb") as f:
        head = f.read(seal.userblock_bytes)
        if len(head) < seal.struct.size or head[:len(seal.magic)] != seal.magic:
            raise DamagedResult(path, "it does not begin with the enamel-dem seal")
        _, fmt, crc, size = seal.struct.unpack_from(head)
        actual = path.stat().st_size
        if fmt != seal.format or size != actual:
            raise DamagedResult(path, f"seal format {fmt}, {size} bytes sealed, {actual} bytes on the disk")
        at = seal.crc_offset
        ours = zlib.crc32(head[:at] + b"\0\0\0\0" + head[at + 4:])  # the block with the crc field as zeros
        while chunk := f.read(1 << 22):
            ours = zlib.crc32(chunk, ours)
    if ours != crc:
        raise DamagedResult(path, f"checksum {crc:08x}, its bytes give {ours:08x}")


@dataclasses.dataclass
class Frame:
    index: int
    target_da: float        # requested Delta_a/d (-1: the final state)
    da: float               # Delta_a/d reached when it was written
    step: int
    iface_state: np.ndarray     # 0 elastic, 1 inelastic, 2 failed (per interface)
    iface_damage: np.ndarray    # 1 - secant stiffness / k
    beam_broken: np.ndarray     # 1 = rod element deleted
    node_displacement: np.ndarray  # (nodes, 6): ux uy uz rx ry rz, d and rad
    beam_stress: np.ndarray     # (beams,), sigma0: the solver's brittle-check stress (0 for deleted elements)


@dataclasses.dataclass
class Geometry:
    node_position: np.ndarray   # (nodes, 3), d
    node_ply: np.ndarray
    beam_nodes: np.ndarray      # (beams, 2)
    beam_strength: np.ndarray   # (beams,), sigma0
    iface_nodes: np.ndarray     # (ifaces, 2): A, B (B through the z-wrap when iface_zshift != 0)
    iface_tag: np.ndarray
    iface_midpoint: np.ndarray  # (ifaces, 3), d: centre of the shared Voronoi edge (z unwrapped from A)
    iface_zshift: np.ndarray    # image of B used: z_B + zshift * B (B = attrs["z_period_B"])
    iface_area: np.ndarray      # (ifaces,), d^2: tributary slice width x Voronoi edge length
    iface_slice: np.ndarray     # (ifaces,): slice index k, at x = k h_e
    attrs: dict                 # w_s, h_s, a0, h_e, z_period_B, y_crack_plane, theta_D_deg, num_slices, ...


@dataclasses.dataclass
class Result:
    path: pathlib.Path
    case: str
    params: dict            # the effective case (parsed /meta case_toml)
    meta: dict              # /meta attributes
    da: np.ndarray          # /rcurve/da_over_d
    R: np.ndarray           # /rcurve/R_over_Gamma
    R_init: float
    R_ss: float
    R_m: float
    dR_m: float
    da_max: float
    broken_rods: int        # last /history/broken_rod_elements
    da_first_rod_fracture: float  # Delta_a/d at the first history row with a broken rod element (nan: none)
    geometry: Geometry | None = None
    frames: list[Frame] | None = None

    @property
    def status(self) -> str:
        return str(self.meta.get("status", "unknown"))

    @property
    def completed(self) -> bool:
        return self.status == "completed"

    @property
    def wall_time_s(self) -> float:
        return float(self.meta.get("wall_time_s", math.nan))

    def param(self, key: str) -> float:
        return float(self.params[key])

    def frame_near(self, da: float) -> Frame:
        """The written frame whose requested Delta_a/d is nearest `da` (the final-state frame if none)."""
        return nearest_frame(self.frames, da)


def nearest_frame(frames: list, da: float):
    """Of frames in the order written (each with .target_da), the one whose requested Delta_a/d is nearest `da`
    (the larger on a tie); the last (the final state) when none was requested at a Delta_a."""
    targeted = [f for f in frames if f.target_da >= 0]
    if not targeted:
        return frames[-1]
    return min(targeted, key=lambda f: (abs(f.target_da - da), -f.target_da))


def attributes(obj) -> dict:
    """An HDF5 object's attributes as Python values (bytes decoded, numpy scalars unwrapped)."""
    out = {}
    for k, v in obj.attrs.items():
        if isinstance(v, bytes):
            v = v.decode()
        elif isinstance(v, np.generic):
            v = v.item()
        out[k] = v
    return out


def read_geometry(g) -> Geometry:
    """/geometry of an open file."""
    return Geometry(node_position=g["node_position"][:], node_ply=g["node_ply"][:], beam_nodes=g["beam_nodes"][:],
                    beam_strength=g["beam_strength_over_sigma0"][:], iface_nodes=g["iface_nodes"][:],
                    iface_tag=g["iface_tag"][:], iface_midpoint=g["iface_midpoint"][:],
                    iface_zshift=g["iface_zshift"][:], iface_area=g["iface_area"][:],
                    iface_slice=g["iface_slice"][:], attrs=attributes(g))


def read_frames(frames_group) -> list[Frame]:
    """Every /frames/<n> of an open file, in the order of n."""
    out = []
    for name in sorted(frames_group, key=int):
        fg = frames_group[name]
        a = attributes(fg)
        out.append(Frame(index=int(name), target_da=float(a["target_da_over_d"]), da=float(a["da_over_d"]),
                         step=int(a["step"]), iface_state=fg["iface_state"][:], iface_damage=fg["iface_damage"][:],
                         beam_broken=fg["beam_broken"][:], node_displacement=fg["node_displacement"][:],
                         beam_stress=fg["beam_stress"][:]))
    return out


def seal_result_file(path) -> None:
    """Write the seal of a result file again after a deliberate edit (h5py "r+"), as output.cpp writes it: what
    an edit changed is then the file's content, not damage. Only for files that carry a seal."""
    path = pathlib.Path(path)
    seal = seal_layout()
    with open(path, "r+b") as f:
        head = f.read(seal.struct.size)
        if head[:len(seal.magic)] != seal.magic:
            raise DamagedResult(path, "no enamel-dem seal to renew")
        f.seek(0)
        size = path.stat().st_size
        f.write(seal.struct.pack(seal.magic, seal.format, 0, size))
        f.seek(0)
        crc = 0
        while chunk := f.read(1 << 22):
            crc = zlib.crc32(chunk, crc)
        f.seek(0)
        f.write(seal.struct.pack(seal.magic, seal.format, crc, size))


def load_result(path, case: str | None = None, full: bool = False) -> Result:
    """Read one result file. `full` also reads /geometry and every /frames/<n> (for maps and VTK export).
    MissingResult when there is none; DamagedResult, naming the file, when it fails its seal or HDF5 cannot
    read what every result file holds."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise MissingResult(path)
    verify_result_file(path)
    try:
        with h5py.File(path, "r") as f:
            return read_open_result(f, path, case, full)
    except (OSError, KeyError, ValueError, TypeError, IndexError) as e:
        raise DamagedResult(path, f"{type(e).__name__}: {str(e).splitlines()[0] if str(e) else 'unreadable'}") from e


def params_of(case: str, meta: dict) -> dict:
    """The effective case of a run: the parameters in its case name, updated with its /meta case_toml."""
    params = params_from_name(case)
    try:
        params.update(tomllib.loads(meta.get("case_toml", "")))
    except (tomllib.TOMLDecodeError, TypeError):  # a damaged case_toml: keep the name's parameters
        pass
    return params


def read_open_result(f, path: pathlib.Path, case: str | None, full: bool) -> Result:
    """The Result of an open result file."""
    meta = attributes(f["meta"])
    rc = attributes(f["rcurve"])
    case = case or meta.get("case_source", path.parent.name)
    case = pathlib.Path(case).stem if case.endswith(".toml") else case
    params = params_of(case, meta)
    h = f["history"]
    broken = h["broken_rod_elements"][:]
    hda = h["da_over_d"][:]
    first = float(hda[np.argmax(broken > 0)]) if broken.size and broken.max() > 0 else math.nan
    res = Result(path=path, case=case, params=params, meta=meta,
                 da=f["rcurve/da_over_d"][:], R=f["rcurve/R_over_Gamma"][:],
                 R_init=float(rc.get("R_init_over_Gamma", math.nan)),
                 R_ss=float(rc.get("R_ss_over_Gamma", math.nan)),
                 R_m=float(rc.get("R_m_over_Gamma", math.nan)),
                 dR_m=float(rc.get("dR_m_over_Gamma", math.nan)),
                 da_max=float(rc.get("da_max_over_d", math.nan)),
                 broken_rods=int(broken[-1]) if broken.size else 0,
                 da_first_rod_fracture=first)
    if full:
        res.geometry = read_geometry(f["geometry"])
        res.frames = read_frames(f["frames"])
    return res
