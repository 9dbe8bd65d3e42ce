"""Type stubs of the extension module under ``delamesh`` (python/src/lib.rs).

Meshes cross the boundary as flat native-endian buffers: float64 points, int64 vertex indices,
int32 labels. The package's own functions (``delamesh.mesh`` ...) turn them into numpy arrays and
``meshio.Mesh`` objects; call those, not these.
"""

from typing import Any, Callable, Dict, List, Mapping, Optional, Tuple, TypedDict

class Error(ValueError):
    """Bad input, option or file: the message is the command line's."""

class RawMesh(TypedDict):
    """A mesh as buffers: blocks ``tetra`` (4 int64 per cell), ``triangle`` (3), ``line`` (2),
    their labels ``subdomain``, ``patch``, ``curve`` (int32 per cell), per-tet float64 fields."""

    points: bytearray
    tetra: bytearray
    triangle: bytearray
    line: bytearray
    subdomain: bytearray
    patch: bytearray
    curve: bytearray
    fields: List[Tuple[str, bytearray]]
    warnings: List[str]

class MeshResult(RawMesh):
    """A mesher's result: the mesh, and what the command line would print as warnings."""

    stopped: Optional[str]

Progress = Callable[[Dict[str, Any]], Any]

def mesh_file(
    path: str, options: Optional[Mapping[str, Any]] = None, progress: Optional[Progress] = None
) -> MeshResult:
    """Meshes the surface or image in the file ``path`` (keyword options as ``delamesh.mesh``)."""

def mesh_surface(
    vertices: bytes,
    faces: bytes,
    options: Optional[Mapping[str, Any]] = None,
    progress: Optional[Progress] = None,
) -> MeshResult:
    """Meshes the closed surface of ``vertices`` (3 float64 each) and ``faces`` (3 int64 each)."""

def mesh_image(
    dims: Tuple[int, int, int],
    spacing: Tuple[float, float, float],
    origin: Tuple[float, float, float],
    dtype: str,
    voxels: bytes,
    options: Optional[Mapping[str, Any]] = None,
    progress: Optional[Progress] = None,
) -> MeshResult:
    """Meshes the labels of a 3D image: ``dims`` voxels of numpy type ``dtype`` (``u1`` ...
    ``f8``), x fastest, centres at ``origin + index * spacing``."""

def delaunay(points: bytes) -> bytearray:
    """The Delaunay tetrahedra of ``points`` (3 float64 each): 4 int64 indices per tetrahedron."""

def info(path: str) -> str:
    """The JSON object of ``delamesh info --json`` for the file ``path``."""

def read(path: str) -> RawMesh:
    """The mesh in the file ``path``."""

def write(path: str, raw: Mapping[str, bytes], ascii: bool = False) -> None:
    """Writes the mesh of buffers ``raw`` (keys of :class:`RawMesh`, ``bytes`` values)."""

def option_names() -> List[str]:
    """The keyword options of ``delamesh.mesh``."""
