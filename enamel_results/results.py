"""Load one result.h5 written by enamel-dem (solver/lib/output.cpp defines the layout): /meta, /rcurve,
/history, and with full=True /geometry and every /frames/<n>.

Normalisation everywhere: crack advance Delta_a by the rod spacing d, crack resistance R by the interface
fracture energy Gamma_i, rod strength by the interface strength sigma0.
"""
from __future__ import annotations

import dataclasses
import math
import pathlib
import tomllib

import h5py
import numpy as np

from enamel_results.cases import params_from_name

# Exit status when a result file is missing (as the solver's MISSING_FILE, solver/lib/exit_codes.hpp).
EXIT_MISSING = 3

# Interface tags (/geometry/iface_tag; solver/lib/geometry.hpp InterfaceTag).
TAG_PLY1, TAG_PLY2, TAG_INTER12, TAG_INTER21 = 0, 1, 2, 3


class MissingResult(Exception):
    def __init__(self, path: pathlib.Path):
        super().__init__(str(path))
        self.path = pathlib.Path(path)


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
    beam_stress: np.ndarray | None  # (beams,), sigma0: the solver's brittle-check stress (0 for deleted elements);
    #                                 None in files of solvers before 2026-12-02, which did not write it


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
        targeted = [f for f in self.frames if f.target_da >= 0]
        if not targeted:
            return self.frames[-1]
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
                         beam_stress=fg["beam_stress"][:] if "beam_stress" in fg else None))
    return out


def load_result(path, case: str | None = None, full: bool = False) -> Result:
    """Read one result.h5. `full` also reads /geometry and every /frames/<n> (for maps and VTK export)."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise MissingResult(path)
    with h5py.File(path, "r") as f:
        meta = attributes(f["meta"])
        rc = attributes(f["rcurve"])
        case = case or meta.get("case_source", path.parent.name)
        case = pathlib.Path(case).stem if case.endswith(".toml") else case
        params = params_from_name(case)
        try:
            params.update(tomllib.loads(meta.get("case_toml", "")))
        except (tomllib.TOMLDecodeError, TypeError):  # a damaged case_toml: keep the name's parameters
            pass
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
