"""The log's front end (meshes/log_end.py): flat, chamfered, rounded.

Geometry against brute force and exact formulas, the meshes against the geometry, and bad
input named before anything is meshed."""
import math

import numpy as np
import pytest
from mpi4py import MPI

from flexcontact.errors import InputError
from flexcontact.meshes.log_end import LogEnd

L, R = 10.0, 0.4
ENDS = [LogEnd(), LogEnd("chamfered", 0.1), LogEnd("chamfered", 0.39),
        LogEnd("rounded", radius_m=0.4), LogEnd("rounded", radius_m=0.8),
        LogEnd("rounded", radius_m=5.0)]


def _profile(end, x):
    """The log's radius at axial positions x (its surface of revolution)."""
    h, d = 0.5 * L, end.depth_m(R)
    r = np.full_like(x, R)
    tip = x > h - d
    if end.shape == "chamfered":
        r[tip] = R - (x[tip] - (h - d))
    elif end.shape == "rounded":
        xc, rho, _ = end.cap(L, R)
        r[tip] = np.sqrt(np.maximum(rho ** 2 - (x[tip] - xc) ** 2, 0.0))
    return r


def _boundary_points(end, n=4001, m=721):
    """Points of the 3D log's surface: its profile revolved, both end discs filled in."""
    x = np.linspace(-0.5 * L, 0.5 * L, n)
    r = _profile(end, x)
    phi = np.linspace(0.0, 2.0 * math.pi, m)
    X = np.repeat(x, m)
    Y = np.outer(r, np.cos(phi)).ravel()
    Z = np.outer(r, np.sin(phi)).ravel()
    pts = [np.column_stack([X, Y, Z])]
    if end.shape == "rounded":  # the cap by its polar angle: x misses the steep pole
        xc, rho, cos_max = end.cap(L, R)
        theta = np.linspace(0.0, math.acos(cos_max), 721)
        r = rho * np.sin(theta)
        pts.append(np.column_stack([np.repeat(xc + rho * np.cos(theta), m),
                                    np.outer(r, np.cos(phi)).ravel(),
                                    np.outer(r, np.sin(phi)).ravel()]))
    return np.vstack(pts)


@pytest.mark.parametrize("end", ENDS, ids=lambda e: f"{e.shape}-{e.chamfer_m}-{e.radius_m}")
def test_support_is_the_farthest_point(end):
    """h(d) = max over the surface of p·d, to the sampling's resolution (1e-4 m), and the
    point it returns lies on the surface and reaches h exactly."""
    pts = _boundary_points(end)
    rng = np.random.default_rng(3)
    pitch = math.radians(12.0)
    axis = np.array([math.cos(pitch), 0.0, math.sin(pitch)])
    # The log along `axis`: rotate the sampled surface (built along x) about y.
    rot = np.array([[math.cos(pitch), 0, -math.sin(pitch)], [0, 1, 0],
                    [math.sin(pitch), 0, math.cos(pitch)]])
    world = pts @ rot.T
    for d in [np.array([1.0, 0, 0]), np.array([0, 0, -1.0]), axis,
              *rng.normal(size=(20, 3))]:
        d = d / np.linalg.norm(d)
        h, x, q = end.support(L, R, axis, d)
        assert h == pytest.approx(float((world @ d).max()), abs=1e-4)
        p = x * axis + q
        assert float(p @ d) == pytest.approx(h, abs=1e-12)
        local = rot.T @ p  # back in the log frame: on the profile
        radius = math.hypot(local[1], local[2])
        on_face = abs(local[0] - 0.5 * L) < 1e-12 and radius <= _profile(end, np.array(
            [local[0]]))[0] + 1e-12
        assert on_face or radius == pytest.approx(_profile(end, np.array([local[0]]))[0],
                                                  abs=1e-9)


@pytest.mark.parametrize("end", ENDS, ids=lambda e: f"{e.shape}-{e.chamfer_m}-{e.radius_m}")
def test_volume_and_area_are_the_profile_integrals(end):
    """The closed forms against quadrature of the profile (1e-9 relative)."""
    from scipy.integrate import quad
    h, d = 0.5 * L, end.depth_m(R)
    f = lambda x: _profile(end, np.array([x]))[0]  # noqa: E731
    vol = math.pi * R * R * (L - d) + quad(lambda x: math.pi * f(x) ** 2, h - d, h,
                                           epsabs=0, epsrel=1e-13)[0] if d else math.pi * R * R * L
    area = 2 * R * (L - d) + quad(lambda x: 2 * f(x), h - d, h, epsabs=0,
                                  epsrel=1e-13)[0] if d else 2 * R * L
    assert end.volume_m3(L, R) == pytest.approx(vol, rel=1e-9)
    assert end.area_m2(L, R) == pytest.approx(area, rel=1e-9)


def test_hemisphere_and_flat_limits():
    """A cap of radius R is a hemisphere (depth R, volume πR²(L − R) + 2πR³/3); a very
    flat cap removes the thin ring a paraboloid would."""
    hemi = LogEnd("rounded", radius_m=R)
    assert hemi.depth_m(R) == pytest.approx(R, abs=1e-15)
    assert hemi.volume_m3(L, R) == pytest.approx(math.pi * R * R * (L - R)
                                                 + 2 * math.pi * R ** 3 / 3, rel=1e-14)
    # A flat cap (ρ ≫ R) removes πR⁴/(4ρ): the paraboloid's rim ring, to O(R/ρ)².
    rho = 1e3
    removed = LogEnd().volume_m3(L, R) - LogEnd("rounded", radius_m=rho).volume_m3(L, R)
    assert removed == pytest.approx(math.pi * R ** 4 / (4 * rho), rel=1e-6)


@pytest.mark.parametrize("kw, name, value", [
    (dict(log_end_shape="pointed"), "log_end_shape", "'pointed'"),
    (dict(log_end_shape=3), "log_end_shape", "3"),
    (dict(log_end_shape="chamfered", log_end_chamfer_m=0.4), "log_end_chamfer_m", "0.4"),
    (dict(log_end_shape="chamfered", log_end_chamfer_m=0.5), "log_end_chamfer_m", "0.5"),
    (dict(log_end_shape="chamfered", log_end_chamfer_m=-0.1), "log_end_chamfer_m", "-0.1"),
    (dict(log_end_shape="rounded", log_end_radius_m=0.39), "log_end_radius_m", "0.39"),
    (dict(log_end_shape="rounded", log_end_radius_m=float("nan")), "log_end_radius_m", "nan"),
    (dict(log_end_shape="rounded", log_end_radius_m="big"), "log_end_radius_m", "'big'"),
])
def test_bad_end_is_named(kw, name, value):
    from flexcontact.dam import DamScenario
    with pytest.raises(InputError, match=rf"{name}={value}"):
        DamScenario(**kw)


def test_flat_scenario_is_unchanged():
    """The flat end keeps the cylinder's placement and mass bitwise (the meshes and every
    earlier result with them)."""
    from flexcontact.dam import DamScenario
    for dim, kw in ((2, {}), (3, dict(log_yaw_deg=15.0))):
        s = DamScenario(dim=dim, **kw)
        a, c, r, hl = s.log_axis, abs(float(s.log_axis[0])), s.log_radius_m, 0.5 * s.log_length_m
        reach = 0.5 * s.log_length_m * c + r * math.sqrt(max(1.0 - c * c, 0.0))
        assert s._log_reach(np.eye(dim)[0]) == reach
        assert s.log_mass_kg() == s.wood.rho_kg_m3 * math.pi * r ** 2 * s.log_length_m
        radial = np.eye(dim)[0] - (a @ np.eye(dim)[0]) * a
        expected = s.log_centre + hl * a + r * radial / np.linalg.norm(radial)
        assert np.array_equal(s.log_front_point, expected)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("shape, kw", [("chamfered", {}), ("rounded", {}),
                                       ("rounded", dict(log_end_radius_m=0.4))])
def test_meshed_log_matches_its_geometry(dim, shape, kw):
    """The meshed log: its volume (area in 2D) within the polygonal error of its curved
    faces, its nearest node to the dam at the gap, and every front-end facet tagged
    ``log_front``."""
    import dolfinx
    import ufl
    from flexcontact import compat
    from flexcontact.dam import DamScenario
    from flexcontact.meshes import dam as dam_mesh
    from flexcontact.meshes import dam_tags as T

    h = 0.05 if dim == 2 else 0.1
    s = DamScenario(dim=dim, log_end_shape=shape, mesh_size_far_m=8.0,
                    mesh_size_impact_m=h, **kw)
    msh, ct, ft, _ = dam_mesh.build(MPI.COMM_WORLD, s)
    dx = ufl.Measure("dx", domain=msh, subdomain_data=ct)
    vol = msh.comm.allreduce(dolfinx.fem.assemble_scalar(dolfinx.fem.form(1.0 * dx(T.LOG))),
                             op=MPI.SUM)
    exact = (s.log_end.area_m2 if dim == 2 else s.log_end.volume_m3)(s.log_length_m,
                                                                     s.log_radius_m)
    # Chords of length e on a circle of radius r cut off (e/r)²/6 of the disc's area (a
    # regular polygon's deficit, to leading order); curved faces and boundaries here have
    # radii r ≥ R (R − c for a chamfer's end disc), and gmsh's edges reach e = 1.4 h, so
    # the bound is (1.4 h/r)²/6. The 2D chamfer's faces are straight: exact.
    r = s.log_radius_m - (s.log_end.chamfer_m if shape == "chamfered" else 0.0)
    tol = 1e-12 if (dim == 2 and shape == "chamfered") else (1.4 * h / r) ** 2 / 6
    assert vol == pytest.approx(exact, rel=tol)

    x = compat.geometry_x(msh)
    cells = ct.indices[ct.values == T.LOG]
    geo = compat.geometry_dofmap(msh)[cells].ravel()
    x_max = msh.comm.allreduce(float(x[geo, 0].max(initial=-np.inf)), op=MPI.MAX)
    # The nearest point is a vertex of a 2D chamfer, and may fall between the nodes of a
    # curved face by a chord's sagitta h²/(8ρ) (ρ: the cap's, or the mantle's R).
    rho = s.log_end.radius_m if shape == "rounded" else s.log_radius_m
    sag = 0.0 if (dim == 2 and shape == "chamfered") else h * h / (8 * rho)
    assert -s.log_gap_m - sag - 1e-12 <= x_max <= -s.log_gap_m + 1e-12

    front = ft.indices[ft.values == T.LOG_FRONT]
    ds = ufl.Measure("ds", domain=msh, subdomain_data=ft)
    area = msh.comm.allreduce(dolfinx.fem.assemble_scalar(
        dolfinx.fem.form(1.0 * ds(T.LOG_FRONT))), op=MPI.SUM)
    R, end = s.log_radius_m, s.log_end
    if shape == "chamfered":
        c = end.chamfer_m
        exact_area = (2 * (R - c) + 2 * math.sqrt(2) * c if dim == 2 else
                      math.pi * (R - c) ** 2 + math.pi * (2 * R - c) * math.sqrt(2) * c)
    else:
        rho, d = end.radius_m, end.depth_m(R)
        exact_area = 2 * rho * math.asin(R / rho) if dim == 2 else 2 * math.pi * rho * d
    assert msh.comm.allreduce(len(front), op=MPI.SUM) > 0
    assert area == pytest.approx(exact_area, rel=tol)
