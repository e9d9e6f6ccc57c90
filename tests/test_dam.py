"""The gravity-dam scenario: checked parameters, the floating log, the mesh's named groups,
stage 1 (statics) against the hand statics of the dam, and the demo in serial and MPI.

References are computed here from textbook statics: the dam's weight from the trapezoid
decomposition of its profile, the hydrostatic resultant ρ_w g h²/2 at h/3, the tailwater's
horizontal thrust and the weight of the water wedge over the downstream slope, the uplift
trapezoid; the linearised base stresses σ = −N/B ± 6 M_c/B²."""
import math

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx.fem

from demo_runner import run_demo
from flexcontact import compat
from flexcontact.dam import DamScenario, WOOD, floating_draft_m
from flexcontact.dam.section import peak_at_offset
from flexcontact.dam.stage1 import solve_stage1, upstream_water_resultant
from flexcontact.forms import Material
from flexcontact.meshes import _gmsh
from flexcontact.meshes import dam_tags as T
from flexcontact.meshes.tools import surface_coordinates as surface_nodes

COMM = MPI.COMM_WORLD
RHO_W, G = 1000.0, 9.81
STATICS_RTOL = 1e-6


def hand_section(s, width=1.0):
    """(N, shear, moment about the heel tipping downstream) of the dam's free body, and the
    heel and toe stresses; tailwater below the knee."""
    H, bc, m = s.dam_height_m, s.crest_width_m, s.downstream_slope
    B = m * H
    yk = H - bc / m
    rect, tri = bc * H, 0.5 * (B - bc) * yk
    area = rect + tri
    xc = (rect * bc / 2 + tri * (bc + (B - bc) / 3)) / area
    W = s.concrete.rho_kg_m3 * G * area
    h, ht = s.water_level_m, s.tailwater_level_m
    P = RHO_W * G * h ** 2 / 2
    N, V, M = W, P, W * xc + P * h / 3
    if ht > 0:
        assert ht <= yk
        Pt, Wt = RHO_W * G * ht ** 2 / 2, RHO_W * G * m * ht ** 2 / 2
        V -= Pt
        N += Wt
        M += -Pt * ht / 3 + Wt * (B - m * ht / 3)
    if s.uplift_factor > 0:
        U = s.uplift_factor * RHO_W * G * B * (h + ht) / 2
        N -= U
        M -= U * B * (h + 2 * ht) / (3 * (h + ht))
    N, V, M = N * width, V * width, M * width
    Mc = M - B / 2 * N
    heel = -N / (B * width) + 6 * Mc / (width * B ** 2)
    toe = -N / (B * width) - 6 * Mc / (width * B ** 2)
    return dict(normal_force_N=N, shear_force_N=V, moment_heel_Nm=M, moment_centre_Nm=Mc,
                sigma_heel_Pa=heel, sigma_toe_Pa=toe)


def assert_section(section, ref, rtol=STATICS_RTOL):
    got = section.as_dict()
    scale = {"moment_centre_Nm": ref["moment_heel_Nm"],  # a small difference of large terms
             "sigma_heel_Pa": abs(ref["sigma_heel_Pa"]) + abs(ref["sigma_toe_Pa"]),
             "sigma_toe_Pa": abs(ref["sigma_heel_Pa"]) + abs(ref["sigma_toe_Pa"])}
    for key, value in ref.items():
        assert abs(got[key] - value) <= rtol * abs(scale.get(key, value)), (key, got[key], value)


# ---- the floating log --------------------------------------------------------------------
def segment_fraction(R, d):
    """Submerged fraction of a circle of radius R at draft d: (θ − sin θ)/(2π)."""
    theta = 2 * math.acos((R - d) / R)
    return (theta - math.sin(theta)) / (2 * math.pi)


@pytest.mark.parametrize("ratio", [0.2, 0.5, 0.65, 0.9])
def test_draft_solves_the_segment_equation(ratio):
    R = 0.4
    d = floating_draft_m(R, ratio)
    assert abs(segment_fraction(R, d) - ratio) < 1e-12


def test_half_density_log_floats_with_its_axis_on_the_water_line():
    wood = Material(E_Pa=10e9, nu=0.3, rho_kg_m3=500.0, name="half")
    s = DamScenario(wood=wood, water_level_m=25.0, log_diameter_m=1.0)
    assert abs(s.log_draft_m - 0.5) < 1e-14
    assert abs(s.log_axis_elevation_m - 25.0) < 1e-12
    # A second hand value: d = R/2 at s = (π/3 − √3/4)/π.
    ratio = (math.pi / 3 - math.sqrt(3) / 4) / math.pi
    assert abs(floating_draft_m(2.0, ratio) - 1.0) < 1e-13


def test_log_elevation_follows_its_draft():
    s = DamScenario()
    R, ratio = s.log_radius_m, WOOD.rho_kg_m3 / RHO_W
    d = s.log_draft_m
    assert abs(segment_fraction(R, d) - ratio) < 1e-12
    assert abs(s.log_axis_elevation_m - (s.water_level_m - d + R)) < 1e-12
    lighter = s.replace(wood=Material(E_Pa=10e9, nu=0.3, rho_kg_m3=400.0))
    assert lighter.log_axis_elevation_m > s.log_axis_elevation_m  # a lighter log rides higher


def test_westergaard_added_mass_integrates_to_seven_twelfths():
    from flexcontact.dam import westergaard_added_mass_kg_m2
    h = 27.0
    # ∫0^h (7/8) ρ sqrt(h (h − y)) dy = (7/12) ρ h²; substitute y = h (1 − t²) so that the
    # integrand is smooth: (7/4) ρ h² ∫0^1 t² dt, Gauss-Legendre exact.
    t, w = np.polynomial.legendre.leggauss(8)
    t, w = 0.5 * (t + 1), 0.5 * w
    depth = h * t ** 2
    total = np.sum(w * westergaard_added_mass_kg_m2(depth, h) * 2 * h * t)
    assert abs(total / (7 / 12 * RHO_W * h ** 2) - 1) < 1e-12
    assert westergaard_added_mass_kg_m2(-1.0, h) == 0.0  # above the water


# ---- the mesh ----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def stage1_2d():
    return solve_stage1(DamScenario(), comm=COMM)


def _present(tags):
    return set().union(*COMM.allgather(set(np.unique(tags.values).tolist())))


def test_mesh_has_the_named_groups_and_a_water_line_node(stage1_2d):
    s = stage1_2d.scenario
    msh, ct, ft, info = stage1_2d.mesh
    assert _present(ct) == set(T.CELL_TAGS)
    assert _present(ft) == set(T.FACET_TAGS_2D)
    up = surface_nodes(msh, ft, T.DAM_UPSTREAM)
    assert np.allclose(up[:, 0], 0.0, atol=1e-12)
    assert np.min(np.abs(up[:, 1] - s.water_level_m)) < 1e-12 * s.dam_height_m
    base = surface_nodes(msh, ft, T.DAM_BASE)
    assert np.allclose(base[:, 1], 0.0, atol=1e-12)
    assert abs(base[:, 0].min()) < 1e-12 and abs(base[:, 0].max() - s.base_width_m) < 1e-9


def test_log_in_the_mesh_sits_at_its_floating_elevation(stage1_2d):
    s = stage1_2d.scenario
    msh, ct, ft, _ = stage1_2d.mesh
    log = np.vstack([surface_nodes(msh, ft, t) for t in (T.LOG_UPPER, T.LOG_LOWER)])
    t = math.radians(s.log_pitch_deg)
    axis = s.water_level_m - s.log_draft_m + s.log_radius_m
    lowest = axis - s.log_length_m / 2 * math.sin(t) - s.log_radius_m * math.cos(t)
    assert abs(log[:, 1].min() - lowest) < 1e-9
    assert abs(log[:, 0].max() + s.log_gap_m) < 1e-9  # nearest point log_gap_m off the face


# ---- stage 1 -----------------------------------------------------------------------------
def test_stage1_base_section_matches_hand_statics(stage1_2d):
    s = stage1_2d.scenario
    ref = hand_section(s)
    assert_section(stage1_2d.section, ref)
    assert_section(stage1_2d.section_foundation, ref)  # the other side: the solve itself
    force, height = upstream_water_resultant(stage1_2d)
    assert abs(force / (RHO_W * G * s.water_level_m ** 2 / 2) - 1) < STATICS_RTOL
    assert abs(height / (s.water_level_m / 3) - 1) < STATICS_RTOL


def test_stage1_with_tailwater_and_uplift():
    s = DamScenario(water_level_m=29.0, tailwater_level_m=6.0, uplift_factor=0.5,
                    mesh_size_far_m=4.0)
    r = solve_stage1(s, comm=COMM)
    ref = hand_section(s)
    assert_section(r.section, ref)
    assert_section(r.section_foundation, ref)
    assert_section(r.reference, ref)


def test_stage1_3d_block_matches_the_section_statics():
    s = DamScenario(dim=3, log_yaw_deg=15.0, mesh_size_far_m=8.0)
    r = solve_stage1(s, comm=COMM)
    msh, ct, ft, _ = r.mesh
    assert _present(ct) == set(T.CELL_TAGS)
    assert _present(ft) == set(T.FACET_TAGS_3D)
    up = surface_nodes(msh, ft, T.DAM_UPSTREAM)
    assert np.sum(np.abs(up[:, 2] - s.water_level_m) < 1e-9) >= 2  # an edge at the water line
    ref = hand_section(s, width=s.dam_width_m)
    assert_section(r.section, ref)
    assert_section(r.section_foundation, ref)


# ---- peak stress at an offset ------------------------------------------------------------
def test_peak_at_offset_of_a_linear_field(stage1_2d):
    msh, ct, _, _ = stage1_2d.mesh
    V = compat.scalar_space(msh, "Lagrange", 1)
    f = dolfinx.fem.Function(V)
    f.interpolate(lambda x: 2.0 * x[0] + 3.0 * x[1])
    value, where = peak_at_offset(f, (5.0, 10.0), 1.0, ct, T.DAM)
    ref = 2 * 5 + 3 * 10 + math.sqrt(13)  # max of a·x on the circle: a·p + r|a|
    assert abs(value - ref) < 1e-4 and abs(np.hypot(where[0] - 5, where[1] - 10) - 1) < 1e-12
    g = dolfinx.fem.Function(V)
    g.interpolate(lambda x: -x[0] - x[1])
    in_dam, _ = peak_at_offset(g, (0.0, 0.0), 1.0, ct, T.DAM)  # the dam's quarter circle
    anywhere, _ = peak_at_offset(g, (0.0, 0.0), 1.0)  # reaches into the foundation
    assert -1 - 1e-4 < in_dam <= -1 + 1e-9
    assert abs(anywhere - math.sqrt(2)) < 1e-4


# ---- bad input ---------------------------------------------------------------------------
BAD = [
    (dict(log_gap_m=-0.1), "log_gap_m=-0.1"),                 # the log inside the dam
    (dict(water_level_m=31.0), "water_level_m=31.0"),         # water above the crest
    (dict(log_speed_m_s=-2.0), "log_speed_m_s=-2.0"),
    (dict(wood=Material(E_Pa=10e9, nu=0.3, rho_kg_m3=1050.0)), "wood.rho_kg_m3=1050.0"),
    (dict(dam_height_m=0.0), "dam_height_m=0.0"),
    (dict(log_diameter_m=-0.8), "log_diameter_m=-0.8"),
    (dict(foundation_depth_m=-1.0), "foundation_depth_m=-1.0"),
    (dict(log_pitch_deg=90.0), "log_pitch_deg=90.0"),
    (dict(log_yaw_deg=30.0), "log_yaw_deg=30.0"),              # yaw in 2D
    (dict(dim=3, log_yaw_deg=-95.0), "log_yaw_deg=-95.0"),
    (dict(friction_mu=-0.1), "friction_mu=-0.1"),
    (dict(added_mass_coefficient=-1.0), "added_mass_coefficient=-1.0"),
    (dict(westergaard="yes"), "westergaard='yes'"),
    (dict(crest_width_m=30.0), "crest_width_m=30.0"),
    (dict(tailwater_level_m=28.0), "tailwater_level_m=28.0"),
    (dict(uplift_factor=1.5), "uplift_factor=1.5"),
    (dict(water_level_m=0.5), "water_level_m=0.5"),           # too shallow to float the log
    (dict(log_pitch_deg=60.0), "log_pitch_deg=60.0"),         # front point above the crest
    (dict(refine=-1), "refine=-1"),
    (dict(mesh_size_log_m=0.0), "mesh_size_log_m=0.0"),
    (dict(mesh_size_log_m="fine"), "mesh_size_log_m='fine'"),
]


@pytest.mark.parametrize("kwargs,message", BAD, ids=[m for _, m in BAD])
def test_bad_input_names_parameter_before_meshing(kwargs, message, monkeypatch):
    def no_mesh(*a, **k):
        raise AssertionError("a mesh was built for a bad scenario")
    monkeypatch.setattr(_gmsh, "generate", no_mesh)
    with pytest.raises(ValueError) as err:
        solve_stage1(DamScenario(**kwargs), comm=COMM)
    assert message in str(err.value)


# ---- the demo, serial and on two ranks ---------------------------------------------------
@pytest.mark.mpi
def test_demo_serial_and_two_ranks_agree(tmp_path):
    serial, folder = run_demo("dam_debris", "--dim", "2", "--elastic-end",
                              results=tmp_path / "serial")
    par, _ = run_demo("dam_debris", "--dim", "2", "--elastic-end", "--no-plot", "--no-paraview",
                      results=tmp_path / "mpi",
                      ranks=2)
    assert (folder / "geometry.png").is_file() and (folder / "stage1.xdmf").is_file()
    ref = hand_section(DamScenario())
    for key, value in ref.items():
        got = serial["stage1"]["base_section"][key]
        assert abs(got - value) <= STATICS_RTOL * max(abs(value), 1e5), (key, got, value)
        other = par["stage1"]["base_section"][key]
        assert abs(other - got) <= 1e-10 * max(abs(got), 1e5), (key, other, got)
    h = serial["scenario"]["water_level_m"]
    assert abs(serial["stage1"]["hydrostatic_resultant_N"] / (RHO_W * G * h * h / 2) - 1) < 1e-6
    assert par["mesh"]["ranks"] == 2
    assert (folder / "impact.xdmf").is_file() and (folder / "impact_force.csv").is_file()
    for key in ("peak_force_N_per_m", "impulse_N_s_per_m", "contact_duration_s",
                "peak_max_principal_stress_near_impact_Pa", "sigma_heel_during_max_Pa",
                "sigma_toe_during_min_Pa", "log_max_rotation_rad", "log_max_strain"):
        got, other = serial["stage2"][key], par["stage2"][key]
        assert abs(other - got) <= 1e-8 * abs(got), (key, other, got)
    imp = serial["stage2"]
    assert abs(imp["impulse_N_s_per_m"] - imp["impulse_ref"]) <= 0.01 * imp["impulse_ref"]
    # The linearised heel stress before the impact is the hand statics' one.
    assert abs(imp["sigma_heel_before_Pa"] - ref["sigma_heel_Pa"]) <= STATICS_RTOL * 1e5
    report = (folder / "report.md").read_text()
    for heading in ("## Scenario", "## Limits of the model", "## Stage 1", "## Stage 2",
                    "## Against design practice", "## Mesh study", "## Figures"):
        assert heading in report, heading
    # The model's force in the design table: the filtered peak × D (2D), three figures.
    D = serial["scenario"]["log_diameter_m"]
    assert f"| {imp['peak_force_filtered'] * D / 1e6:.3g} |" in report
    assert (folder / "impact_stresses.png").is_file()
    assert (folder / "impact_peak.xdmf").is_file()
    # The picture, or the reason it is missing.
    assert ((folder / "stress_paraview.png").is_file() or "No ParaView picture" in report)
