#!/usr/bin/env python3
"""Export one enamel-dem result (result.h5) to ParaView files, one time point per written frame (/frames/<n>).

    python3 -m pipeline.export_vtk RESULT_H5 OUTDIR [--format vtu|xdmf]     (from the repository root)

Two series, both in the reference configuration (apply "Warp By Vector" with `displacement` to deform):
  rods        line cells, one per rod (beam) element, between its two nodes.
              cell data: broken (1 = deleted), strength_over_sigma0, stress_over_sigma0 (the solver's brittle
              criterion as the solver computed it, /frames/<n>/beam_stress: axial N/A plus the larger end
              bending stress, sigma0 units; NaN for deleted elements), stress_ratio (stress / strength: the
              element is deleted when it reaches 1). point data: displacement (ux, uy, uz), rotation (rx, ry, rz),
              radius (d/2, the rod's extreme fibre: ParaView's Tube filter, "Vary Radius: By Absolute Scalar").
  interfaces  quad cells, one per interface: the shared Voronoi face of its two rods, in the interface's plane
              (normal along A -> B, B through the periodic z-wrap), h_x along x by l_i along the Voronoi edge,
              centred on the edge's midpoint (the solver's cohesive point, /geometry/iface_midpoint). h_x is the
              slice's tributary width (h_e; h_e/2 for the first and last slice, which end at x = 0 and w_s), so
              that h_x l_i = area. cell data: damage (1 - secant stiffness / k), state (0 elastic, 1 inelastic,
              2 failed), tag (0 ply 1, 1 ply 2, 2 interlayer 1-2, 3 interlayer 2-1), area (d^2), opening (the
              solver's relative displacement of the two faces at the cohesive point, d). point data:
              displacement of each corner: the mean of the two faces' rigid-arm motions, u + theta x (corner - node)
              for node A and for node B (the solver's linearised kinematics, solver/lib/geometry/cohesive.cpp).
              The quads keep z unwrapped from node A: interlayer 2-1 faces sit between z = t and z = B.
Lengths in d, stresses in sigma0. Time value of each point: the frame's crack advance Delta_a/d (frames that
repeat the state of the previous one, same solver step, are skipped; if the advances are not strictly
increasing the time value is the frame's number 0, 1, ...); OUTDIR/frames.csv lists the frames.

Formats: --format vtu (default): rods.pvd + rods_NNN.vtu, interfaces.pvd + interfaces_NNN.vtu;
         --format xdmf: rods.xdmf/.h5 and interfaces.xdmf/.h5 written with meshio.xdmf.TimeSeriesWriter.
"""
from __future__ import annotations

import argparse
import os
import pathlib
import sys
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from enamel_results.results import EXIT_DAMAGED, EXIT_MISSING, DamagedResult, MissingResult, load_result

ROD_RADIUS = 0.5  # d: the extreme fibre c of both sections (hexagon across flats d, circle of diameter d)


# --- interface faces ---
def interface_quads(g) -> dict:
    """The reference geometry of every interface's face: corners (n, 4, 3), the unit normal A -> B (n, 3), the
    two nodes' positions with B's periodic image (n, 3 each), tributary width along x and edge length (n,).
    Corners go round the quad: (-x, -edge), (+x, -edge), (+x, +edge), (-x, +edge)."""
    X = g.node_position.astype(np.float64)
    a = g.attrs
    h_e, period = float(a["h_e"]), float(a["z_period_B"])
    last = int(a["num_slices"]) - 1
    xa = X[g.iface_nodes[:, 0]]
    xb = X[g.iface_nodes[:, 1]] + np.outer(g.iface_zshift.astype(np.float64) * period, [0.0, 0.0, 1.0])
    normal = xb - xa
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    ex = np.array([1.0, 0.0, 0.0])
    edge = np.cross(ex, normal)  # in the slice's yz-plane, perpendicular to A -> B: along the Voronoi edge
    edge /= np.linalg.norm(edge, axis=1)[:, None]
    k = g.iface_slice
    # The slice's tributary strip along x: [x - h_e/2, x + h_e/2], cut at the specimen's ends x = 0 and w_s.
    x0 = np.where(k == 0, 0.0, -0.5 * h_e)
    x1 = np.where(k == last, 0.0, 0.5 * h_e)
    width = x1 - x0
    length = g.iface_area.astype(np.float64) / width
    c = g.iface_midpoint.astype(np.float64)
    half = 0.5 * length[:, None] * edge
    corners = np.stack([c + x0[:, None] * ex - half, c + x1[:, None] * ex - half,
                        c + x1[:, None] * ex + half, c + x0[:, None] * ex + half], axis=1)
    return dict(corners=corners, normal=normal, xa=xa, xb=xb, width=width, length=length, centre=c)


def rigid_arm_displacement(q6: np.ndarray, nodes: np.ndarray, node_pos: np.ndarray, points: np.ndarray):
    """u + theta x (point - node position) for each row: the linearised motion of a point carried by a node."""
    return q6[nodes, :3] + np.cross(q6[nodes, 3:], points - node_pos)


def interface_motion(q6: np.ndarray, g, quads: dict):
    """(corner displacements (n, 4, 3): mean of the two faces; opening at the cohesive point (n, 3): face B
    minus face A, as cohesive::relativeDisplacement)."""
    ia, ib = g.iface_nodes[:, 0], g.iface_nodes[:, 1]
    corner = np.zeros_like(quads["corners"])
    for j in range(4):
        p = quads["corners"][:, j]
        corner[:, j] = 0.5 * (rigid_arm_displacement(q6, ia, quads["xa"], p)
                              + rigid_arm_displacement(q6, ib, quads["xb"], p))
    c = quads["centre"]
    opening = rigid_arm_displacement(q6, ib, quads["xb"], c) - rigid_arm_displacement(q6, ia, quads["xa"], c)
    return corner, opening


# --- writing ---
def distinct_frames(frames):
    """Frames in order, without those that repeat the previous frame's solver step (the final-state frame
    often repeats the last targeted one)."""
    out = []
    for f in sorted(frames, key=lambda f: (f.step, f.index)):
        if out and out[-1].step == f.step:
            continue
        out.append(f)
    return out


def write_pvd(path: pathlib.Path, entries):
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">', "  <Collection>"]
    for t, fname in entries:
        lines.append(f'    <DataSet timestep="{t:.10g}" group="" part="0" file={quoteattr(fname)}/>')
    lines += ["  </Collection>", "</VTKFile>", ""]
    path.write_text("\n".join(lines))


def add_nodes_per_element(path: pathlib.Path) -> None:
    """The XDMF format needs NodesPerElement on Polyline topologies (our rods: 2); meshio 5 leaves it out."""
    text = path.read_text()
    text = text.replace('TopologyType="Polyline" NumberOfElements=',
                        'TopologyType="Polyline" NodesPerElement="2" NumberOfElements=')
    path.write_text(text)


def rod_data(r, frame) -> dict:
    """Point and cell data of the rods in one frame; the stress is the solver's own (/frames/<n>/beam_stress, the
    brittle check's axial plus larger end bending stress), NaN for deleted elements."""
    g = r.geometry
    q = frame.node_displacement.astype(np.float64)
    strength = g.beam_strength.astype(np.float64)
    broken = frame.beam_broken.astype(np.uint8)
    stress = np.where(broken > 0, np.nan, frame.beam_stress.astype(np.float64))
    return dict(point_data={"displacement": q[:, :3], "rotation": q[:, 3:],
                            "radius": np.full(len(q), ROD_RADIUS)},
                cell_data={"broken": [broken], "strength_over_sigma0": [strength],
                           "stress_over_sigma0": [stress], "stress_ratio": [stress / strength]})


def interface_data(r, quads: dict, frame) -> dict:
    """Point data (per quad corner) and cell data of the interfaces in one frame."""
    g = r.geometry
    corner_u, opening = interface_motion(frame.node_displacement.astype(np.float64), g, quads)
    return dict(point_data={"displacement": corner_u.reshape(-1, 3)},
                cell_data={"damage": [frame.iface_damage.astype(np.float64)],
                           "state": [frame.iface_state.astype(np.int32)],
                           "tag": [g.iface_tag.astype(np.int32)],
                           "area": [g.iface_area.astype(np.float64)],
                           "opening": [opening]})


def export(result_path, outdir, fmt: str = "vtu") -> dict:
    r = load_result(result_path, full=True)
    g = r.geometry
    outdir = pathlib.Path(outdir).resolve()
    outdir.mkdir(parents=True, exist_ok=True)
    frames = distinct_frames(r.frames)
    times = [f.da for f in frames]
    if any(b <= a for a, b in zip(times, times[1:])):  # not strictly increasing: number the frames instead
        times = [float(i) for i in range(len(frames))]
    X = g.node_position.astype(np.float64)
    rod_cells = [("line", g.beam_nodes.astype(np.int64))]
    quads = interface_quads(g)
    n_iface = len(g.iface_nodes)
    quad_points = quads["corners"].reshape(-1, 3)  # 4 corners per interface, not shared: faces open apart
    iface_cells = [("quad", np.arange(4 * n_iface, dtype=np.int64).reshape(n_iface, 4))]

    def frame_data(f):
        return rod_data(r, f), interface_data(r, quads, f)

    written = []
    if fmt == "vtu":
        rod_entries, iface_entries = [], []
        for i, (f, t) in enumerate(zip(frames, times)):
            rods, ifaces = frame_data(f)
            rn, inn = f"rods_{i:03d}.vtu", f"interfaces_{i:03d}.vtu"
            meshio.Mesh(X, rod_cells, **rods).write(outdir / rn)
            meshio.Mesh(quad_points, iface_cells, **ifaces).write(outdir / inn)
            rod_entries.append((t, rn))
            iface_entries.append((t, inn))
        write_pvd(outdir / "rods.pvd", rod_entries)
        write_pvd(outdir / "interfaces.pvd", iface_entries)
        written = [outdir / "rods.pvd", outdir / "interfaces.pvd"]
    elif fmt == "xdmf":
        data = [frame_data(f) for f in frames]
        cwd = os.getcwd()
        os.chdir(outdir)  # meshio 5 writes the .h5 beside the working directory, not beside the .xdmf
        try:
            for name, pts, cells, k in (("rods", X, rod_cells, 0), ("interfaces", quad_points, iface_cells, 1)):
                with meshio.xdmf.TimeSeriesWriter(f"{name}.xdmf") as w:
                    w.write_points_cells(pts, cells)
                    for t, d in zip(times, data):
                        w.write_data(t, point_data=d[k]["point_data"], cell_data=d[k]["cell_data"])
                add_nodes_per_element(outdir / f"{name}.xdmf")
                written.append(outdir / f"{name}.xdmf")
        finally:
            os.chdir(cwd)
    else:
        raise ValueError(f"unknown format '{fmt}'")
    with open(outdir / "frames.csv", "w") as fcsv:
        fcsv.write("index,time_value,target_da_over_d,da_over_d,step,frame_group\n")
        for i, (f, t) in enumerate(zip(frames, times)):
            fcsv.write(f"{i},{t:.10g},{f.target_da:g},{f.da:.10g},{f.step},/frames/{f.index}\n")
    return dict(files=written, frames=len(frames), beams=len(g.beam_nodes), interfaces=n_iface)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("result", type=pathlib.Path, metavar="RESULT_H5", help="a result.h5 written by enamel-dem")
    p.add_argument("outdir", type=pathlib.Path, metavar="OUTDIR", help="output directory (created)")
    p.add_argument("--format", choices=("vtu", "xdmf"), default="vtu",
                   help="vtu: .pvd + .vtu series (default); xdmf: XDMF time series (meshio TimeSeriesWriter)")
    args = p.parse_args(argv)
    try:
        info = export(args.result, args.outdir, args.format)
    except MissingResult as e:
        print(f"export_vtk.py: missing result file {e.path}: run the case first "
              f"(`enamel-dem run CASE.toml` or `make runs PRESET=...`)", file=sys.stderr)
        return EXIT_MISSING
    except DamagedResult as e:
        print(f"export_vtk.py: {e}", file=sys.stderr)
        return EXIT_DAMAGED
    for fpath in info["files"]:
        print(fpath)
    print(f"{info['frames']} frames, {info['beams']} rod elements, {info['interfaces']} interfaces",
          file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
