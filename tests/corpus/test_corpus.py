"""The corpus generator (gridshell.corpus) against closed forms and the properties a design
target needs (a disk, no folds, a sensible aspect, consistently oriented faces)."""
import collections

import numpy as np
import pytest

from gridshell.corpus import COUNTS, FAMILIES, FAST, MODES, REFERENCES, build_reference, get, \
    select
from gridshell.corpus.surfaces import make_near_sphere
from gridshell.geometry.quadmesh import QuadMesh, TriMesh
from gridshell.geometry.meshfile import read_mesh

AB = np.meshgrid(np.linspace(0.02, 0.98, 9), np.linspace(0.02, 0.98, 9), indexing="ij")


def test_the_corpus_spans_families_sizes_resolutions_and_meshes():
    assert len(REFERENCES) >= 60
    assert len({r.name for r in REFERENCES}) == len(REFERENCES)
    fam = collections.Counter(r.family for r in REFERENCES)
    assert set(fam) == set(FAMILIES) and min(fam.values()) >= 3
    sizes = [r.size for r in REFERENCES]
    assert min(sizes) == pytest.approx(0.5) and max(sizes) == pytest.approx(60.0)
    res = [max(r.rows, r.cols) for r in REFERENCES]
    assert min(min(r.rows, r.cols) for r in REFERENCES) == 10 and max(res) == 200
    kinds = collections.Counter(r.mesh for r in REFERENCES)
    assert kinds["quad"] >= 20 and kinds["tri"] >= 20
    assert {r.orientation for r in REFERENCES} == {"upright", "yaw", "tilted", "y-up", "any"}
    assert sum(np.linalg.norm(r.offset) > 10 * r.size for r in REFERENCES) >= 10
    for f in FAMILIES:  # each family at several resolutions and sizes, as quads and triangles
        rs = [r for r in REFERENCES if r.family == f]
        assert {r.mesh for r in rs} == {"quad", "tri"}, f
        assert len({max(r.rows, r.cols) for r in rs}) >= 3, f
        assert max(r.size for r in rs) / min(r.size for r in rs) > 10, f
        assert len({r.orientation for r in rs}) >= 3, f
    # every pipeline and mode has references to run on
    runs = collections.Counter(m for r in REFERENCES for m in r.modes)
    assert set(runs) == set(MODES) and runs["gg"] == len(REFERENCES)
    assert runs["ncp-phlw"] >= 20 and runs["ncp-aa"] >= 15
    # saddle-like and dome-like both among the NCP references
    assert {r.curvature for r in REFERENCES if "ncp-cnc" in r.modes} == {"K>0", "K<0"}


def test_references_are_reproducible_and_independent_of_the_corpus_order():
    r = get("hill-03")
    again = build_reference("hill", 3, r.index)
    np.testing.assert_array_equal(r.grid(), again.grid())
    # the surface comes from the name; only the variant (mesh, size, ...) from the position
    moved = build_reference("hill", 3, r.index + len(REFERENCES))
    assert moved.params == r.params


def test_modes_follow_the_sign_of_K_and_the_umbilics():
    for r in REFERENCES:
        lo, hi = r.K_range
        assert r.modes[0] == "gg"
        assert (r.curvature == "K>0") == (lo > 0) or r.curvature == "mixed"
        if r.curvature == "K<0":
            assert hi < 0
        assert ("ncp-aa" in r.modes) == (r.curvature == "K<0")
        if "ncp-phlw" in r.modes:
            assert r.curvature != "mixed" and r.umbilic_gap > 0.1
        assert ("ncp-aa" in r.no_net) == (r.curvature == "K>0")
    # every point of a sphere is umbilic: no principal net, GG only
    assert all(r.modes == ("gg",) for r in select("sphere-cap"))
    # monkey saddles have a flat point: K reaches 0
    assert all(r.curvature == "mixed" and r.K_range[1] == pytest.approx(0, abs=1e-9)
               for r in select("monkey"))


@pytest.mark.parametrize("ref", REFERENCES, ids=lambda r: r.name)
def test_every_reference_is_a_reasonable_design_target(ref):
    P = ref.grid()
    assert np.all(np.isfinite(P))
    # extent: the size asked for (largest horizontal span before the rotation), metres
    R = np.asarray(ref.rotation)
    Q = (P.reshape(-1, 3) - ref.offset) @ R  # back to the upright frame
    assert max(np.ptp(Q[:, 0]), np.ptp(Q[:, 1])) == pytest.approx(ref.size, rel=0.02)
    assert np.ptp(Q[:, 2]) > 0.02 * ref.size       # not flat
    # no folds: neighbouring cell normals within 60 degrees, all facing the same side
    d1, d2 = P[1:, :-1] - P[:-1, :-1], P[:-1, 1:] - P[:-1, :-1]
    n = np.cross(d2, d1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    assert (n[1:] * n[:-1]).sum(-1).min() > 0.5 and (n[:, 1:] * n[:, :-1]).sum(-1).min() > 0.5
    assert (n.reshape(-1, 3) @ R[:, 2]).min() > -0.5   # facing up in the upright frame
    # a sensible aspect: sides within 1:3, cells within 1:4
    la = np.linalg.norm(np.diff(P[:, P.shape[1] // 2], axis=0), axis=1)
    lb = np.linalg.norm(np.diff(P[P.shape[0] // 2], axis=0), axis=1)
    assert 1 / 3 <= la.sum() / lb.sum() <= 3
    cell = np.linalg.norm(d1, axis=-1) / np.linalg.norm(d2, axis=-1)
    assert 0.25 < cell.min() and cell.max() < 4


@pytest.mark.parametrize("name", ["revolution-03", "hill-01", "saddle-02", "associate-03",
                                  "near-sphere-00", "dini-01"])
def test_meshes_are_oriented_disks(name):
    ref = get(name)
    V, F = ref.mesh_arrays()
    mesh = (QuadMesh if ref.mesh == "quad" else TriMesh)(V, F)   # validates orientation
    assert mesh.is_disk and F.shape[1] == (4 if ref.mesh == "quad" else 3)
    assert len(V) == ref.rows * ref.cols
    # faces up in the upright frame
    up = np.asarray(ref.rotation)[:, 2]
    assert (mesh.face_normals @ up).mean() > 0.5


def test_obj_round_trip(tmp_path):
    ref = get("dome-02")
    path = ref.write_obj(tmp_path / "dome.obj")
    m = read_mesh(path, kind="any")
    V, F = ref.mesh_arrays()
    np.testing.assert_array_equal(m.V, V)
    np.testing.assert_array_equal(m.F, F)


@pytest.mark.parametrize("ref", [r for r in REFERENCES if r.closed_K(0.5, 0.5) is not None],
                         ids=lambda r: r.name)
def test_gaussian_curvature_matches_the_closed_form(ref):
    """Central differences of the placed, scaled and rotated surface against the family's
    closed form (revolution: the profile formula; height field: the graph formula; sphere
    1/R^2, pseudosphere -1/R^2, Dini -1/(a^2+b^2), associates -1/cosh^4 v)."""
    K = ref.gaussian_curvature(*AB)
    Kc = ref.closed_K(*AB)
    scale = np.abs(Kc).max()
    np.testing.assert_allclose(K, Kc, atol=2e-5 * scale)


def test_constant_curvature_patches():
    for ref in select("sphere-cap"):
        K = ref.gaussian_curvature(*AB)
        R = ref.size / ref.shape.params["X"] / 2    # canonical R = 1 over a span of 2 X
        assert R == pytest.approx(ref.scale)
        np.testing.assert_allclose(K, 1 / R**2, rtol=1e-5)
    for ref in select("pseudosphere,dini"):
        K = ref.gaussian_curvature(*AB)
        assert np.ptp(K) < 1e-5 * abs(K.mean()) and K.mean() < 0


def test_sphere_cap_angle_defect():
    """An independent discrete check on the mesh itself: the angle defect of the interior
    vertices of a triangulated sphere cap over their area is 1/R^2."""
    ref = get("sphere-cap-01")
    V, F = ref.mesh_arrays()
    assert F.shape[1] == 3
    defect = np.full(len(V), 2 * np.pi)
    area = np.zeros(len(V))
    for k in range(3):
        p, q, r = V[F[:, k]], V[F[:, (k + 1) % 3]], V[F[:, (k + 2) % 3]]
        u, w = q - p, r - p
        ang = np.arctan2(np.linalg.norm(np.cross(u, w), axis=1), (u * w).sum(1))
        np.subtract.at(defect, F[:, k], ang)
        np.add.at(area, F[:, k], np.linalg.norm(np.cross(u, w), axis=1) / 6)
    inner = np.setdiff1d(np.arange(len(V)), TriMesh(V, F).boundary_vertices)
    K = defect[inner].sum() / area[inner].sum()
    R = ref.size / ref.shape.params["X"] / 2
    assert K == pytest.approx(1 / R**2, rel=0.02)


@pytest.mark.parametrize("ref", select("associate"), ids=lambda r: r.name)
def test_associates_are_isometric_to_the_catenoid(ref):
    """The first fundamental form of every associate (any angle) equals the catenoid's,
    ``E = G = cosh^2 v``, ``F = 0`` (in u, v), from the emitted surface by differences."""
    E, F, G = ref.first_form(*AB)
    Ec, Fc, Gc = ref.closed_metric(*AB)
    s = Ec.max()
    np.testing.assert_allclose(E, Ec, atol=1e-6 * s)
    np.testing.assert_allclose(F, Fc, atol=1e-6 * s)
    np.testing.assert_allclose(G, Gc, atol=1e-6 * s)


def test_ellipsoid_cap_curvature_closed_form():
    shape = make_near_sphere(np.random.default_rng(7))
    a, b, c = (shape.params[k] for k in "abc")
    P = shape.f(*AB)
    x, y, z = P[..., 0], P[..., 1], P[..., 2]
    assert np.allclose(x**2 / a**2 + y**2 / b**2 + z**2 / c**2, 1)
    K = 1 / (a * a * b * b * c * c * (x**2 / a**4 + y**2 / b**4 + z**2 / c**4) ** 2)
    np.testing.assert_allclose(shape.closed["K"](*AB), K, rtol=1e-9)


def test_select_and_the_fast_subset():
    assert [r.name for r in select("saddle-01,dome")][:2] == ["saddle-01", "dome-00"]
    assert len(select("dome")) == COUNTS["dome"]
    fast = select("fast")
    assert 4 <= len(fast) == len(FAST) <= 12
    assert {r.mesh for r in fast} == {"quad", "tri"}
    with pytest.raises(KeyError, match="no reference"):
        get("nope-00")


# ---- the shapes architects draw, in the files users bring ---------------------------------

USER_FAMILIES = ("bump", "round-dome", "asym-hill", "pavilion", "round-plan")


def test_user_families_come_in_every_format_and_unit():
    refs = [r for r in REFERENCES if r.family in USER_FAMILIES]
    assert len(refs) >= 28
    assert {r.file_format for r in refs} == {"3dm", "obj", "ply", "off"}
    assert {r.units for r in refs} == {"m", "cm", "mm"}
    assert sum(r.file_format == "3dm" and r.units == "mm" for r in refs) >= 5
    assert all(r.file_format == "obj" and r.units == "m" for r in REFERENCES
               if r.family not in USER_FAMILIES)
    # every NCP mode a user would try is run: admitted, refused by construction, or tried
    for r in refs:
        assert set(r.modes) | set(r.no_net) | set(r.tried) >= {"gg", "ncp-phlw", "ncp-cnc",
                                                               "ncp-aa"}


@pytest.mark.parametrize("name", [r.name for r in REFERENCES if r.family in USER_FAMILIES][::3])
def test_target_file_reads_back_as_the_reference_in_metres(tmp_path, name):
    from gridshell.io.read import read_input

    ref = get(name)
    path = ref.write_target(tmp_path)
    assert path.suffix == "." + ref.file_format
    g = read_input(str(path), units=None if ref.file_format == "3dm" else ref.units)
    V, _ = ref.mesh_arrays()
    span = np.ptp(V, axis=0).max()
    # every format keeps the coordinates to the last digits (a .3dm in double precision)
    tol = 1e-12
    assert g.V.shape == V.shape and np.abs(g.V - V).max() <= tol * span


def test_round_dome_has_its_umbilic_at_the_crown():
    t = np.linspace(0.02, 0.98, 97)
    A, B = np.meshgrid(t, t, indexing="ij")
    for r in select("round-dome"):
        k = 2 * r.params["h"] / (1.0 + r.params["Y"] ** 2) / r.scale   # k1 = k2 at the crown
        k1, k2 = r.principal_curvatures(A, B)
        i = np.unravel_index(np.argmin(np.abs(k2 - k1)), A.shape)
        assert abs(k2 - k1)[i] < 0.02 * k and abs(abs(k1[i]) - k) < 0.02 * k
        P = r.surface(A, B)                     # the umbilic is the crown: the highest point
        up = np.asarray(r.rotation) @ np.array([0.0, 0.0, 1.0])
        top = np.unravel_index(np.argmax(P @ up), A.shape)
        assert np.hypot(A[i] - A[top], B[i] - B[top]) < 0.03
        assert r.curvature == "K>0" and r.no_net == ("ncp-aa",)


def test_pavilion_footprint_is_three_by_two():
    for r in select("pavilion"):
        V, _ = r.mesh_arrays()
        R = np.asarray(r.rotation)
        base = (V - np.asarray(r.offset)) @ R        # back to the canonical frame (R^T R = I)
        dx, dy = np.ptp(base[:, 0]), np.ptp(base[:, 1])
        assert 1.35 < max(dx, dy) / min(dx, dy) < 1.7


def test_round_plans_have_the_closed_form_crown_and_a_round_rim():
    """The round-plan family: at the plan's centre a dome of revolution is umbilic with the
    closed-form curvature (paraboloid h (1 - r^2 / R2): 2 h / R2; sphere of radius R: 1 / R;
    oblate spheroid of semi-axes R, R, c at its pole: c / R^2); the grid's outer ring of
    vertices lies on the rim, 1 to 1.1 times the semi-axes from the centre (canonical plan)."""
    refs = select("round-plan")
    assert len(refs) == 10 and len({r.params["kind"] for r in refs}) >= 5
    assert {r.mesh for r in refs} == {"quad", "tri"} and {"3dm", "obj"} <= {r.file_format
                                                                        for r in refs}
    for r in refs:
        p, t = r.params, r.params["terms"]
        if p["kind"] in ("paraboloid", "sphere", "oblate"):
            k = {"paraboloid": lambda: -2 * t[1][1],
                 "sphere": lambda: 1 / t[0][1],
                 "oblate": lambda: t[0][3] / t[0][1] ** 2}[p["kind"]]() / r.scale
            k1, k2 = r.principal_curvatures(np.array([0.5]), np.array([0.5]))
            assert abs(abs(k1[0]) - k) < 0.01 * k and abs(abs(k2[0]) - k) < 0.01 * k, r.name
            assert r.revolution and r.curvature == "K>0" and r.no_net == ("ncp-aa",)
        P = r.grid()
        rim = np.concatenate([P[0], P[-1], P[:, 0], P[:, -1]])
        base = (rim - np.asarray(r.offset)) @ np.asarray(r.rotation) / r.scale  # canonical
        rho = np.hypot(base[:, 0] - base[:, 0].mean(), (base[:, 1] - base[:, 1].mean()) / p["Y"])
        assert rho.min() > 0.99 * rho.max() / 1.1 and rho.max() / rho.min() < 1.11, r.name
