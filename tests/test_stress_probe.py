"""The recovered largest principal stress at an offset (dam/stress_probe.py): exact where the
nodal average is exact, and the same on two ranks as in serial."""
import numpy as np
import pytest

from conftest import on_two_ranks
import stress_probe_case as case


@pytest.mark.parametrize("dim", [2, 3])
def test_a_constant_stress_is_recovered_exactly_beside_a_material_interface(dim):
    # The sphere crosses the interface at x = 1.3; only the samples in material 1 count,
    # and its nodes on the interface average material 1's cells only. The stress is the
    # same at every such sample, so the peak's place is any of them, by round-off: it lies
    # in material 1's cells, which reach x = 4/3 (those whose centroid is left of 1.3).
    p = case.probe(dim, "linear", interface_x=1.3)
    value, where = p.peak()
    eps = np.zeros((3, 3))
    eps[:dim, :dim] = 0.5 * (case.A[:dim, :dim] + case.A[:dim, :dim].T)
    ref = np.linalg.eigvalsh(case.stress(case.CONCRETE, eps, "3d"))[-1]
    assert value == pytest.approx(ref, rel=1e-12)
    assert where[0] <= case.reach_x(dim, 1.3) + 1e-12
    assert np.linalg.norm(where[:dim] - case.CENTRE) == pytest.approx(case.OFFSET_M, rel=1e-12)
    exact = case.stress(case.CONCRETE, eps, "3d")   # and so is its mean over the samples
    assert np.abs(p.mean() - exact).max() <= 1e-12 * np.abs(exact).max()


@pytest.mark.parametrize("dim", [2, 3])
def test_a_linear_stress_is_recovered_exactly_on_a_centrally_symmetric_mesh(dim):
    # Every interior node of these structured meshes sits at the volume-weighted mean of its
    # cells' centroids, so the average of the cell values of a linear field is its value at
    # the node, and the linear interpolant is the field itself: the peak over the samples is
    # the exact one there. The cell-wise reading is off by the field's change over a cell.
    p = case.probe(dim, "quadratic")
    value, _ = p.peak()
    pts = p.offset.points[:, :dim]
    sig = np.array([case.stress(case.CONCRETE, e, "3d") for e in case.quadratic_strain(pts)])
    ref = np.linalg.eigvalsh(sig)[:, -1].max()
    assert value == pytest.approx(ref, rel=1e-10)


def test_the_closed_form_largest_principal_stress_is_lapacks():
    # Random symmetric tensors, and the cases where the trigonometric form is weakest: an
    # isotropic one, a double largest eigenvalue, two largest apart by 1e-9 relative.
    from flexcontact.dam.stress_probe import largest_principal
    rng = np.random.default_rng(7)
    t = 1e6 * rng.standard_normal((500, 3, 3))
    t = t + t.transpose(0, 2, 1)
    q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    t[0] = 2e6 * np.eye(3)
    t[1] = q @ np.diag([3e6, 3e6, -1e6]) @ q.T
    t[2] = q @ np.diag([5e6, 5e6 * (1 - 1e-9), 1e6]) @ q.T
    t[3] = q @ np.diag([-1e6, 4e6, 4e6 * (1 + 1e-7)]) @ q.T
    ref = np.linalg.eigvalsh(t)[:, -1]
    scale = np.abs(t).reshape(len(t), -1).max(axis=1)
    assert np.all(np.abs(largest_principal(t) - ref) <= 1e-13 * scale)


@pytest.mark.parametrize("diagonal", ["right", "crossed"])
def test_the_flamant_tension_behind_a_line_load_converges(diagonal):
    # Exact: 2Q/(π r) at r = 0.5 m. Measured (right, crossed diagonals): 1.2 % and 1.4 %
    # at h = 0.1 m (r/h = 5), 0.16 % and 0.31 % at 0.05 m. The cell-wise peak over the
    # same circle is 21 % and 12 % high at 0.1 m and 7.6 % (right) at 0.05 m: its error
    # is first order, the recovered one's about second order.
    errors = []
    for cells_per_m in (10, 20):
        probe, exact = case.flamant(cells_per_m, diagonal)
        value, where = probe.peak()
        errors.append(abs(value / exact - 1))
        assert where[1] > -0.1 and where[0] < 0   # behind the load, at the surface
    assert errors[0] <= 0.02 and errors[1] <= 0.005
    assert errors[1] <= errors[0] / 3


def test_the_halfspace_value_is_boussinesqs_peak_tension_on_the_hemisphere():
    # What the 3D report sets beside the recovered reading: the largest principal stress
    # over the hemisphere of radius r around a normal force F is the surface's radial
    # tension (1 − 2ν) F/(2π r²), and it halves within 0.1 r of the surface: the layer
    # that 0.1–0.2 m elements at r = 0.5 m cannot resolve.
    from flexcontact.dam import DamScenario
    from flexcontact.dam.key_numbers import halfspace_surface_tension_Pa
    s = DamScenario(dim=3)
    force, r = 0.75e6, 0.5
    t = np.radians(np.linspace(0.0, 90.0, 901))
    pts = r * np.column_stack([np.cos(t), np.zeros_like(t), -np.sin(t)])  # every azimuth alike
    pts[0, 2] = -1e-12 * r            # the surface point, on the half-space's side
    sigma1 = case.boussinesq_principal(pts, force, s.concrete.nu)
    value = halfspace_surface_tension_Pa(s, force, r)
    assert value == pytest.approx(sigma1.max(), rel=1e-9)
    depth = r * np.sin(t)
    assert sigma1[np.searchsorted(depth, 0.1 * r)] < 0.5 * value
    assert halfspace_surface_tension_Pa(DamScenario(dim=2), force, r) is None
    # The field itself is checked against the Green's tensor in test_halfspace.py.


def test_boussinesqs_surface_tension_is_bracketed_by_the_two_readings():
    # The tension 0.5 m and 1 m from a normal force lies in a surface layer about a tenth
    # of r deep, thinner than the 0.2 m elements: the recovered reading is low and the
    # cell-wise one high (measured −23 % and +152 % at 0.5 m, −34 % and +74 % at 1 m).
    # That is what the 3D dam report says beside its reading (docs/dam.md).
    from flexcontact.dam.fields import StressFields
    from flexcontact.dam.stress_probe import RecoveredStressProbe
    force = 1e6
    u, tags = case.boussinesq_box(5, force)
    cellwise = StressFields(u.function_space, u, tags, {1: case.CONCRETE}, "3d").update()[1]
    for r in (0.5, 1.0):
        probe = RecoveredStressProbe(u, tags, {1: case.CONCRETE}, "3d", np.zeros(3), r, 1)
        exact = case.boussinesq_principal(probe.offset.points[probe.offset.found], force,
                                          case.CONCRETE.nu).max()
        assert exact == pytest.approx((1 - 2 * case.CONCRETE.nu) * force / (2 * np.pi * r * r),
                                      rel=0.01)   # the samples reach the surface
        recovered, _ = probe.peak()
        high, _ = probe.offset.peak(cellwise)
        assert 0.5 * exact < recovered < exact < high


@pytest.mark.mpi
@pytest.mark.parametrize("dim", [2, 3])
def test_two_ranks_give_the_serial_peak(dim, tmp_path):
    p = case.probe(dim, "quadratic", interface_x=1.3)
    serial, where = p.peak()
    mean = p.mean()
    on_two_ranks(case.__file__, dim, "quadratic", tmp_path / "two.npz")
    two = np.load(tmp_path / "two.npz")
    assert float(two["value"]) == pytest.approx(serial, rel=1e-12)
    assert np.allclose(two["where"], where, rtol=0, atol=1e-14)
    assert np.abs(two["mean"] - mean).max() <= 1e-12 * np.abs(mean).max()
