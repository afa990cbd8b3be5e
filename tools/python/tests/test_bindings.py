"""The bindings against answers they did not produce: the C++ tool's reports for the same job,
finite differences, round trips, and the shapes, dtypes and errors of the interface."""

import inspect
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import elastic
from conftest import MESHES, PLANE_CAP, tool_report


def test_every_binding_has_a_docstring():
    for name in elastic.__all__:
        item = getattr(elastic, name)
        assert item.__doc__ and item.__doc__.strip(), name
        if inspect.isclass(item) and not issubclass(item, BaseException):
            for attr, member in vars(item).items():
                if not attr.startswith("_") and (callable(member) or isinstance(member, property)):
                    assert member.__doc__ and member.__doc__.strip(), f"{name}.{attr}"


def test_mesh_arrays_have_the_documented_shapes_and_view_without_copy():
    mesh = elastic.load_mesh(str(MESHES / "grid.off"))
    v = mesh.vertices
    assert v.shape == (mesh.num_vertices, 3) and v.dtype == np.float64
    assert not v.flags.owndata and not v.flags.writeable  # a view of the C++ positions
    f = mesh.faces
    assert f.dtype == np.int32 and f.shape[0] == mesh.num_faces and f.shape[1] in (3, 4)
    assert f.min() >= 0 and f.max() < mesh.num_vertices
    assert np.array_equal(mesh.face_vertices, f.ravel())


def test_mesh_round_trip_through_a_file(tmp_path):
    vertices = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.5]], dtype=np.float64)
    faces = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)
    path = tmp_path / "two.obj"
    elastic.save_mesh(str(path), elastic.Mesh(vertices, faces))
    back = elastic.load_mesh(str(path))
    assert np.allclose(back.vertices, vertices, atol=1e-12)
    assert np.array_equal(back.faces, faces)


def test_shape_and_dtype_errors_name_the_argument(cap):
    with pytest.raises(ValueError, match="points"):
        cap.closest(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="points"):
        cap.closest(np.array([["a", "b", "c"]]))
    with pytest.raises(ValueError, match="uv"):
        cap.evaluate(np.zeros(3, dtype=np.int32), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="face"):
        cap.evaluate(np.array([cap.num_faces], dtype=np.int32), np.zeros((1, 2)))
    with pytest.raises(ValueError, match="faces"):
        elastic.Mesh(np.zeros((3, 3)), np.array([[0, 1, 7]]))


def test_library_errors_are_typed_and_name_the_input(tmp_path, cap):
    missing = str(tmp_path / "missing.obj")
    with pytest.raises(elastic.IoError, match="missing.obj") as e:
        elastic.load_mesh(missing)
    assert isinstance(e.value, OSError) and isinstance(e.value, elastic.Error)
    bad = tmp_path / "bad.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n")
    with pytest.raises(elastic.InvalidInputError, match="bad.off") as e:
        elastic.Surface(str(bad))
    assert isinstance(e.value, ValueError)
    with pytest.raises(elastic.InvalidInputError, match="disk"):
        cap.region("disk:0,0")


def test_derivatives_match_finite_differences(cap):
    rng = np.random.default_rng(7)
    n = 64
    face = rng.integers(0, cap.num_faces, n).astype(np.int32)
    uv = rng.uniform(0.2, 0.3, (n, 2))  # inside the triangle u + v <= 1 (Loop) and the quad
    h = 1e-6
    at = cap.evaluate(face, uv)
    du_plus = cap.evaluate(face, uv + [h, 0])["position"]
    du_minus = cap.evaluate(face, uv - [h, 0])["position"]
    dv_plus = cap.evaluate(face, uv + [0, h])["position"]
    dv_minus = cap.evaluate(face, uv - [0, h])["position"]
    scale = np.abs(at["du"]).max()
    assert np.allclose((du_plus - du_minus) / (2 * h), at["du"], atol=1e-6 * scale)
    assert np.allclose((dv_plus - dv_minus) / (2 * h), at["dv"], atol=1e-6 * scale)
    normal = np.cross(at["du"], at["dv"])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    assert np.allclose(normal, at["normal"], atol=1e-12)


def test_closest_points_come_back_along_the_normal(cap):
    rng = np.random.default_rng(3)
    n = 200
    face = rng.integers(0, cap.num_faces, n).astype(np.int32)
    uv = rng.uniform(0.1, 0.4, (n, 2))
    on = cap.evaluate(face, uv)
    lifted = on["position"] + 1e-3 * on["normal"]
    found = cap.closest(lifted)
    assert found["face"].dtype == np.int32 and found["uv"].shape == (n, 2)
    assert np.allclose(found["position"], on["position"], atol=1e-7)
    assert np.allclose(found["distance"], 1e-3, atol=1e-7)


def test_plane_curvature_is_zero(plane):
    face = np.arange(min(plane.num_faces, 50), dtype=np.int32)
    c = plane.curvature(face, np.full((face.size, 2), 0.25))
    assert np.abs(c["k1"]).max() < 1e-9 and np.abs(c["k2"]).max() < 1e-9


def test_region_from_a_polyline_equals_the_points_file(plane, tmp_path):
    square = np.array([[0.2, 0.2, 0], [0.8, 0.2, 0], [0.8, 0.8, 0], [0.2, 0.8, 0]], dtype=float)
    from_array = plane.region(square)
    points = tmp_path / "square.txt"
    points.write_text("".join(f"{x} {y} {z}\n" for x, y, z in square))
    from_file = plane.region(f"points:{points}")
    assert from_array.area == pytest.approx(from_file.area, rel=1e-12)
    # The polygon's area is 0.36; its sides are straight to 4e-4 on this coarse plane (docs/regions.md).
    assert from_array.area == pytest.approx(0.36, rel=1e-3)
    assert from_array.triangles.dtype == np.int32 and from_array.boundary.size >= 4


def test_map_matches_the_tools_report_for_the_same_job(plane_cap, tmp_path):
    report = tool_report("map", PLANE_CAP, tmp_path)
    m = plane_cap
    assert m.num_particles == report["particles"]
    assert m.iterations == report["iterations"]
    assert m.converged == report["converged"] and m.reason == report["reason"]
    assert m.folds == report["folds"] == 0 and m.ok
    assert m.sigma_min == pytest.approx(report["sigma_min"], rel=1e-12)
    assert m.energy["length"] == pytest.approx(report["energy"]["length"], rel=1e-12)
    assert m.rest_scale == pytest.approx(report["rest_scale"]["factor"], rel=1e-12)
    assert m.target_positions.shape == (m.num_particles, 3)
    assert m.triangles.dtype == np.int32 and m.triangles.max() < m.num_particles


def test_metrics_and_baseline_match_the_tools_compare(plane_cap, tmp_path):
    report = tool_report("compare", PLANE_CAP, tmp_path, "--baselines", "lscm")
    methods = report["methods"]
    ours = plane_cap.metrics()
    theirs = methods["elastic"]
    for key in ("length_energy", "symmetric_dirichlet", "angle_error_mean_deg", "stretch_l2"):
        assert ours[key] == pytest.approx(theirs[key], rel=1e-9), key
    lscm = plane_cap.baseline("lscm")
    assert lscm["positions"].shape == (plane_cap.num_particles, 3)
    assert lscm["metrics"]["symmetric_dirichlet"] == pytest.approx(
        methods["lscm"]["symmetric_dirichlet"], rel=1e-9
    )


def plane_cap_source_point(points):
    return elastic.Surface(str(MESHES / "grid.off")).closest(points)


def test_forward_and_inverse_round_trip(plane_cap):
    source = plane_cap.source_points
    forward = plane_cap.forward(source["face"], source["uv"])
    assert forward["inside"].dtype == np.bool_ and forward["inside"].all()
    assert np.allclose(forward["position"], plane_cap.target_positions, atol=1e-9)
    back = plane_cap.inverse(forward["face"], forward["uv"])
    assert back["inside"].all()
    # Interior particles come back exactly; boundary ones to within the boundary curve's chords
    # (the target curve between two particles lies off the grid's boundary edge).
    interior = np.setdiff1d(np.arange(plane_cap.num_particles), plane_cap.boundary)
    assert np.allclose(back["position"][interior], plane_cap.source_positions[interior], atol=1e-9)
    assert np.allclose(back["position"], plane_cap.source_positions, atol=1e-3)
    # A point of the plane outside the disk is not mapped.
    far = plane_cap.source_positions[:1] * 0 + [0.03, 0.03, 0.0]
    where = plane_cap_source_point(far)
    corner = plane_cap.forward(where["face"], where["uv"])
    assert not corner["inside"][0] and np.isnan(corner["position"]).all()


def test_progress_is_called_and_can_stop_the_map(plane, cap):
    stages = []

    def progress(stage, iteration, total, energy, gradient):
        stages.append(stage)
        return stage != "relax" or iteration < 3

    with pytest.raises(elastic.Error, match="cancelled during"):
        elastic.map_regions(plane.region("disk:0.5,0.5,0,0.45"), cap.region("boundary"),
                            particles=800, progress=progress)
    assert "sample" in stages and "relax" in stages


def test_an_exception_in_the_callback_is_raised(plane, cap):
    def progress(*_):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        elastic.map_regions(plane.region("disk:0.5,0.5,0,0.45"), cap.region("boundary"),
                            particles=800, progress=progress)


def test_ctrl_c_stops_a_long_map(plane, cap):
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            elastic.map_regions(plane.region("disk:0.5,0.5,0,0.45"), cap.region("boundary"),
                                particles=200000)
    finally:
        timer.cancel()


def test_paste_writes_the_painted_files_together(tmp_path, cap):
    source, region = elastic.image_source(str(MESHES / "pmp_logo_512.png"), shape="ellipse")
    m = elastic.map_regions(region, cap.region("boundary"), particles=800)
    assert m.ok
    out = tmp_path / "pasted"
    files = m.paste(str(out))
    names = {os.path.basename(f) for f in files}
    assert "painted.obj" in names and all(os.path.exists(f) for f in files)
    painted = elastic.load_mesh(str(out / "painted.obj"))
    assert painted.num_faces > 0
    assert not [p for p in os.listdir(tmp_path) if p != "pasted"]  # no staging left behind


def test_particle_count_out_of_range(plane, cap):
    with pytest.raises(ValueError, match="particles"):
        elastic.map_regions(plane.region("boundary"), cap.region("boundary"), particles=3)
    with pytest.raises(ValueError, match="curvature_radius"):
        elastic.map_regions(plane.region("boundary"), cap.region("boundary"), curvature_radius=-1)
    with pytest.raises(ValueError, match="distortion_weight"):
        elastic.map_regions(plane.region("boundary"), cap.region("boundary"), distortion_weight=-1)


def test_distortion_weight_matches_the_tools_flag(plane, cap, plane_cap, tmp_path):
    assert plane_cap.energy["distortion"] == 0.0  # off by default
    report = tool_report("map", dict(PLANE_CAP, **{"distortion-weight": 0.25}), tmp_path)
    m = elastic.map_regions(
        plane.region(PLANE_CAP["source-region"]),
        cap.region(PLANE_CAP["target-region"]),
        particles=PLANE_CAP["particles"],
        distortion_weight=0.25,
        threads=2,
    )
    assert m.ok and m.energy["distortion"] > 0.0
    assert m.energy["distortion"] == pytest.approx(report["energy"]["distortion"], rel=1e-12)
    assert m.energy["length"] == pytest.approx(report["energy"]["length"], rel=1e-12)


def test_newton_matches_the_tools_flag(plane, cap, plane_cap, tmp_path):
    # Newton's H0 from the first iteration (docs/solvers.md): another path to the same minimum.
    report = tool_report("map", dict(PLANE_CAP, newton="on"), tmp_path)
    assert report["newton"]["mode"] == "on" and report["newton"]["iterations"] > 0
    m = elastic.map_regions(plane.region(PLANE_CAP["source-region"]),
                            cap.region(PLANE_CAP["target-region"]),
                            particles=PLANE_CAP["particles"], newton="on", threads=2)
    assert m.ok and m.iterations == report["iterations"] != plane_cap.iterations
    assert m.energy["length"] == pytest.approx(report["energy"]["length"], rel=1e-12)
    assert m.energy["length"] == pytest.approx(plane_cap.energy["length"], rel=1e-3)
    with pytest.raises(elastic.InvalidInputError, match="newton"):
        elastic.map_regions(plane.region("boundary"), cap.region("boundary"), newton="always")


def test_coarse_start_matches_the_tools_flag(plane, cap, plane_cap, tmp_path):
    # The multilevel start (docs/solvers.md): 1/8 of the particles mapped first, the boundary held
    # where that map slid it: near the cold map's minimum (measured: length energy 0.07% above it
    # with 186 coarse particles).
    report = tool_report("map", dict(PLANE_CAP, **{"coarse-start": 1000}), tmp_path)
    assert report["coarse_start"]["particles"] > 0
    assert report["seconds"]["coarse_start"] > 0.0
    m = elastic.map_regions(plane.region(PLANE_CAP["source-region"]),
                            cap.region(PLANE_CAP["target-region"]),
                            particles=PLANE_CAP["particles"], coarse_start=1000, threads=2)
    assert m.ok and m.iterations == report["iterations"]
    assert m.seconds["coarse_start"] > 0.0
    assert m.energy["length"] == pytest.approx(report["energy"]["length"], rel=1e-12)
    assert m.energy["length"] == pytest.approx(plane_cap.energy["length"], rel=2e-3)
    assert plane_cap.seconds["coarse_start"] == 0.0  # below the default 50,000
    with pytest.raises(ValueError, match="coarse_start"):
        elastic.map_regions(plane.region("boundary"), cap.region("boundary"), coarse_start=-1)


def test_distortion_guard_matches_the_tools_flag(plane, tmp_path):
    # A flat disk onto the top of spot's back: the guard acts (docs/solvers.md); off, it does not.
    job = {"source": str(MESHES / "grid.off"), "source-region": "disk:0.5,0.5,0,0.45",
           "target": str(MESHES / "spot.obj"), "target-region": "disk:0.181,0.946,-0.245,0.3",
           "particles": 1500}
    spot = elastic.Surface(job["target"])
    lengths = {}
    for guard in (True, False):
        report = tool_report("map", dict(job, **{"distortion-guard": "on" if guard else "off"}),
                             tmp_path)
        m = elastic.map_regions(plane.region(job["source-region"]),
                                spot.region(job["target-region"]), particles=job["particles"],
                                distortion_guard=guard, threads=2)
        assert m.ok
        assert report["distortion_guard"]["taken"] is guard
        assert m.energy["length"] == pytest.approx(report["energy"]["length"], rel=1e-12)
        lengths[guard] = m.energy["length"]
    assert lengths[True] > lengths[False]  # the guard trades length for less distortion


def test_vectors_follow_the_maps_differential(plane_cap, plane):
    rng = np.random.default_rng(11)
    angle = rng.uniform(0, 2 * np.pi, 40)
    radius = rng.uniform(0.0, 0.35, 40)
    x = np.stack([0.5 + radius * np.cos(angle), 0.5 + radius * np.sin(angle), np.zeros(40)], 1)
    v = np.stack([np.cos(2 * angle), np.sin(2 * angle), np.zeros(40)], 1)
    at = plane.closest(x)
    moved = plane_cap.transport_vectors(at["face"], at["uv"], v)
    assert moved["inside"].all()
    # J v against a finite difference of the map along v. J is the grid triangle's (flat)
    # Jacobian while the mapped points lie on the curved limit surface: they differ by about 0.13%
    # here, whatever h (1e-4 .. 1e-7).
    h = 1e-6
    ahead = plane.closest(x + h * v)
    f0 = plane_cap.forward(at["face"], at["uv"])["position"]
    f1 = plane_cap.forward(ahead["face"], ahead["uv"])["position"]
    scale = np.linalg.norm(moved["vectors"], axis=1)
    assert np.allclose((f1 - f0) / h, moved["vectors"], atol=5e-3 * scale.max())
    rotated = plane_cap.transport_vectors(at["face"], at["uv"], v, mode="rotation")
    assert np.allclose(np.linalg.norm(rotated["vectors"], axis=1), 1.0, atol=1e-9)
    with pytest.raises(ValueError, match="mode"):
        plane_cap.transport_vectors(at["face"], at["uv"], v, mode="shear")


CTRL_C_DURING_A_BUILD = """
import os, signal, sys, threading, time
import elastic
start = time.monotonic()
elastic.Surface(sys.argv[1])  # a temporary: freed as soon as the call returns
alone = time.monotonic() - start
threading.Timer(0.05, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
start = time.monotonic()
try:
    elastic.Surface(sys.argv[1])
    print("not interrupted")
except KeyboardInterrupt:
    print(alone, time.monotonic() - start)
"""


def test_ctrl_c_stops_building_a_surface_at_once_and_the_exit_is_clean():
    # Building a limit surface has no progress callback: it runs on a thread of its own while the
    # call watches for Ctrl-C, and raises KeyboardInterrupt without waiting for it. The process's
    # exit then waits for the abandoned build; a build's surfaces freed by a thread nobody waited
    # for once aborted the process at exit (an Embree mutex, after its statics were gone).
    run = subprocess.run([sys.executable, "-c", CTRL_C_DURING_A_BUILD,
                          str(MESHES / "nefertiti-lowres.obj")],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "terminate" not in run.stderr
    alone, interrupted = map(float, run.stdout.split())
    assert interrupted < 0.05 + 0.5 < alone, (alone, interrupted)


def test_paste_with_luminance_height_writes_the_displaced_mesh(tmp_path, cap):
    source, region = elastic.image_source(str(MESHES / "pmp_logo_512.png"), shape="ellipse")
    m = elastic.map_regions(region, cap.region("boundary"), particles=600)
    files = m.paste(str(tmp_path / "relief"), height="luminance", height_scale=0.05)
    names = {os.path.basename(f) for f in files}
    assert "displaced.obj" in names, names
    displaced = elastic.load_mesh(str(tmp_path / "relief" / "displaced.obj"))
    painted = elastic.load_mesh(str(tmp_path / "relief" / "painted.obj"))
    moved = np.abs(displaced.vertices - painted.vertices).max()
    assert 0 < moved <= 0.05 + 1e-9


def test_an_image_beyond_max_pixels_is_refused_by_name():
    with pytest.raises(elastic.InvalidInputError, match="max_pixels"):
        elastic.image_source(str(MESHES / "pmp_logo_512.png"), max_pixels=512 * 511)


def test_a_mesh_of_mixed_polygons_from_a_list(tmp_path):
    vertices = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0.5, 0]], dtype=float)
    mesh = elastic.Mesh(vertices, [[0, 1, 2, 3], [1, 4, 2]])
    assert mesh.faces is None  # mixed sizes
    assert np.array_equal(mesh.face_offsets, [0, 4, 7])
    assert np.array_equal(mesh.face_vertices, [0, 1, 2, 3, 1, 4, 2])
    with pytest.raises(ValueError, match="face 1 has 2 corners"):
        elastic.Mesh(vertices, [[0, 1, 2], [1, 2]])
    with pytest.raises(ValueError, match="faces"):
        elastic.Mesh(vertices, "0 1 2")


def test_place_decal_matches_the_tools_report_and_pastes(plane, cap, tmp_path):
    job = {
        "source": str(MESHES / "grid.off"),
        "source-region": "disk:0.5,0.5,0,0.3",
        "target": str(MESHES / "hemisphere.off"),
        "target-place": "0.275924,0.275924,0.91974,25,1.5",
        "particles": 600,
    }
    report = tool_report("map", job, tmp_path)
    m = elastic.place_decal(
        plane.region("disk:0.5,0.5,0,0.3"), cap, (0.275924, 0.275924, 0.91974),
        angle=25, scale=1.5, particles=600, threads=2,
    )
    assert m.ok and m.folds == report["folds"] == 0
    assert m.num_particles == report["particles"]
    assert m.iterations == report["iterations"]
    assert m.energy["length"] == pytest.approx(report["energy"]["length"], rel=1e-12)
    assert m.rest_scale == pytest.approx(1.5, rel=1e-15)
    d = m.decal
    assert d["scale"] == 1.5 and d["angle_deg"] == 25
    assert d["centre"] == pytest.approx(report["decal"]["centre"], rel=1e-12)
    assert d["target_area"] == pytest.approx(report["decal"]["target_area"], rel=1e-12)
    assert elastic.map_regions(plane.region("disk:0.5,0.5,0,0.3"), cap.region("boundary"),
                               particles=100).decal is None
    _, logo = elastic.image_source(str(MESHES / "pmp_logo_512.png"), width=0.5)
    d = elastic.place_decal(logo, cap, (0.275924, 0.275924, 0.91974), angle=-10, particles=400)
    assert d.ok and d.decal["target_area"] == pytest.approx(0.25, rel=0.02)
    files = d.paste(str(tmp_path / "decal"))
    assert "painted.obj" in {os.path.basename(f) for f in files}
    with pytest.raises(ValueError, match="SCALE at most"):
        elastic.place_decal(plane.region("disk:0.5,0.5,0,0.3"), cap, (0.9, 0.0, 0.3), scale=3,
                            particles=200)


def test_warm_start_from_a_previous_map(plane, cap):
    source = plane.region(PLANE_CAP["source-region"])
    before = cap.region("disk:0,0,1,0.5")
    after = cap.region("disk:0.1,0,0.995,0.52")
    first = elastic.map_regions(source, before, particles=800, threads=2)
    cold = elastic.map_regions(source, after, particles=800, threads=2)
    warm = elastic.map_regions(source, after, particles=800, threads=2, previous=first)
    assert first.ok and cold.ok and warm.ok
    assert warm.num_particles == first.num_particles  # the previous grid, not a new sampling
    assert warm.energy["length"] == pytest.approx(cold.energy["length"], rel=0.02)
    # Another source region (even an equal one) cannot reuse the previous grid.
    with pytest.raises(ValueError, match="previous map"):
        elastic.map_regions(plane.region(PLANE_CAP["source-region"]), after, previous=first)
