"""Sizing fields from Python: ``sizing=`` a callable, background-mesh arrays, sized points or a
Gmsh file give meshes that follow the field; bad values and the callable's exceptions raise."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

import delamesh

ROOT = Path(__file__).resolve().parents[2]
SPHERE = ROOT / "models" / "sphere.off"  # the unit sphere
H_EXPR = "0.08 + 0.15 * (x + 1)"
NO_FEATURES = {"no_features": True}


def h(x: float, y: float, z: float) -> float:
    return 0.08 + 0.15 * (x + 1)


def kuhn_grid(n: int, half: float) -> tuple[np.ndarray, np.ndarray]:
    """The nodes and tets of ``n``³ cubes over [-half, half]³, six tets each."""
    t = np.linspace(-half, half, n + 1)
    z, y, x = np.meshgrid(t, t, t, indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), z.ravel()])

    def node(i, j, k):
        return i + (n + 1) * (j + (n + 1) * k)

    tets = []
    for i, j, k in itertools.product(range(n), repeat=3):
        c = [node(i + (b & 1), j + ((b >> 1) & 1), k + (b >> 2)) for b in range(8)]
        for p, q in ((1, 3), (1, 5), (2, 3), (2, 6), (4, 5), (4, 6)):
            tets.append([c[0], c[p], c[q], c[7]])
    return points, np.array(tets, dtype=np.int64)


def circumcentres(m) -> tuple[np.ndarray, np.ndarray]:
    """Each tet's circumcentre and circumradius."""
    p = m.points[m.cells_dict["tetra"]]
    a = p[:, 0]
    d = p[:, 1:] - a[:, None, :]
    rhs = 0.5 * np.einsum("tij,tij->ti", d, d)
    centre = a + np.linalg.solve(d, rhs[..., None])[..., 0]
    return centre, np.linalg.norm(centre - a, axis=1)


def assert_follows(m, size=h) -> None:
    centre, radius = circumcentres(m)
    bound = np.array([size(*c) for c in centre])
    worst = np.max(radius / bound)
    # Refinement bounds the circumradius by the field; the optimisation after it (on by default,
    # as on the command line) moves vertices by a little and reads the size at centroids.
    assert worst <= 1.05, f"a cell's circumradius is {worst} × the field"
    p = m.points[m.cells_dict["tetra"]]
    edges = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    ratios = [
        np.linalg.norm(p[:, i] - p[:, j], axis=1)
        / np.array([size(*c) for c in 0.5 * (p[:, i] + p[:, j])])
        for i, j in edges
    ]
    median = float(np.median(np.concatenate(ratios)))
    assert 0.5 <= median <= 2.0, f"median edge / h = {median}"


def vertices(**options) -> int:
    return len(delamesh.mesh(SPHERE, **NO_FEATURES, **options).points)


def test_a_callable_gives_the_mesh_of_the_same_expression():
    m = delamesh.mesh(SPHERE, sizing=h, **NO_FEATURES)
    assert_follows(m)
    expression = vertices(sizing_expr=H_EXPR)
    assert abs(len(m.points) / expression - 1) < 0.01, (len(m.points), expression)
    left = np.count_nonzero(m.points[:, 0] < 0)
    assert left > 1.25 * (len(m.points) - left), "finer where the field is small"


def test_background_arrays_and_sized_points_follow_the_field():
    points, tets = kuhn_grid(6, 1.2)
    values = np.array([h(*p) for p in points])
    expression = vertices(sizing_expr=H_EXPR)
    m = delamesh.mesh(SPHERE, sizing=(points, tets, values), **NO_FEATURES)
    assert_follows(m)
    assert abs(len(m.points) / expression - 1) < 0.03, (len(m.points), expression)
    cloud = vertices(sizing=(points, values))
    assert abs(cloud / expression - 1) < 0.1, (cloud, expression)


def test_a_gmsh_background_mesh_in_every_format_gives_the_same_mesh(tmp_path):
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.occ.addBox(-1.2, -1.2, -1.2, 2.4, 2.4, 2.4)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.4)
        gmsh.model.mesh.generate(3)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        view = gmsh.view.add("h")
        xyz = np.reshape(coords, (-1, 3))
        gmsh.view.addModelData(view, 0, "", "NodeData", tags, [[h(*p)] for p in xyz])
        paths = []
        for version, binary in itertools.product((2.2, 4.1), (0, 1)):
            path = tmp_path / f"bg-{version}-{binary}.msh"
            gmsh.option.setNumber("Mesh.MshFileVersion", version)
            gmsh.option.setNumber("Mesh.Binary", binary)
            gmsh.write(str(path))
            gmsh.view.write(view, str(path), append=True)
            paths.append(path)
    finally:
        gmsh.finalize()
    counts = [vertices(sizing=p) for p in paths]
    # ASCII files round the values: within a few vertices of the binary ones.
    assert max(counts) / min(counts) - 1 < 0.01, counts
    expression = vertices(sizing_expr=H_EXPR)
    assert all(abs(n / expression - 1) < 0.03 for n in counts), (counts, expression)


@pytest.mark.parametrize(
    "sizing, expected",
    [
        (lambda x, y, z: x - 0.5, "not a positive size"),
        (lambda x, y, z: "small", "not a number"),
        (42, "expected a path, a callable"),
    ],
)
def test_bad_callables_and_values_raise_delamesh_error(sizing, expected):
    with pytest.raises(delamesh.Error, match=expected):
        delamesh.mesh(SPHERE, sizing=sizing, **NO_FEATURES)


def test_the_callables_exception_is_raised():
    def broken(x, y, z):
        raise ZeroDivisionError("no size here")

    with pytest.raises(ZeroDivisionError, match="no size here"):
        delamesh.mesh(SPHERE, sizing=broken, **NO_FEATURES)


def test_bad_arrays_are_refused_naming_the_node():
    points, tets = kuhn_grid(2, 1.2)
    values = np.full(len(points), 0.4)
    for bad, expected in [(-1.0, "node 3 .* holds -1"), (np.nan, "node 3 .* holds NaN")]:
        v = values.copy()
        v[3] = bad
        with pytest.raises(delamesh.Error, match=expected):
            delamesh.mesh(SPHERE, sizing=(points, tets, v))
    with pytest.raises(delamesh.Error, match="one per point"):
        delamesh.mesh(SPHERE, sizing=(points, tets, values[:-1]))
    with pytest.raises(delamesh.Error, match="not a vertex"):
        delamesh.mesh(SPHERE, sizing=(points, tets + len(points), values))
    small, small_tets = kuhn_grid(2, 0.5)
    with pytest.raises(delamesh.Error, match="does not cover"):
        delamesh.mesh(SPHERE, sizing=(small, small_tets, np.full(len(small), 0.4)))
