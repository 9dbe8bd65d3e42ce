"""delamesh: quality tetrahedral meshes by Delaunay refinement.

The pipeline of ``delamesh mesh`` from Python, returning ``meshio.Mesh`` objects::

    import delamesh
    mesh = delamesh.mesh("part.stl", facet_size=0.05, cell_size=0.1)
    mesh.write("part.vtu")

Meshing runs without the GIL (other threads keep going; two meshes can run at once), and Ctrl-C
stops it. Bad input, options or files raise :class:`delamesh.Error` (a ``ValueError``) with the
command line's message.
"""

from __future__ import annotations

import json
import math
import os
import warnings
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import meshio
import numpy as np

from . import _delamesh
from ._delamesh import Error

__all__ = ["Error", "OPTIONS", "delaunay", "info", "mesh", "read", "write"]

#: The keyword options of :func:`mesh`: the long options of ``delamesh mesh``, ``-`` → ``_``.
OPTIONS: Tuple[str, ...] = tuple(_delamesh.option_names())

#: A path, a ``meshio.Mesh`` with triangle cells, or a ``(vertices, faces)`` pair of arrays.
Source = Union[str, "os.PathLike[str]", meshio.Mesh, Tuple[Any, Any]]

#: Cell types by block, with the label array of each (the order the VTK writers use).
_BLOCKS = (("tetra", "subdomain", 4), ("triangle", "patch", 3), ("line", "curve", 2))


def mesh(
    source: Source,
    *,
    progress: Optional[Callable[[Dict[str, Any]], Any]] = None,
    voxel_size: Optional[Union[float, Tuple[float, float, float]]] = None,
    origin: Optional[Tuple[float, float, float]] = None,
    **options: Any,
) -> meshio.Mesh:
    """A quality tetrahedral mesh of the volume bounded by a closed surface, or of a 3D image.

    ``source`` is a file path (any surface format the command line reads, or a segmented image:
    .inr .nii .vti .nrrd .nhdr, optionally .gz), a ``meshio.Mesh`` (its triangle cells), a
    ``(vertices, faces)`` pair: an ``(n, 3)`` float array and an ``(m, 3)`` integer array of
    vertex indices, triangles oriented either way, or a 3D array of voxel labels indexed
    ``[x, y, z]`` (one subdomain per label, ``background`` outside), its voxel centres at
    ``origin + index * voxel_size`` (defaults: 0 and 1; ``voxel_size`` a number or three).

    ``options`` are the long options of ``delamesh mesh`` with underscores: ``edge_size``,
    ``facet_size``, ``facet_distance``, ``facet_angle``, ``cell_size``,
    ``cell_radius_edge_ratio``, ``max_vertices``, ``time_limit``, ``feature_angle``,
    ``no_features=True``, ``strict=True``... (all of them: :data:`OPTIONS`). An unknown keyword or
    a bad value raises :class:`Error` naming it.

    ``sizing`` (the size of facets and cells, and of edges along sharp features) is a path (a
    background mesh .vtu .vtk .msh .mesh with a point field, a size image, or ``x y z h``
    lines), a callable ``f(x, y, z) -> float``, a ``(points, tets, values)`` triple of arrays (a
    background tet mesh: ``(n, 3)`` floats, ``(m, 4)`` vertex indices, ``n`` sizes, linear in
    each tet, the nearest node's value outside) or a ``(points, values)`` pair (sizes at
    scattered points). A value that is not a positive number raises :class:`Error` with the
    point; an exception the callable raises stops meshing and is raised here.

    ``progress``, if given, is called about ten times a second during refinement with a dict
    ``{"vertices": int, "insertions": int, "pending": {level: queued}}``; an exception it raises
    stops meshing and is raised here. Ctrl-C (any pending signal whose handler raises) stops
    meshing the same way: it is noticed in every phase; refinement and optimisation stop at
    once, the other phases finish first.

    The result has blocks ``tetra``, ``triangle`` (the boundary) and ``line`` (sharp feature
    edges, if any) and the cell data of the .vtu files: ``subdomain``, ``patch``, ``curve`` (int32,
    -1 on the blocks a label does not apply to) and per-tet quality fields (NaN elsewhere).
    Tetrahedra are positively oriented (det[b-a, c-a, d-a] > 0). What the command line prints as
    warnings (repairs of the input, a run stopped early with ``keep_partial=True``) is issued with
    :func:`warnings.warn`.
    """
    if progress is not None and not callable(progress):
        raise Error(f"progress: expected a callable, got {type(progress).__name__}")
    raised = _sizing(options)
    try:
        raw = _dispatch(source, voxel_size, origin, options, progress)
    except Error as e:
        if raised:
            raise raised[0] from e
        raise
    for note in raw["warnings"]:
        warnings.warn(note, stacklevel=2)
    if raw["stopped"] is not None:
        warnings.warn(raw["stopped"], stacklevel=2)
    return _meshio(raw)


def _dispatch(
    source: Source, voxel_size: Any, origin: Any, options: Dict[str, Any], progress: Any
) -> Dict[str, Any]:
    """The extension's call for ``source``: its flat buffers."""
    image = isinstance(source, np.ndarray) and source.ndim == 3
    if not image and (voxel_size is not None or origin is not None):
        raise Error("voxel_size and origin are those of an image: give a 3D array of labels")
    if isinstance(source, (str, os.PathLike)):
        raw = _delamesh.mesh_file(os.fspath(source), options, progress)
    elif isinstance(source, meshio.Mesh):
        faces = [c.data for c in source.cells if c.type == "triangle"]
        if not faces:
            raise Error("the meshio.Mesh has no triangle cells: give a closed triangle surface")
        vertices = _floats(source.points, "vertices")
        raw = _delamesh.mesh_surface(
            vertices, _indices(np.concatenate(faces), 3, "faces"), options, progress
        )
    elif isinstance(source, np.ndarray) and source.ndim == 3:
        raw = _mesh_image(source, voxel_size, origin, options, progress)
    elif isinstance(source, tuple) and len(source) == 2:
        vertices = _floats(source[0], "vertices")
        raw = _delamesh.mesh_surface(vertices, _indices(source[1], 3, "faces"), options, progress)
    else:
        raise Error(
            "mesh: the source must be a path, a meshio.Mesh or a (vertices, faces) pair, "
            f"got {type(source).__name__}"
        )
    return raw


def _sizing(options: Dict[str, Any]) -> List[BaseException]:
    """Puts ``sizing=`` in the form the extension takes: a path as it is, a callable wrapped so
    that what it raises (or a result that is not a number) is kept and gives NaN, which stops
    meshing with the point; arrays as tagged tuples of bytes. Returns the list where the
    callable's first exception goes, to be raised instead of the extension's error."""
    value = options.get("sizing")
    raised: List[BaseException] = []
    if value is None or isinstance(value, (str, os.PathLike)):
        return raised
    if callable(value):
        f = value

        def size(x: float, y: float, z: float) -> float:
            try:
                result = f(x, y, z)
            except BaseException as e:  # kept, and raised once meshing stops
                raised[:] = raised or [e]
                return math.nan
            try:
                return float(result)
            except (TypeError, ValueError):
                bad = Error(f"sizing: the callable gave {result!r} at ({x}, {y}, {z}), not a number")
                raised[:] = raised or [bad]
                return math.nan

        options["sizing"] = size
    elif isinstance(value, tuple) and len(value) == 3:
        points, tets, sizes = value
        options["sizing"] = (
            "background",
            _floats(points, "sizing points"),
            _indices(tets, 4, "sizing tets"),
            _sizes(sizes, points),
        )
    elif isinstance(value, tuple) and len(value) == 2:
        points, sizes = value
        options["sizing"] = ("points", _floats(points, "sizing points"), _sizes(sizes, points))
    else:
        raise Error(
            "sizing: expected a path, a callable f(x, y, z), (points, tets, values) or "
            f"(points, values) arrays, got {type(value).__name__}"
        )
    return raised


def _sizes(values: Any, points: Any) -> bytes:
    """One float64 size per point, as native-endian bytes (NaN kept: the facade names it)."""
    try:
        x = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise Error(f"sizing values: not an array of numbers ({e})") from None
    n = len(np.asarray(points))
    if x.shape != (n,):
        raise Error(f"sizing values: expected one per point ({n},), got shape {x.shape}")
    return np.ascontiguousarray(x).tobytes()


def delaunay(points: Any) -> np.ndarray:
    """The Delaunay tetrahedralisation of an ``(n, 3)`` array of points.

    Returns an ``(N, 4)`` int64 array of indices into ``points`` (a repeated point is represented
    by its first occurrence), each tetrahedron positively oriented (det[b-a, c-a, d-a] > 0).
    Fewer than four distinct points, or all of them in a plane, raise :class:`Error`.
    """
    cells = _delamesh.delaunay(_floats(points, "points"))
    return np.frombuffer(cells, dtype=np.int64).reshape(-1, 4)


def info(path: Union[str, "os.PathLike[str]"]) -> Dict[str, Any]:
    """What ``delamesh info --json`` prints about the mesh file ``path``, as a dict: counts,
    bounding box, patches, topology of its surface, labels of a volume mesh, sharp features and
    what ``mesh`` would repair."""
    result: Dict[str, Any] = json.loads(_delamesh.info(os.fspath(path)))
    return result


def read(path: Union[str, "os.PathLike[str]"]) -> meshio.Mesh:
    """The mesh in the file ``path``, any format the command line reads (STL, OFF, OBJ, PLY, glTF,
    VTK, VTU, VTP, MEDIT, Gmsh...): a surface (``triangle`` block with ``patch``) or a volume
    mesh (blocks and cell data as :func:`mesh` returns them)."""
    raw = _delamesh.read(os.fspath(path))
    for note in raw["warnings"]:
        warnings.warn(f"{os.fspath(path)}: {note}", stacklevel=2)
    return _meshio(raw)


def write(path: Union[str, "os.PathLike[str]"], mesh: meshio.Mesh, *, ascii: bool = False) -> None:
    """Writes ``mesh`` to ``path`` the way the command line writes (atomically), the format
    following the extension: .vtu .vtk .mesh .msh for a volume mesh, or a surface format (.stl
    .off .obj .ply) for its triangles. Cells of type ``tetra``, ``triangle`` and ``line`` are
    written with their ``subdomain``, ``patch`` and ``curve`` cell data (0 where missing)."""
    raw: Dict[str, bytes] = {"points": _floats(mesh.points, "points")}
    for kind, label, width in _BLOCKS:
        cells, labels = [], []
        for i, block in enumerate(mesh.cells):
            if block.type != kind:
                continue
            cells.append(np.asarray(block.data).reshape(-1, width))
            values = mesh.cell_data.get(label)
            if values is not None:
                labels.append(np.asarray(values[i]).reshape(-1))
        if cells:
            raw[kind] = _indices(np.concatenate(cells), width, kind)
        if labels:
            if len(labels) != len(cells):
                raise Error(f"{label}: given for some {kind} blocks and not for others")
            raw[label] = _ints(np.concatenate(labels), label)
    other = sorted({c.type for c in mesh.cells} - {k for k, _, _ in _BLOCKS})
    if other:
        raise Error(f"cannot write cells of type {', '.join(other)} (only tetra, triangle, line)")
    _delamesh.write(os.fspath(path), raw, ascii)


def _mesh_image(
    labels: np.ndarray, voxel_size: Any, origin: Any, options: Dict[str, Any], progress: Any
) -> Dict[str, Any]:
    """Meshes a 3D array of labels indexed ``[x, y, z]``."""
    if labels.dtype.kind == "b":
        labels = labels.astype(np.uint8)
    code = f"{labels.dtype.kind}{labels.dtype.itemsize}"
    spacing = _triple(1.0 if voxel_size is None else voxel_size, "voxel_size")
    start = _triple(0.0 if origin is None else origin, "origin")
    native = labels.astype(labels.dtype.newbyteorder("="), copy=False)
    voxels = native.ravel(order="F").tobytes()  # x fastest
    dims = tuple(int(n) for n in labels.shape)
    return _delamesh.mesh_image(dims, spacing, start, code, voxels, options, progress)


def _triple(v: Any, what: str) -> Tuple[float, float, float]:
    """A number or three, as three floats."""
    try:
        x = np.broadcast_to(np.asarray(v, dtype=np.float64), (3,))
    except (TypeError, ValueError):
        raise Error(f"{what}: expected a number or three, got {v!r}") from None
    return (float(x[0]), float(x[1]), float(x[2]))


def _floats(a: Any, what: str) -> bytes:
    """An ``(n, 3)`` float64 array as native-endian bytes."""
    try:
        x = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise Error(f"{what}: not an array of numbers ({e})") from None
    if x.ndim != 2 or x.shape[1] != 3:
        raise Error(f"{what}: expected an (n, 3) array, got shape {x.shape}")
    return np.ascontiguousarray(x).tobytes()


def _indices(a: Any, width: int, what: str) -> bytes:
    """An ``(m, width)`` integer array as native-endian int64 bytes."""
    x = np.asarray(a)
    if x.dtype.kind not in "iu":
        raise Error(f"{what}: expected integer vertex indices, got dtype {x.dtype}")
    if x.ndim != 2 or x.shape[1] != width:
        raise Error(f"{what}: expected an (m, {width}) array, got shape {x.shape}")
    if x.dtype.kind == "u" and x.size and x.max() > np.iinfo(np.int64).max:
        raise Error(f"{what}: index {x.max()} is too large")
    return np.ascontiguousarray(x, dtype=np.int64).tobytes()


def _ints(a: Any, what: str) -> bytes:
    """Labels as native-endian int32 bytes."""
    x = np.asarray(a)
    if x.dtype.kind not in "iu":
        raise Error(f"{what}: expected integer labels, got dtype {x.dtype}")
    if x.size and (x.min() < 0 or x.max() > np.iinfo(np.int32).max):
        raise Error(f"{what}: labels must be in 0..{np.iinfo(np.int32).max}")
    return np.ascontiguousarray(x, dtype=np.int32).tobytes()


def _meshio(raw: Dict[str, Any]) -> meshio.Mesh:
    """The ``meshio.Mesh`` of the extension's flat buffers, laid out as the .vtu writer lays out
    its cells: one block per cell type, each label array over every block (-1 where it does not
    apply), per-tet float fields NaN on the other blocks."""
    points = np.frombuffer(raw["points"], dtype=np.float64).reshape(-1, 3)
    blocks = []
    for kind, label, width in _BLOCKS:
        cells = np.frombuffer(raw[kind], dtype=np.int64).reshape(-1, width)
        if len(cells):
            labels = np.frombuffer(raw[label], dtype=np.int32)
            blocks.append((kind, label, cells, labels))
    cells = [(kind, c) for kind, _, c, _ in blocks]
    cell_data: Dict[str, list] = {}
    for _, label, _ in _BLOCKS:
        if any(lab == label for _, lab, _, _ in blocks):
            cell_data[label] = [
                values if lab == label else np.full(len(c), -1, dtype=np.int32)
                for _, lab, c, values in blocks
            ]
    for name, values in raw["fields"]:
        per_tet = np.frombuffer(values, dtype=np.float64)
        cell_data["_".join(name.split())] = [
            per_tet if kind == "tetra" else np.full(len(c), np.nan) for kind, _, c, _ in blocks
        ]
    return meshio.Mesh(points, cells, cell_data=cell_data)
