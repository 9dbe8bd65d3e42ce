"""Tests of the Python package: the same meshes as the command line, arrays in and out, every
error class raising delamesh.Error, determinism, threads, interrupts, and round trips through
meshio and pyvista.

The command line is taken from $DELAMESH_CLI, else from the workspace's target/debug or
target/release; the tests comparing with it are skipped when there is none.
"""

from __future__ import annotations

import json
import os
import shutil
import re
import signal
import subprocess
import threading
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import meshio
import numpy as np
import pytest

import delamesh

ROOT = Path(__file__).resolve().parents[2]
SPHERE = ROOT / "models" / "sphere.off"
BOX = ROOT / "tests" / "data" / "box.off"  # sharp edges: feature curves and a line block
BAD = ROOT / "tests" / "bad"
# Coarse criteria: each mesh takes a fraction of a second, even in a debug build.
SPHERE_OPTIONS = {"facet_size": 0.3, "cell_size": 0.3}
BOX_OPTIONS = {"edge_size": 0.5, "facet_size": 0.5}


def cli() -> Path | None:
    given = os.environ.get("DELAMESH_CLI")
    if given:
        return Path(given)
    for profile in ("debug", "release"):
        exe = ROOT / "target" / profile / "delamesh"
        if exe.exists():
            return exe
    return shutil.which("delamesh") and Path(shutil.which("delamesh"))


needs_cli = pytest.mark.skipif(cli() is None, reason="no delamesh command line built")


def flags(options: dict) -> list[str]:
    out = []
    for name, value in options.items():
        flag = "--" + name.replace("_", "-")
        if value is True:
            out.append(flag)
        elif value is not False:
            out.append(f"{flag}={value}")
    return out


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(cli()), *args], capture_output=True, text=True, timeout=600)


def cli_mesh(path: Path, options: dict, tmp_path: Path) -> meshio.Mesh:
    out = tmp_path / "cli.vtu"
    done = run_cli("mesh", str(path), "-o", str(out), "-q", *flags(options))
    assert done.returncode == 0, done.stderr
    return meshio.read(out)


def cli_error(*args: str) -> str:
    done = run_cli(*args)
    assert done.returncode != 0
    line = done.stderr.strip().splitlines()[0]
    assert line.startswith("error: ")
    return line[len("error: ") :]


def assert_same_mesh(a: meshio.Mesh, b: meshio.Mesh) -> None:
    """Same points, same blocks of cells, same cell data (NaN equal to NaN; meshio reads one-
    component arrays of .vtu files as (n, 1), ours are (n,))."""
    np.testing.assert_array_equal(a.points, b.points)
    assert [c.type for c in a.cells] == [c.type for c in b.cells]
    for ca, cb in zip(a.cells, b.cells):
        np.testing.assert_array_equal(ca.data, cb.data)
    assert sorted(a.cell_data) == sorted(b.cell_data)
    for name in a.cell_data:
        for x, y in zip(a.cell_data[name], b.cell_data[name]):
            x, y = (np.asarray(z, dtype=float).reshape(len(z), -1) for z in (x, y))
            np.testing.assert_array_equal(x, y)


def tet_volumes(m: meshio.Mesh) -> np.ndarray:
    p = m.points[m.cells_dict["tetra"]]
    return (
        np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6
    )


def surface(path: Path) -> tuple[np.ndarray, np.ndarray]:
    m = delamesh.read(path)  # meshio reads no quads from OFF files
    return m.points, m.cells_dict["triangle"]


# --- the same meshes as the command line ---------------------------------------------------------


@needs_cli
@pytest.mark.parametrize(
    "path, options",
    [
        (SPHERE, SPHERE_OPTIONS),
        (BOX, BOX_OPTIONS),
        (SPHERE, {"cell_size": 0.4, "no_features": True, "facet_angle": 20}),
        (SPHERE, {"sizing_expr": "0.2 + 0.3 * abs(z)", "size_gradation": 0.5}),
        (BOX, {"subdivision": "auto", "facet_size": 0.5, "cell_size": 0.5}),
        (BOX, {"crease_angle": 60, "subdivision": "catmull-clark", "facet_size": 0.5}),
    ],
)
def test_same_mesh_as_the_command_line(path, options, tmp_path):
    assert_same_mesh(delamesh.mesh(path, **options), cli_mesh(path, options, tmp_path))


# What `delamesh mesh` takes that `delamesh.mesh` does not: where the mesh and its report go
# (the caller writes the result), and run-time plugins (the command line's domain loader).
NOT_KEYWORDS = {"output", "report", "report_plot", "ascii", "plugin", "plugin_config", "quiet", "help"}


@needs_cli
def test_every_meshing_option_of_the_command_line_is_a_keyword():
    usage = run_cli("mesh", "--help").stdout
    long_options = {m.replace("-", "_") for m in re.findall(r"^\s+(?:-\w, )?--([a-z][a-z-]*)", usage, re.M)}
    assert {"facet_size", "no_features", "preserve_surface"} <= long_options
    assert long_options - NOT_KEYWORDS <= set(delamesh.OPTIONS), long_options - set(delamesh.OPTIONS)


@needs_cli
def test_feature_edges_come_as_a_line_block_with_curves(tmp_path):
    m = delamesh.mesh(BOX, **BOX_OPTIONS)
    assert [c.type for c in m.cells] == ["tetra", "triangle", "line"]
    curves = m.cell_data["curve"][2]
    assert len(curves) == len(m.cells[2].data) and (curves >= 0).all()
    # Labels do not apply to the other blocks: -1 there, as in the .vtu files.
    assert (m.cell_data["curve"][0] == -1).all() and (m.cell_data["subdomain"][1] == -1).all()


def test_arrays_and_meshio_input_give_the_mesh_of_the_file():
    from_file = delamesh.mesh(SPHERE, **SPHERE_OPTIONS)
    vertices, faces = surface(SPHERE)
    assert_same_mesh(delamesh.mesh((vertices, faces), **SPHERE_OPTIONS), from_file)
    assert_same_mesh(delamesh.mesh(meshio.read(SPHERE), **SPHERE_OPTIONS), from_file)
    # Any integer type and a non-contiguous float array are accepted.
    faces32 = np.asarray(faces, dtype=np.uint32)
    fortran = np.asfortranarray(vertices)
    assert_same_mesh(delamesh.mesh((fortran, faces32), **SPHERE_OPTIONS), from_file)


def two_balls() -> np.ndarray:
    """Labels indexed [x, y, z]: a ball of label 2 inside a ball of label 1."""
    x, y, z = np.mgrid[0:20, 0:24, 0:28]
    r2 = (x - 10) ** 2 + (y - 12) ** 2 + (z - 14) ** 2
    labels = (r2 < 64).astype(np.uint8)
    labels[r2 < 16] = 2
    return labels


IMAGE_OPTIONS = {"facet_size": 1.0, "cell_size": 1.0}


@needs_cli
def test_an_image_array_gives_the_mesh_of_its_file(tmp_path):
    nib = pytest.importorskip("nibabel")
    labels = two_balls()
    nib.save(nib.Nifti1Image(labels, np.diag([0.5, 0.5, 0.5, 1.0])), tmp_path / "balls.nii")
    from_array = delamesh.mesh(labels, voxel_size=0.5, **IMAGE_OPTIONS)
    assert_same_mesh(from_array, cli_mesh(tmp_path / "balls.nii", IMAGE_OPTIONS, tmp_path))
    # Any integer type, the same labels: the same mesh.
    assert_same_mesh(
        delamesh.mesh(labels.astype(np.int32), voxel_size=0.5, **IMAGE_OPTIONS), from_array
    )


def test_an_image_array_is_meshed_where_its_labels_are():
    labels = two_balls()
    origin = (10.0, -5.0, 2.0)
    m = delamesh.mesh(labels, voxel_size=(0.5, 0.5, 0.5), origin=origin, **IMAGE_OPTIONS)
    assert set(np.unique(m.cell_data["subdomain"][0])) == {1, 2}
    v = tet_volumes(m)
    assert (v > 0).all()
    # Axes in [x, y, z] order: the outer ball's centre is voxel (10, 12, 14), radius 8 voxels.
    centre = np.asarray(origin) + 0.5 * np.array([10, 12, 14])
    box_centre = (m.points.min(0) + m.points.max(0)) / 2
    np.testing.assert_allclose(box_centre, centre, atol=0.5)
    ball = 4 / 3 * np.pi * 4.0**3
    assert abs(v.sum() - ball) < 0.15 * ball


# --- arrays out: dtypes, shapes, orientation -----------------------------------------------------


def test_dtypes_shapes_and_orientation():
    m = delamesh.mesh(BOX, **BOX_OPTIONS)
    assert m.points.dtype == np.float64 and m.points.shape[1] == 3
    for block in m.cells:
        assert block.data.dtype == np.int64
        assert block.data.min() >= 0 and block.data.max() < len(m.points)
    for name in ("subdomain", "patch", "curve"):
        assert all(a.dtype == np.int32 for a in m.cell_data[name])
    v = tet_volumes(m)
    assert (v > 0).all(), "every tetrahedron is positive: det[b-a, c-a, d-a] > 0"
    # The boundary is oriented outwards: its divergence-theorem volume is the tets' volume,
    # here the box's (a polyhedron is meshed exactly).
    t = m.points[m.cells_dict["triangle"]]
    enclosed = np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6
    vertices, faces = surface(BOX)
    s = vertices[faces]
    box = np.einsum("ij,ij->i", s[:, 0], np.cross(s[:, 1], s[:, 2])).sum() / 6
    assert enclosed == pytest.approx(v.sum(), rel=1e-9)
    assert v.sum() == pytest.approx(abs(box), rel=1e-9)


def test_the_result_is_writable_and_wraps_in_pyvista(tmp_path):
    m = delamesh.mesh(SPHERE, **SPHERE_OPTIONS)
    m.points[0, 0] += 0.0  # numpy arrays of our own, not read-only views
    m.write(tmp_path / "out.vtu")
    assert_same_mesh(meshio.read(tmp_path / "out.vtu"), m)
    pv = pytest.importorskip("pyvista")
    grid = pv.wrap(m)
    assert grid.n_points == len(m.points)
    assert grid.n_cells == sum(len(c.data) for c in m.cells)
    np.testing.assert_array_equal(
        grid.cell_data["subdomain"], np.concatenate(m.cell_data["subdomain"])
    )
    grid.save(tmp_path / "pv.vtu")
    assert_same_mesh(delamesh.read(tmp_path / "pv.vtu"), delamesh.read(tmp_path / "out.vtu"))


# --- delaunay, info, read, write -----------------------------------------------------------------


def test_delaunay_is_positive_and_empty_sphere():
    rng = np.random.default_rng(7)
    points = rng.random((200, 3))
    tets = delamesh.delaunay(points)
    assert tets.dtype == np.int64 and tets.shape[1] == 4
    p = points[tets]
    a, b, c, d = p[:, 0], p[:, 1], p[:, 2], p[:, 3]
    assert (np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) > 0).all()
    # No point strictly inside any circumsphere (with a margin: the check is in floating point).
    m = np.stack([b - a, c - a, d - a], axis=1)
    rhs = 0.5 * np.stack([(x * x).sum(1) for x in (b - a, c - a, d - a)], axis=1)
    centre = a + np.linalg.solve(m, rhs[..., None])[..., 0]
    r2 = ((a - centre) ** 2).sum(1)
    d2 = ((points[None, :, :] - centre[:, None, :]) ** 2).sum(2)
    assert (d2 >= r2[:, None] * (1 - 1e-9)).all()
    # A repeated point is its first occurrence.
    again = delamesh.delaunay(np.vstack([points, points[:5]]))
    assert again.max() < len(points)
    np.testing.assert_array_equal(np.sort(again, axis=None), np.sort(tets, axis=None))


@needs_cli
def test_delaunay_matches_the_command_line(tmp_path):
    points = np.random.default_rng(3).random((100, 3))
    np.savetxt(tmp_path / "p.xyz", points, fmt="%.17g")
    done = run_cli("delaunay", str(tmp_path / "p.xyz"), "-o", str(tmp_path / "dt.vtu"))
    assert done.returncode == 0, done.stderr
    dt = meshio.read(tmp_path / "dt.vtu")
    index = {tuple(p): i for i, p in enumerate(points)}
    theirs = np.array([[index[tuple(dt.points[v])] for v in t] for t in dt.cells_dict["tetra"]])
    np.testing.assert_array_equal(delamesh.delaunay(points), theirs)


@needs_cli
@pytest.mark.parametrize("path", [SPHERE, BOX])
def test_info_is_the_json_of_the_command_line(path):
    done = run_cli("info", "--json", str(path))
    assert done.returncode == 0, done.stderr
    assert delamesh.info(path) == json.loads(done.stdout)
    assert delamesh.info(str(path))["kind"] == "surface"


@pytest.mark.parametrize("ext", ["vtu", "vtk", "mesh", "msh"])
def test_write_then_read_gives_the_mesh_back(ext, tmp_path):
    m = delamesh.mesh(BOX, **BOX_OPTIONS)
    delamesh.write(tmp_path / f"out.{ext}", m)
    if ext == "msh":
        # Gmsh files are written, not read: meshio reads them back, labels as physical tags.
        back = meshio.read(tmp_path / f"out.{ext}")
        subdomains = back.cell_data_dict["gmsh:physical"]["tetra"]
    else:
        back = delamesh.read(tmp_path / f"out.{ext}")
        subdomains = back.cell_data["subdomain"][0]
    np.testing.assert_allclose(back.points, m.points, rtol=1e-12)
    assert back.cells_dict["tetra"].tolist() == m.cells_dict["tetra"].tolist()
    np.testing.assert_array_equal(subdomains, m.cell_data["subdomain"][0])


def test_read_a_surface_and_write_it(tmp_path):
    s = delamesh.read(SPHERE)
    assert [c.type for c in s.cells] == ["triangle"] and list(s.cell_data) == ["patch"]
    delamesh.write(tmp_path / "s.stl", s)
    np.testing.assert_array_equal(
        delamesh.read(tmp_path / "s.stl").cells_dict["triangle"].shape,
        s.cells_dict["triangle"].shape,
    )


# --- errors --------------------------------------------------------------------------------------


def test_error_is_a_value_error():
    assert issubclass(delamesh.Error, ValueError)
    assert delamesh.Error.__module__ == "delamesh"


@needs_cli
@pytest.mark.parametrize(
    "path, options",
    [
        (ROOT / "no-such-file.off", {}),
        (BAD / "nan_vertex.off", {}),
        (BAD / "index_out_of_range.off", {}),
        (BAD / "wrong_magic.ply", {}),
        (SPHERE, {"facet_size": -1}),
        (SPHERE, {"cell_radius_edge_ratio": 0.5}),
        (SPHERE, {"time_limit": -2}),
        (SPHERE, {"max_vertices": 10}),
    ],
)
def test_errors_carry_the_message_of_the_command_line(path, options, tmp_path):
    expected = cli_error("mesh", str(path), "-o", str(tmp_path / "x.vtu"), "-q", *flags(options))
    with pytest.raises(delamesh.Error) as e:
        delamesh.mesh(path, **options)
    assert str(e.value) == expected
    assert not (tmp_path / "x.vtu").exists()


@needs_cli
def test_other_functions_carry_the_message_of_the_command_line(tmp_path):
    for path in (ROOT / "missing.off", BAD / "truncated.ply"):
        with pytest.raises(delamesh.Error) as e:
            delamesh.info(path)
        assert str(e.value) == cli_error("info", str(path))
    np.savetxt(tmp_path / "flat.xyz", [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    with pytest.raises(delamesh.Error) as e:
        delamesh.delaunay(np.loadtxt(tmp_path / "flat.xyz"))
    assert str(e.value) == cli_error(
        "delaunay", str(tmp_path / "flat.xyz"), "-o", str(tmp_path / "d.vtu")
    ).replace(str(tmp_path / "flat.xyz"), "points")


def open_box():
    vertices, faces = surface(BOX)
    return vertices, faces[1:]


@pytest.mark.parametrize(
    "call",
    [
        lambda: delamesh.mesh(SPHERE, facet_sise=0.1),  # unknown option
        lambda: delamesh.mesh(SPHERE, facet_size="fine"),
        lambda: delamesh.mesh(SPHERE, max_vertices=-1),
        lambda: delamesh.mesh(SPHERE, no_features="yes"),
        lambda: delamesh.mesh(SPHERE, label_interpolation="cubic"),
        lambda: delamesh.mesh(SPHERE, cell_size_per_label={1: -2.0}),
        lambda: delamesh.mesh(42),
        lambda: delamesh.mesh(SPHERE, progress="tqdm"),
        lambda: delamesh.mesh(SPHERE, voxel_size=0.5),
        lambda: delamesh.mesh(two_balls(), voxel_size=-1),
        lambda: delamesh.mesh(two_balls(), voxel_size=(1, 2)),
        lambda: delamesh.mesh(two_balls(), origin=(np.nan, 0, 0)),
        lambda: delamesh.mesh(two_balls().astype(np.complex64)),
        lambda: delamesh.mesh(np.zeros((0, 4, 4), dtype=np.uint8)),
        lambda: delamesh.mesh(np.zeros((4, 4, 4), dtype=np.uint8)),  # background only
        lambda: delamesh.mesh(meshio.Mesh(np.zeros((4, 3)), [("tetra", np.array([[0, 1, 2, 3]]))])),
        lambda: delamesh.mesh((np.zeros((4, 2)), np.array([[0, 1, 2]]))),
        lambda: delamesh.mesh((np.zeros((4, 3)), np.array([[0, 1, 2.0]]))),
        lambda: delamesh.mesh((np.zeros((4, 3)), np.array([[0, 1, 4]]))),
        lambda: delamesh.mesh((np.zeros((4, 3)), np.array([[0, 1, -1]]))),
        lambda: delamesh.mesh((np.array([[np.nan, 0, 0]] * 4), np.array([[0, 1, 2]]))),
        lambda: delamesh.mesh((np.array([["a", "b", "c"]]), np.array([[0, 0, 0]]))),
        lambda: delamesh.mesh(open_box(), strict=True),
        lambda: delamesh.mesh(BOX, features=str(ROOT / "missing.polylines.txt")),
        lambda: delamesh.delaunay(np.zeros((3, 3))),
        lambda: delamesh.delaunay(np.zeros((5, 2))),
        lambda: delamesh.delaunay([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, np.inf]]),
        lambda: delamesh.read(BAD / "not_xml.vtu"),
        lambda: delamesh.read(ROOT / "missing.vtu"),
        lambda: delamesh.write(ROOT / "out.unknown", delamesh.read(SPHERE)),
        lambda: delamesh.write(ROOT / "missing-dir" / "out.vtu", delamesh.read(SPHERE)),
        lambda: delamesh.write(
            "x.vtu", meshio.Mesh(np.zeros((3, 3)), [("triangle", np.array([[0, 1, 3]]))])
        ),
        lambda: delamesh.write(
            "x.vtu", meshio.Mesh(np.zeros((4, 3)), [("quad", np.array([[0, 1, 2, 3]]))])
        ),
        lambda: delamesh.write(
            "x.vtu",
            meshio.Mesh(
                np.zeros((3, 3)),
                [("triangle", np.array([[0, 1, 2]]))],
                cell_data={"patch": [np.array([-3])]},
            ),
        ),
    ],
)
def test_every_error_class_raises_delamesh_error(call):
    with pytest.raises(delamesh.Error) as e:
        call()
    message = str(e.value)
    assert message and "\n" not in message
    assert not Path("x.vtu").exists()


def test_unknown_option_is_named():
    with pytest.raises(delamesh.Error, match="facet_sise"):
        delamesh.mesh(SPHERE, facet_sise=0.1)


def test_keep_partial_returns_the_mesh_reached_with_a_warning():
    with pytest.warns(UserWarning, match="stopped early"):
        m = delamesh.mesh(SPHERE, cell_size=0.05, max_vertices=300, keep_partial=True)
    assert len(m.cells_dict["tetra"]) > 0 and (tet_volumes(m) > 0).all()


# --- determinism, threads, progress, interrupts --------------------------------------------------


def test_the_same_call_gives_the_same_mesh():
    assert_same_mesh(delamesh.mesh(BOX, **BOX_OPTIONS), delamesh.mesh(BOX, **BOX_OPTIONS))


def test_two_meshes_at_once_in_threads():
    alone = [delamesh.mesh(SPHERE, **SPHERE_OPTIONS), delamesh.mesh(BOX, **BOX_OPTIONS)]
    with ThreadPoolExecutor(2) as pool:
        together = list(
            pool.map(
                lambda a: delamesh.mesh(a[0], **a[1]),
                [(SPHERE, SPHERE_OPTIONS), (BOX, BOX_OPTIONS)],
            )
        )
    for a, b in zip(alone, together):
        assert_same_mesh(a, b)


# Fine enough to run for seconds; the time limit bounds the test should cancellation fail.
LONG = {"cell_size": 0.01, "facet_size": 0.01, "max_vertices": 10**8, "time_limit": 120}


def test_progress_is_called_and_its_exception_stops_meshing():
    seen = []

    def progress(p):
        seen.append(p)
        if len(seen) == 2:
            raise KeyError("enough")

    with pytest.raises(KeyError, match="enough"):
        delamesh.mesh(SPHERE, progress=progress, **LONG)
    assert len(seen) == 2
    assert seen[1]["vertices"] >= seen[0]["vertices"] > 0
    assert set(seen[0]) == {"vertices", "insertions", "pending"}


@pytest.mark.skipif(
    threading.current_thread() is not threading.main_thread(),
    reason="signals go to the main thread",
)
def test_ctrl_c_interrupts_a_long_run():
    # Python's own Ctrl-C handler, as in a terminal: a process started in the background by a
    # non-interactive shell inherits SIGINT ignored, and Python then installs none.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            delamesh.mesh(SPHERE, **LONG)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)


def test_the_readme_example_runs(tmp_path, monkeypatch):
    readme = (ROOT / "README.md").read_text()
    section = readme[readme.index("## From Python") :]
    code = section[section.index("```python\n") + len("```python\n") :]
    code = code[: code.index("```")]
    for folder in ("models", "tests"):
        (tmp_path / folder).symlink_to(ROOT / folder)
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    exec(compile(code, "README.md", "exec"), scope)
    torus = meshio.read(tmp_path / "torus.vtu")
    assert len(scope["labels"]) == len(torus.cells_dict["tetra"]) > 0
    assert (tet_volumes(torus) > 0).all() and scope["tets"].shape[1] == 4


def test_the_gil_is_released_while_meshing():
    # The main thread counts while another meshes; with the GIL held by the mesher it could
    # only count during the progress callbacks, which take microseconds.
    counts = []
    counter = [0]

    class Enough(Exception):
        pass

    def progress(_):
        counts.append(counter[0])
        if len(counts) == 3:
            raise Enough

    worker = ThreadPoolExecutor(1)
    job = worker.submit(delamesh.mesh, SPHERE, progress=progress, **LONG)
    while not job.done():
        counter[0] += 1
    with pytest.raises(Enough):
        job.result()
    worker.shutdown()
    assert counts[2] - counts[1] > 1000, counts


def test_an_option_refining_a_missing_one_raises():
    with pytest.raises(delamesh.Error, match="sizing-field needs sizing"):
        delamesh.mesh(SPHERE, sizing_field="h")
    with pytest.raises(delamesh.Error, match="crease-angle needs subdivision"):
        delamesh.mesh(SPHERE, crease_angle=30)
    with pytest.raises(delamesh.Error, match="unknown subdivision scheme"):
        delamesh.mesh(BOX, subdivision="butterfly")
