"""prism.Mesh and prism.bezier_patch against `prism mesh` and `prism bezier`."""

import numpy as np
import pytest

import prism
from conftest import course_file, run


def same_mesh(a: "prism.Mesh", b: "prism.Mesh"):
    assert np.array_equal(a.vertices, b.vertices)
    assert np.array_equal(np.asarray(a.faces), np.asarray(b.faces))


@pytest.mark.parametrize("weights", ["warren", "loop"])
def test_subdivide_equals_the_command(tmp_path, cli, weights):
    """Oracle: `prism mesh subdivide -n 2` writes the vertices and faces of .subdivide(2)."""
    cow = course_file("cow.dae")
    out = tmp_path / "cli.obj"
    run(cli, "mesh", "subdivide", cow, "-o", out, "-n", "2", "--weights", weights)
    mine = prism.Mesh.read(cow).subdivide(2, weights=weights)
    same_mesh(mine, prism.Mesh.read(out))
    written = tmp_path / "py.obj"
    mine.write(written)
    assert written.read_bytes() == out.read_bytes()


@pytest.mark.parametrize("op", ["flip", "split", "collapse"])
def test_edits_equal_the_command(tmp_path, cli, op):
    """Oracle: `prism mesh OP --edge E` writes the same OBJ as .OP(E) then .write."""
    cow = course_file("cow.dae")
    out = tmp_path / "cli.obj"
    run(cli, "mesh", op, cow, "-o", out, "--edge", "120")
    mesh = prism.Mesh.read(cow)
    getattr(mesh, op)(120)
    written = tmp_path / "py.obj"
    mesh.write(written)
    assert written.read_bytes() == out.read_bytes()


def test_edges_are_the_commands_edge_list(cli):
    """Oracle: `prism mesh info --edges` lists edge i as the vertices of .edges[i] (from 1)."""
    cow = course_file("cow.dae")
    listed = run(cli, "mesh", "info", cow, "--edges", "--limit", "50").stdout
    edges = prism.Mesh.read(cow).edges
    for i in range(50):
        a, b = edges[i] + 1
        assert f"edge {i}: vertices {a},{b}" in listed


def test_edge_by_vertices_and_topology_errors():
    """An edge named by its vertices is the same edge; a refused edit raises TopologyError."""
    mesh = prism.Mesh.read(course_file("cow.dae"))
    a, b = mesh.edges[7]
    other = prism.Mesh.read(course_file("cow.dae"))
    mesh.flip(7)
    other.flip((int(a), int(b)))
    assert np.array_equal(np.asarray(mesh.faces), np.asarray(other.faces))
    with pytest.raises(prism.TopologyError):
        mesh.flip(10**6)


def test_normals_equal_the_command(tmp_path, cli):
    """Oracle: `prism mesh normals` writes the area-weighted normals .normals() returns."""
    teapot = course_file("teapot.dae")
    out = tmp_path / "cli.obj"
    run(cli, "mesh", "normals", teapot, "-o", out)
    vn = np.array(
        [[float(x) for x in line.split()[1:4]] for line in out.read_text().splitlines() if line.startswith("vn ")]
    )
    assert np.array_equal(prism.Mesh.read(teapot).normals(), vn)


def test_bezier_patch_equals_the_command(tmp_path, cli):
    """Oracle: `prism bezier --resolution 8` writes the mesh bezier_patch returns."""
    bez = course_file("teapot.bez")
    out = tmp_path / "cli.obj"
    run(cli, "bezier", bez, "-o", out, "--resolution", "8")
    mine = prism.bezier_patch(bez, resolution=8)
    written = tmp_path / "py.obj"
    mine.write(written)
    assert written.read_bytes() == out.read_bytes()


def test_mesh_from_arrays_round_trips(tmp_path):
    """Property: a mesh made from arrays reads back as itself, in every format; a
    tetrahedron's subdivision keeps Euler's V - E + F = 2."""
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    f = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    mesh = prism.Mesh(v, f)
    for ext in ("obj", "ply", "dae"):
        mesh.write(tmp_path / f"t.{ext}")
        back = prism.Mesh.read(tmp_path / f"t.{ext}")
        assert np.allclose(back.vertices, v) and np.array_equal(back.faces, f)
    s = mesh.subdivide(3)
    assert s.vertex_count - len(s.edges) + s.face_count == 2
    quads = prism.Mesh(v, [[0, 1, 2], [0, 1, 2, 3]])
    assert quads.faces == [[0, 1, 2], [0, 1, 2, 3]]
    with pytest.raises(prism.ArgumentError):
        prism.Mesh(v, [[0, 1, 9]])
