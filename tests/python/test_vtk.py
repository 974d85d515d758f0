"""pipeline/export_vtk.py: the ParaView files, read back with VTK's
own reader (vtkXMLUnstructuredGridReader; the .pvd collection is plain XML), have one line cell per rod element
and one quad per interface, the arrays that --help promises with the values of the HDF5 file, one time point per
distinct frame, and interface quads that are the interfaces' faces: area = /geometry/iface_area, planar, normal
along A -> B, containing the midpoint of A and B (and the cohesive point). The rod stress is the solver's own
(/frames/<n>/beam_stress; its formula is tested in tests/cpp/test_beam.cpp) and never exceeds the strength of an
intact element.
"""
import subprocess
import sys
import xml.etree.ElementTree as ET

import h5py
import meshio
import numpy as np
import pytest
import vtk
from vtk.util.numpy_support import vtk_to_numpy

from conftest import ROOT
from enamel_results.results import load_result
from pipeline import export_vtk

CASE = "theta30_s28.5_e10_cv0.3_seed1"  # breaks rod elements within Delta_a/d = 1.5 on the tiny specimen
ROD_CELL_DATA = {"broken", "strength_over_sigma0", "stress_over_sigma0", "stress_ratio"}
ROD_POINT_DATA = {"displacement", "rotation", "radius"}
IFACE_CELL_DATA = {"damage", "state", "tag", "area", "opening"}
IFACE_POINT_DATA = {"displacement"}
AREA_RTOL = 1e-9      # quad area against /geometry/iface_area (both double precision)
GEOM_ATOL = 1e-12     # d: planarity, distances of points from the quad's plane (coordinates of order 10 d)
# The deletion rule "most_overloaded" removes one element per step and re-evaluates the rest, so an element may
# sit slightly above its strength at the step a frame is written (and beam_stress is stored as float32).
RATIO_TOL = 0.02


@pytest.fixture(scope="module")
def result(tiny_run):
    return tiny_run(CASE)


@pytest.fixture(scope="module")
def h5(result):
    """What the HDF5 file says, read with h5py alone (not through the exporter's loader)."""
    with h5py.File(result, "r") as f:
        g = f["geometry"]
        frames = [f["frames"][k] for k in sorted(f["frames"], key=int)]
        period = float(g.attrs["z_period_B"])
        X = g["node_position"][:]
        nodes = g["iface_nodes"][:]
        xb = X[nodes[:, 1]] + np.outer(g["iface_zshift"][:] * period, [0, 0, 1])
        yield dict(
            beams=g["beam_nodes"][:], X=X, ifaces=len(nodes), xa=X[nodes[:, 0]], xb=xb,
            iface_tag=g["iface_tag"][:], iface_area=g["iface_area"][:], iface_mid=g["iface_midpoint"][:],
            iface_slice=g["iface_slice"][:], h_e=float(g.attrs["h_e"]), w_s=float(g.attrs["w_s"]),
            h_s=float(g.attrs["h_s"]), period=period, node_slice=g["node_slice"][:],
            strength=g["beam_strength_over_sigma0"][:],
            frames=[dict(step=int(fg.attrs["step"]), da=float(fg.attrs["da_over_d"]),
                         broken=fg["beam_broken"][:], state=fg["iface_state"][:], damage=fg["iface_damage"][:],
                         q=fg["node_displacement"][:], stress=fg["beam_stress"][:]) for fg in frames])


def distinct_frames(frames):
    """Frames in step order without those repeating the previous frame's step (the exporter's documented rule)."""
    order = sorted(range(len(frames)), key=lambda i: (frames[i]["step"], i))
    return [frames[i] for j, i in enumerate(order) if j == 0 or frames[i]["step"] != frames[order[j - 1]]["step"]]


def read_vtu(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    assert grid.GetNumberOfCells() > 0, path

    def arrays(data):
        return {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i)) for i in range(data.GetNumberOfArrays())}
    types = np.array([grid.GetCellType(i) for i in range(grid.GetNumberOfCells())])
    offsets = vtk_to_numpy(grid.GetCells().GetOffsetsArray())
    return dict(points=vtk_to_numpy(grid.GetPoints().GetData()).astype(np.float64), types=types,
                sizes=np.diff(offsets), connectivity=vtk_to_numpy(grid.GetCells().GetConnectivityArray()),
                cell=arrays(grid.GetCellData()), point=arrays(grid.GetPointData()))


def read_pvd(path):
    """(time value, file) of each DataSet of a .pvd collection."""
    return [(float(e.get("timestep")), e.get("file"))
            for e in ET.parse(path).getroot().findall("./Collection/DataSet")]


@pytest.fixture(scope="module")
def exported(result, tmp_path_factory):
    out = tmp_path_factory.mktemp("vtk")
    r = subprocess.run([sys.executable, "-m", "pipeline.export_vtk", str(result), str(out)], cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    return out


def test_help_names_every_array(exported):
    r = subprocess.run([sys.executable, "-m", "pipeline.export_vtk", "--help"], cwd=ROOT, capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    for name in ROD_CELL_DATA | ROD_POINT_DATA | IFACE_CELL_DATA | IFACE_POINT_DATA:
        assert name in r.stdout, name
    first = read_vtu(exported / read_pvd(exported / "interfaces.pvd")[0][1])
    assert IFACE_CELL_DATA <= set(first["cell"]) and IFACE_POINT_DATA <= set(first["point"])


def test_time_series_has_one_point_per_distinct_frame(exported, h5):
    kept = distinct_frames(h5["frames"])
    assert len(h5["frames"]) == 3 and len(kept) == 2, "two targets; the final-state frame repeats the last one"
    for name in ("rods", "interfaces"):
        entries = read_pvd(exported / f"{name}.pvd")
        assert len(entries) == len(kept)
        assert [t for t, _ in entries] == pytest.approx([f["da"] for f in kept], rel=1e-9)
        assert all(b > a for (a, _), (b, _) in zip(entries, entries[1:])), "strictly increasing time values"
        assert all((exported / f).is_file() for _, f in entries)
    lines = (exported / "frames.csv").read_text().strip().splitlines()
    assert len(lines) == len(kept) + 1 and lines[0].startswith("index,time_value")


def test_rods_are_lines_with_the_frames_data(exported, h5):
    kept = distinct_frames(h5["frames"])
    for (_, fname), fr in zip(read_pvd(exported / "rods.pvd"), kept):
        rods = read_vtu(exported / fname)
        assert np.all(rods["types"] == vtk.VTK_LINE) and len(rods["types"]) == len(h5["beams"])
        np.testing.assert_array_equal(rods["connectivity"].reshape(-1, 2), h5["beams"])
        np.testing.assert_array_equal(rods["points"], h5["X"])
        assert ROD_CELL_DATA <= set(rods["cell"]) and ROD_POINT_DATA <= set(rods["point"])
        np.testing.assert_array_equal(rods["cell"]["broken"], fr["broken"])
        np.testing.assert_allclose(rods["cell"]["strength_over_sigma0"], h5["strength"], rtol=1e-15)
        np.testing.assert_array_equal(rods["point"]["displacement"], fr["q"][:, :3])
        np.testing.assert_array_equal(rods["point"]["rotation"], fr["q"][:, 3:])
        np.testing.assert_array_equal(rods["point"]["radius"], np.full(len(h5["X"]), export_vtk.ROD_RADIUS))
        assert np.all(np.isnan(rods["cell"]["stress_over_sigma0"][fr["broken"] > 0]))
        intact = fr["broken"] == 0
        np.testing.assert_array_equal(rods["cell"]["stress_over_sigma0"][intact], fr["stress"][intact])
    assert kept[-1]["broken"].sum() > 0, "this tiny case breaks rods"


def test_interfaces_are_quads_with_the_frames_data(exported, h5):
    kept = distinct_frames(h5["frames"])
    for (_, fname), fr in zip(read_pvd(exported / "interfaces.pvd"), kept):
        ifs = read_vtu(exported / fname)
        assert np.all(ifs["types"] == vtk.VTK_QUAD) and len(ifs["types"]) == h5["ifaces"]
        assert np.all(ifs["sizes"] == 4)
        np.testing.assert_array_equal(ifs["cell"]["state"], fr["state"])
        np.testing.assert_array_equal(ifs["cell"]["damage"], fr["damage"])
        np.testing.assert_array_equal(ifs["cell"]["tag"], h5["iface_tag"])
        np.testing.assert_array_equal(ifs["cell"]["area"], h5["iface_area"])
        assert ifs["point"]["displacement"].shape == (4 * h5["ifaces"], 3)
    assert np.any(kept[-1]["state"] > 0), "the process zone is there to see"


def test_interface_quads_are_the_interface_faces(exported, h5):
    ifs = read_vtu(exported / read_pvd(exported / "interfaces.pvd")[0][1])
    Q = ifs["points"][ifs["connectivity"].reshape(-1, 4)]           # (n, 4, 3) corners in cell order
    e1, e2 = Q[:, 1] - Q[:, 0], Q[:, 3] - Q[:, 0]
    # a rectangle: opposite sides equal, adjacent sides perpendicular
    np.testing.assert_allclose(Q[:, 2] - Q[:, 1], e2, atol=GEOM_ATOL)
    assert np.max(np.abs(np.einsum("ij,ij->i", e1, e2))) < GEOM_ATOL
    area = np.linalg.norm(np.cross(e1, e2), axis=1)
    np.testing.assert_allclose(area, h5["iface_area"], rtol=AREA_RTOL)
    # planar, and its plane is the interface's: normal along A -> B (B's periodic image), side e1 along x
    normal = np.cross(e1, e2) / area[:, None]
    for j in range(4):
        assert np.max(np.abs(np.einsum("ij,ij->i", Q[:, j] - Q[:, 0], normal))) < GEOM_ATOL
    ab = h5["xb"] - h5["xa"]
    ab /= np.linalg.norm(ab, axis=1)[:, None]
    np.testing.assert_allclose(np.abs(np.einsum("ij,ij->i", normal, ab)), 1.0, atol=1e-12)
    np.testing.assert_allclose(e1[:, 1:], 0.0, atol=GEOM_ATOL)

    def inside(p):
        s = np.einsum("ij,ij->i", p - Q[:, 0], e1) / np.einsum("ij,ij->i", e1, e1)
        t = np.einsum("ij,ij->i", p - Q[:, 0], e2) / np.einsum("ij,ij->i", e2, e2)
        off = np.abs(np.einsum("ij,ij->i", p - Q[:, 0], normal))
        return (s >= -1e-12) & (s <= 1 + 1e-12) & (t >= -1e-12) & (t <= 1 + 1e-12) & (off < GEOM_ATOL)

    assert np.all(inside(0.5 * (h5["xa"] + h5["xb"]))), "the midpoint of A and B is on the face"
    assert np.all(inside(h5["iface_mid"])), "so is the cohesive point (the Voronoi edge's midpoint)"
    # along x: the slice's tributary strip, inside the specimen
    x = Q[:, :, 0]
    assert x.min() >= 0 and x.max() <= h5["w_s"] + GEOM_ATOL
    width = np.abs(e1[:, 0])
    end = (h5["iface_slice"] == 0) | (h5["iface_slice"] == h5["iface_slice"].max())
    np.testing.assert_allclose(width[~end], h5["h_e"], rtol=1e-12)
    np.testing.assert_allclose(width[end], 0.5 * h5["h_e"], rtol=1e-12)
    # along the edge: the shared Voronoi edge of the slice. Its ends (taken at the slice's x) are Voronoi vertices:
    # no node of the slice (or its z-images) is nearer than A and B, and a third one is as near, unless the end
    # lies on the specimen's side y = 0 or h_s. A wrong l_i moves the ends off the vertices.
    images = np.array([-1.0, 0.0, 1.0]) * h5["period"]
    for j in (0, 3):  # corners 0 and 3: the two ends of the edge on the same side in x
        p = Q[:, j].copy()
        p[:, 0] = h5["xa"][:, 0]
        for i in range(h5["ifaces"]):
            nodes = h5["X"][h5["node_slice"] == h5["iface_slice"][i]]
            pts = (nodes[:, None, :] + np.outer(images, [0, 0, 1])[None]).reshape(-1, 3)
            dist = np.linalg.norm(pts - p[i], axis=1)
            r = np.linalg.norm(p[i] - h5["xa"][i])
            assert dist.min() == pytest.approx(r, rel=1e-9), i
            on_side = min(abs(p[i, 1]), abs(p[i, 1] - h5["h_s"])) < 1e-9
            assert on_side or np.count_nonzero(np.abs(dist - r) < 1e-9 * max(r, 1)) >= 3, i


def test_quad_corners_follow_rigid_motions(result):
    """Corners move as rigid-arm points of both nodes: a translation moves every corner by itself, a rotation
    about z (the periodic axis) by theta x corner; neither opens an interface."""
    g = load_result(result, full=True).geometry
    quads = export_vtk.interface_quads(g)
    X = g.node_position
    t = np.array([0.1, -0.2, 0.3])
    w = np.array([0.0, 0.0, 0.01])
    for q6, expected in ((np.tile(np.r_[t, 0, 0, 0], (len(X), 1)), lambda p: np.broadcast_to(t, p.shape)),
                         (np.hstack([np.cross(w, X), np.tile(w, (len(X), 1))]), lambda p: np.cross(w, p))):
        corner_u, opening = export_vtk.interface_motion(q6, g, quads)
        np.testing.assert_allclose(corner_u, expected(quads["corners"]), atol=1e-14)
        np.testing.assert_allclose(opening, 0.0, atol=1e-14)
    # pulling node B of one interface along the normal opens it by that amount, along the normal
    q6 = np.zeros((len(X), 6))
    i = 0
    q6[g.iface_nodes[i, 1], :3] = 0.01 * quads["normal"][i]
    corner_u, opening = export_vtk.interface_motion(q6, g, quads)
    np.testing.assert_allclose(opening[i], 0.01 * quads["normal"][i], atol=1e-15)
    np.testing.assert_allclose(corner_u[i], np.tile(0.005 * quads["normal"][i], (4, 1)), atol=1e-15)


def test_xdmf_series_read_back(result, h5, tmp_path):
    info = export_vtk.export(result, tmp_path, "xdmf")
    assert (info["beams"], info["interfaces"]) == (len(h5["beams"]), h5["ifaces"])
    assert (tmp_path / "rods.h5").exists() and (tmp_path / "interfaces.h5").exists()
    for name, kind, count, cell_names, point_names in (
            ("rods", "line", len(h5["beams"]), ROD_CELL_DATA, ROD_POINT_DATA),
            ("interfaces", "quad", h5["ifaces"], IFACE_CELL_DATA, IFACE_POINT_DATA)):
        reader = meshio.xdmf.TimeSeriesReader(tmp_path / f"{name}.xdmf")
        _, cells = reader.read_points_cells()
        assert [c.type for c in cells] == [kind] and len(cells[0].data) == count
        assert reader.num_steps == len(distinct_frames(h5["frames"]))
        _, point_data, cell_data = reader.read_data(reader.num_steps - 1)
        assert cell_names <= set(cell_data) and point_names <= set(point_data)
    assert 'NodesPerElement="2"' in (tmp_path / "rods.xdmf").read_text()


def test_intact_rods_stay_below_their_strength(result):
    r = load_result(result, full=True)
    g = r.geometry
    assert r.broken_rods > 0
    worst = max(float(np.max((f.beam_stress / g.beam_strength)[f.beam_broken == 0])) for f in r.frames)
    assert worst <= 1 + RATIO_TOL
    assert worst > 0.5, "near a growing crack some intact element is loaded close to its strength"
