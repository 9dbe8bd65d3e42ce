#!/usr/bin/env python3
"""Real-client check: every delamesh writer's output is opened by the readers people use.

For each small model in tests/data, `delamesh convert` writes every output format; then VTK's own
readers (vtkXMLUnstructuredGridReader, vtkUnstructuredGridReader: the code ParaView uses), meshio and
pymeshlab (MeshLab's code, for the surface formats) read the files back. Counts of vertices and of
cells per type, bounding boxes and label histograms must match what `delamesh info --json` says of
the input. A final self-test feeds the checks a wrong output and requires them to fail, so this
script cannot pass vacuously.

Run from anywhere: python3 tests/clients/check_outputs.py
"""

import json
import os
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

import meshio
import numpy as np
import pymeshlab
import vtk

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"

SURFACE_INPUTS = ["box.off", "icosahedron.obj", "tetrahedron.stl", "torus.ply", "pyramid.glb", "pyramid.gltf"]
VOLUME_INPUTS = ["box.mesh"]
# Meshed by `delamesh mesh` first: their sharp edges become line cells with a `curve` id, which
# every volume format must carry to the clients.
FEATURE_INPUTS = ["features/cube.off", "features/two_boxes.off"]

# (file name suffix, extra convert flags)
VOLUME_OUTPUTS = [
    ("vtu", []),
    ("ascii.vtu", ["--ascii"]),
    ("vtk", []),
    ("ascii.vtk", ["--ascii"]),
    ("mesh", []),
    ("msh", []),
    ("v22.msh", ["--msh22"]),
]
SURFACE_OUTPUTS = [("ply", []), ("obj", []), ("stl", []), ("off", [])]

VTK_TETRA, VTK_TRIANGLE, VTK_LINE = 10, 5, 3


def delamesh_binary():
    """Builds the CLI once and returns the path of the binary cargo made."""
    subprocess.run(["cargo", "build", "--quiet", "--bin", "delamesh"], cwd=ROOT, check=True)
    meta = subprocess.run(
        ["cargo", "metadata", "--format-version", "1", "--no-deps"],
        cwd=ROOT, check=True, capture_output=True, text=True,
    )
    target = Path(json.loads(meta.stdout)["target_directory"])
    return target / "debug" / "delamesh"


def run(binary, *args):
    out = subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"delamesh {' '.join(map(str, args))} failed:\n{out.stderr}")
    return out.stdout


class Expected:
    """What delamesh says of a mesh: the reference every client is compared with."""

    def __init__(self, info):
        vm = info["volume_mesh"] or {}
        self.vertices = info["vertices"]
        self.triangles = info["triangles"]
        self.tets = vm.get("tetrahedra", 0)
        self.edges = vm.get("feature_edges", 0)
        self.bbox = np.array([info["bounding_box"]["min"], info["bounding_box"]["max"]])
        self.subdomains = {s["id"]: s["tetrahedra"] for s in vm.get("subdomains", [])}
        self.patches = {p["id"]: p["triangles"] for p in info["patches"]}
        # Vertices on the boundary triangles (V = χ + E − F): all an STL file can keep.
        topo = info["topology"]
        self.surface_vertices = topo["euler_characteristic"] + topo["edges"] - self.triangles


class Checker:
    def __init__(self):
        self.passed = 0
        self.failures = []

    def check(self, ok, what):
        if ok:
            self.passed += 1
        else:
            self.failures.append(what)

    def bbox(self, got, exp, what, f32=False):
        got = np.asarray(got, dtype=float)
        scale = max(1.0, float(np.abs(exp.bbox).max()))
        tol = 1e-6 * scale if f32 else 1e-12 * scale
        self.check(got.shape == exp.bbox.shape and np.allclose(got, exp.bbox, rtol=0, atol=tol),
                   f"{what}: bounding box {got.tolist()} != {exp.bbox.tolist()}")


def vtk_read(reader, path):
    errors = []
    reader.AddObserver("ErrorEvent", lambda obj, ev: errors.append(ev))
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput(), errors


def check_vtk(c, path, exp, legacy):
    reader = vtk.vtkUnstructuredGridReader() if legacy else vtk.vtkXMLUnstructuredGridReader()
    name = f"{type(reader).__name__}({path.name})"
    grid, errors = vtk_read(reader, path)
    c.check(not errors, f"{name}: reader reported errors")
    c.check(grid.GetNumberOfPoints() == exp.vertices,
            f"{name}: {grid.GetNumberOfPoints()} points, expected {exp.vertices}")
    types = Counter(grid.GetCellType(i) for i in range(grid.GetNumberOfCells()))
    want = Counter({VTK_TETRA: exp.tets, VTK_TRIANGLE: exp.triangles, VTK_LINE: exp.edges})
    c.check(+types == +want, f"{name}: cell types {dict(types)}, expected {dict(+want)}")
    if grid.GetNumberOfPoints():
        b = grid.GetBounds()
        c.bbox([[b[0], b[2], b[4]], [b[1], b[3], b[5]]], exp, name)
    data = grid.GetCellData()
    names = {data.GetArrayName(i) for i in range(data.GetNumberOfArrays())}
    c.check({"subdomain", "patch"} <= names, f"{name}: cell arrays {sorted(names)} lack subdomain/patch")
    if {"subdomain", "patch"} <= names:
        sub, patch = data.GetArray("subdomain"), data.GetArray("patch")
        cells = range(grid.GetNumberOfCells())
        tets = Counter(int(sub.GetValue(i)) for i in cells if grid.GetCellType(i) == VTK_TETRA)
        tris = Counter(int(patch.GetValue(i)) for i in cells if grid.GetCellType(i) == VTK_TRIANGLE)
        c.check(dict(tets) == exp.subdomains, f"{name}: tets per subdomain {dict(tets)} != {exp.subdomains}")
        c.check(dict(tris) == exp.patches, f"{name}: triangles per patch {dict(tris)} != {exp.patches}")


def check_meshio(c, path, exp, f32=False):
    name = f"meshio({path.name})"
    try:
        m = meshio.read(path)
    except Exception as e:  # noqa: BLE001 - any failure to read is the finding
        c.check(False, f"{name}: {type(e).__name__}: {e}")
        return
    c.check(len(m.points) == exp.vertices, f"{name}: {len(m.points)} points, expected {exp.vertices}")
    types = Counter()
    for block in m.cells:
        types[block.type] += len(block.data)
    want = Counter({"tetra": exp.tets, "triangle": exp.triangles, "line": exp.edges})
    c.check(+types == +want, f"{name}: cells {dict(types)}, expected {dict(+want)}")
    if len(m.points):
        pts = np.asarray(m.points, dtype=float)
        c.bbox([pts.min(axis=0), pts.max(axis=0)], exp, name, f32)


def check_meshlab(c, path, exp, f32=False):
    name = f"pymeshlab({path.name})"
    ms = pymeshlab.MeshSet()
    try:
        ms.load_new_mesh(str(path))
    except Exception as e:  # noqa: BLE001
        c.check(False, f"{name}: {e}")
        return
    mesh = ms.current_mesh()
    c.check(mesh.vertex_number() == exp.vertices, f"{name}: {mesh.vertex_number()} vertices, expected {exp.vertices}")
    c.check(mesh.face_number() == exp.triangles, f"{name}: {mesh.face_number()} faces, expected {exp.triangles}")
    b = mesh.bounding_box()
    c.bbox([b.min(), b.max()], exp, name, f32)


def check_output(c, path, exp):
    suffix = path.suffix.lower()
    if suffix == ".vtu":
        check_vtk(c, path, exp, legacy=False)
        check_meshio(c, path, exp)
    elif suffix == ".vtk":
        check_vtk(c, path, exp, legacy=True)
        check_meshio(c, path, exp)
    elif suffix in (".mesh", ".msh"):
        check_meshio(c, path, exp)
    else:
        f32 = suffix == ".stl"
        if f32:
            exp = surface_view(exp)
            exp.vertices = exp.surface_vertices
        check_meshlab(c, path, exp, f32)
        # meshio 5.3 cannot read binary PLY faces with an extra scalar property (our `patch`):
        # it fails inside its own Mesh constructor; VTK's PLY reader checks those files instead.
        if suffix == ".ply":
            check_vtk_ply(c, path, exp)
        else:
            check_meshio(c, path, exp, f32)


def check_vtk_ply(c, path, exp):
    name = f"vtkPLYReader({path.name})"
    poly, errors = vtk_read(vtk.vtkPLYReader(), path)
    c.check(not errors, f"{name}: reader reported errors")
    c.check(poly.GetNumberOfPoints() == exp.vertices, f"{name}: {poly.GetNumberOfPoints()} points")
    c.check(poly.GetNumberOfPolys() == exp.triangles, f"{name}: {poly.GetNumberOfPolys()} polygons")
    b = poly.GetBounds()
    # vtkPLYReader stores points as float32 whatever the file holds.
    c.bbox([[b[0], b[2], b[4]], [b[1], b[3], b[5]]], exp, name, f32=True)


def surface_view(exp):
    """What a surface format holds of a volume mesh: its boundary triangles only."""
    s = Expected.__new__(Expected)
    s.__dict__.update(exp.__dict__)
    s.tets, s.edges, s.subdomains = 0, 0, {}
    return s


def main():
    binary = delamesh_binary()
    c = Checker()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        written = {}
        sources = [DATA / name for name in SURFACE_INPUTS + VOLUME_INPUTS]
        for name in FEATURE_INPUTS:
            meshed = tmp / f"{Path(name).stem}-meshed.mesh"
            run(binary, "mesh", DATA / name, "-o", meshed, "--quiet")
            c.check(Expected(json.loads(run(binary, "info", meshed, "--json"))).edges > 0,
                    f"{name}: meshed without feature edges")
            sources.append(meshed)
        for src in sources:
            name = src.name
            exp = Expected(json.loads(run(binary, "info", src, "--json")))
            outputs = VOLUME_OUTPUTS + SURFACE_OUTPUTS
            for suffix, flags in outputs:
                out = tmp / f"{src.stem}-{src.suffix[1:]}.{suffix}"
                run(binary, "convert", src, out, *flags)
                is_surface_format = out.suffix.lower() in (".ply", ".obj", ".stl", ".off")
                check_output(c, out, surface_view(exp) if is_surface_format else exp)
                written[(name, suffix)] = out
            # A file delamesh wrote is read back by delamesh with the same counts.
            back = Expected(json.loads(run(binary, "info", written[(name, "vtu")], "--json")))
            c.check((back.vertices, back.triangles, back.tets) == (exp.vertices, exp.triangles, exp.tets),
                    f"delamesh info of its own {name} .vtu differs")

        # Self-test: the checks must reject a wrong output (the torus's files against the box's
        # numbers), or they prove nothing.
        box = Expected(json.loads(run(binary, "info", DATA / "box.mesh", "--json")))
        for suffix in ("vtu", "vtk", "msh", "ply", "stl"):
            wrong = Checker()
            exp = surface_view(box) if suffix in ("ply", "stl") else box
            check_output(wrong, written[("torus.ply", suffix)], exp)
            c.check(len(wrong.failures) > 0, f"self-test: a wrong .{suffix} output went undetected")

    for f in c.failures:
        print(f"FAIL {f}")
    print(f"real clients: VTK {vtk.vtkVersion.GetVTKVersion()}, meshio {meshio.__version__}, pymeshlab")
    print(f"clients: {c.passed} passed, {len(c.failures)} failed")
    return 1 if c.failures else 0


if __name__ == "__main__":
    os.environ.setdefault("CARGO_TERM_COLOR", "never")
    sys.exit(main())
