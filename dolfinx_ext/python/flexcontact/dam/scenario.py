"""One debris-impact scenario of a concrete gravity dam: every parameter, checked up front.

Axes: x points downstream, the vertical axis is the last one (y in 2D, z in 3D), and in 3D y
runs along the dam axis (0 ≤ y ≤ ``dam_width_m``). The heel is the origin: the vertical
upstream face is x = 0 and the dam's base (its interface with the foundation) is the
vertical coordinate 0. The profile is the usual one: a crest of width ``crest_width_m``, a
vertical downstream face under the crest down to the *knee*, then the downstream slope
(``downstream_slope`` horizontal per vertical) down to the toe at x = B = slope · height
(the slope line runs through the upstream crest corner).

The log floats: its axis elevation follows from the water level and its draft (see
:mod:`flexcontact.dam.buoyancy`); it is pitched (front end up for a positive angle) and, in
3D, yawed about the vertical axis, and is placed so that its point nearest the dam is
``log_gap_m`` upstream of the face, in 3D with its centre at y = ``log_across_m`` (default:
mid-width of the block). A pitched log keeps the
centre elevation of the horizontal floating log (exact for s = 1/2 by the symmetry of the
segment area about d = R, a small-angle approximation otherwise).

Materials: concrete and foundation rock are isotropic. Wood is modelled isotropic with the
along-grain modulus, because a log hits nearly end-on and then its axial stiffness governs
the impact; the across-grain modulus is kept (``wood_E_across_grain_Pa``) for reports, not
used by the model.

With ``log_end_crushes=True`` the log's front end crushes: the log/dam interface caps the
contact pressure, averaged over each slave node's tributary measure, at the wood's crushing
strength parallel to the grain (docs/crushing.md). The default is False (an elastic end, the
upper bound of the force) until the default meshes resolve the crushed patch: a pitched log's
corner crushes over a few centimetres, less than one element of the default meshes, so the
capped force would be σ_c times one node's tributary measure, a number of the mesh. The
``wood_crushing_strength_Pa`` = 26.1 MPa is the mean maximum crushing strength parallel to the
grain of green (unseasoned) coast Douglas-fir, 3,784 lbf/in², in the USDA Forest Products
Laboratory's Wood Handbook (2010, ch. 5, Table 5-3a); green loblolly pine has 24.2 MPa
(3,511 lbf/in²). A log carried by a flood is green: its strength is the green one.

Stage-2 parameters are held and checked here too: the log's speed, the friction coefficient,
the log's added-mass coefficient, the optional Westergaard added mass of the reservoir and
the time scheme's ``time_scheme_theta`` (0.55: θ = ½ lets a crushing front chatter, which
makes its force about 15 % low and sensitive to rounding; docs/dam.md, "The time scheme").
``added_mass_coefficient`` C_a multiplies the mass of the water the log displaces, which for
a floating log equals the log's own mass: m_effective = (1 + C_a) m_log. Its default 0.05
covers a log moving nearly along its axis: a slender prolate spheroid of the log's aspect
ratio (L/D = 12.5) has an axial added-mass coefficient of about 0.015 fully submerged; a log
driven sideways would need about 1.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Optional

import numpy as np

from ..forms import Material
from ..forms.loads import STANDARD_GRAVITY_M_S2, WATER_DENSITY_KG_M3
from ..meshes.log_end import LogEnd
from .buoyancy import floating_draft_m

CONCRETE = Material(E_Pa=25e9, nu=0.2, rho_kg_m3=2400.0, name="concrete")
"""Mass concrete of a gravity dam."""
ROCK = Material(E_Pa=20e9, nu=0.25, rho_kg_m3=2600.0, name="rock")
"""Sound foundation rock (deformation modulus)."""
WOOD = Material(E_Pa=10e9, nu=0.3, rho_kg_m3=650.0, name="wood")
"""Green softwood log, isotropic with the along-grain modulus."""

_DEFAULT_MESH = {2: (3.0, 0.2), 3: (6.0, 0.4)}  # (far, impact) element sizes in m by dimension

CRUSHED_PATCH_MESH = {2: (0.00625, 0.1, None), 3: (0.0125, 0.35, 0.05)}
"""(mesh_size_contact_m, contact_zone_m, contact_layer_m) by dimension that resolve the
crushed patch of the default log (10 m × Ø0.8 m, 10° pitch, 2 m/s, flat end, σ_c =
26.1 MPa) at the peak force by at least four elements (the main job's rounded end:
:func:`crushed_patch_mesh`). Measured at θ = 0.55
(docs/dam.md, "The time scheme"): in 2D the patch is about 5 cm along the end (11 crushing
nodes at 6.25 mm); the filtered peak force 1.79, 1.62, 1.76, 1.68, 1.63 MN/m at 50, 25,
12.5, 6.25, 3.1 mm (order 0.9 over the last three, extrapolated 1.58). In 3D the patch is a
segment of the end, 279 pairs at their cap at 12.5 mm within the 0.35 m ball. In 3D the
ball refines the log only (meshes/dam.py), and only 5 cm deep behind its end: the flat
end at the main job's sizes has 28,071 DOFs; with the whole ball refined it had more than
twice as many,
and its answers differed by 0.2 % or less (docs/dam.md, "The mesh study")."""


ROUNDED_PATCH_ZONE_M = 0.2
"""contact_zone_m of the rounded end in 3D. Its crushed patch is a disc about the cap's
first-contact point, of radius √(2ρδ) for a crush depth δ: 0.12 m for the main job's log
(ρ = D, δ = 9.2 mm), 346 pairs at their cap at 12.5 mm. A 0.2 m ball holds it with six
elements to spare, and puts 1,267 nodes on the end where the flat end's 0.35 m ball puts
2,919 on the cap; against the 0.35 m ball (the log's shaft at 0.2 m) the main job's filtered
peak force moved by +1.1 %, Δσ_heel by +0.8 % and the impulse by +0.1 %, inside their
discretisation error (docs/dam.md, "The mesh study")."""


def crushed_patch_mesh(dim: int, end_shape: str = "flat") -> tuple:
    """(mesh_size_contact_m, contact_zone_m, contact_layer_m) that resolve the default log's
    crushed patch with the end ``end_shape``: :data:`CRUSHED_PATCH_MESH`, with the smaller
    ball :data:`ROUNDED_PATCH_ZONE_M` for a rounded end in 3D."""
    size, zone, layer = CRUSHED_PATCH_MESH[dim]
    if dim == 3 and end_shape == "rounded":
        zone = ROUNDED_PATCH_ZONE_M
    return size, zone, layer


MAIN_JOB_LOG_MESH_M = {2: None, 3: 0.1}
"""mesh_size_log_m of the main job by dimension (None: the impact zone's size). In 3D the
log's shaft at the impact zone's 0.2 m is four elements across its 0.8 m: the pitched
impact bends it, and linear tetrahedra that coarse are too stiff in bending, so its rebound,
the impulse and Δσ_heel came out 2.2 % and 2.5 % low against the log at 0.1 m, which gives
the finest study mesh's Δσ_heel (docs/dam.md, "The mesh study")."""

MAIN_JOB_MESH = {2: (3.0, 0.2), 3: (3.0, 0.2)}
"""(mesh_size_far_m, mesh_size_impact_m) of the main job (demos/dam_debris.py) by
dimension. In 3D finer than the sweeps' default (6 m, 0.4 m): the main job's mesh study
(docs/dam.md) put that mesh's Δσ_heel 7 % below its Richardson extrapolation (GCI 9.5 %),
while 3 m / 0.2 m costs little beside the crushed patch's elements (56,082 DOFs against
45,921)."""


@dataclass(frozen=True)
class DamScenario:
    """All parameters of one scenario, in SI units; raises ValueError on a bad one.

    Construct with keywords and derive variants with :meth:`replace`. Every check runs in
    the constructor, so nothing is meshed or computed for a bad scenario.
    """

    dim: int = 2
    # dam and foundation (m)
    dam_height_m: float = 30.0
    crest_width_m: float = 5.0
    downstream_slope: float = 0.8
    dam_width_m: float = 15.0
    foundation_depth_m: float = 30.0
    foundation_upstream_m: float = 30.0
    foundation_downstream_m: float = 30.0
    # water (m above the base)
    water_level_m: float = 27.0
    tailwater_level_m: float = 0.0
    uplift_factor: float = 0.0
    # log (m, degrees)
    log_length_m: float = 10.0
    log_diameter_m: float = 0.8
    log_pitch_deg: float = 10.0
    log_yaw_deg: float = 0.0
    log_gap_m: float = 0.02
    # 3D: where the log's centre is across the block, y (m); None: mid-width
    log_across_m: Optional[float] = None
    # the front end (meshes/log_end.py): "flat", "chamfered" (bevel log_end_chamfer_m,
    # None: D/8) or "rounded" (a spherical cap of radius log_end_radius_m >= D/2, None: D)
    log_end_shape: str = "flat"
    log_end_chamfer_m: Optional[float] = None
    log_end_radius_m: Optional[float] = None
    # stage 2 (impact)
    log_speed_m_s: float = 2.0
    friction_mu: float = 0.5
    added_mass_coefficient: float = 0.05
    westergaard: bool = False
    # θ of stage 2's Moreau–Jean scheme, in [0.5, 1]; above ½ it damps the mesh's highest
    # frequencies, which a crushing end otherwise excites into chatter (docs/dam.md)
    time_scheme_theta: float = 0.55
    # materials and strengths
    concrete: Material = CONCRETE
    rock: Material = ROCK
    wood: Material = WOOD
    wood_E_across_grain_Pa: float = 0.6e9
    wood_crushing_strength_Pa: float = 26.1e6
    log_end_crushes: bool = False
    concrete_tensile_strength_Pa: float = 2.5e6
    water_density_kg_m3: float = WATER_DENSITY_KG_M3
    gravity_m_s2: float = STANDARD_GRAVITY_M_S2
    # mesh
    mesh_size_far_m: Optional[float] = None
    mesh_size_impact_m: Optional[float] = None
    impact_zone_m: float = 1.0
    # on the log, if finer than h_impact (None: h_impact): its shaft, in the whole mesh and
    # in the log's own frame alike
    mesh_size_log_m: Optional[float] = None
    # the first-contact point's cap (None: h_log) within contact_zone_m of it
    mesh_size_contact_m: Optional[float] = None
    contact_zone_m: float = 0.1
    # ... and only within contact_layer_m behind the log's front end (None: the whole ball)
    contact_layer_m: Optional[float] = None
    refine: int = 0

    def __post_init__(self):
        from .validate import check_scenario
        check_scenario(self)

    def replace(self, **changes) -> DamScenario:
        """A copy with some parameters changed (checked again)."""
        return replace(self, **changes)

    @classmethod
    def from_dict(cls, d: dict) -> DamScenario:
        """The scenario of :meth:`as_dict`'s output (materials keep their default names)."""
        kwargs = {}
        for f in fields(cls):
            if f.name not in d:
                continue
            v = d[f.name]
            if isinstance(f.default, Material):
                v = Material(E_Pa=v["E_Pa"], nu=v["nu"], rho_kg_m3=v["rho_kg_m3"],
                             name=f.default.name)
            kwargs[f.name] = v
        return cls(**kwargs)

    def as_dict(self) -> dict:
        """Plain parameters for a summary (materials as dicts)."""
        out = {}
        for f in fields(self):
            v = getattr(self, f.name)
            out[f.name] = ({"E_Pa": v.E_Pa, "nu": v.nu, "rho_kg_m3": v.rho_kg_m3}
                           if isinstance(v, Material) else v)
        return out

    # ---- dam profile -------------------------------------------------------------------
    @property
    def base_width_m(self) -> float:
        """B = slope · height: heel at x = 0, toe at x = B."""
        return self.downstream_slope * self.dam_height_m

    @property
    def knee_elevation_m(self) -> float:
        """Where the downstream slope meets the vertical face under the crest."""
        return self.dam_height_m - self.crest_width_m / self.downstream_slope

    def downstream_face_x_m(self, elevation_m: float) -> float:
        """x of the downstream face at a given elevation."""
        if elevation_m >= self.knee_elevation_m:
            return self.crest_width_m
        return self.base_width_m - self.downstream_slope * elevation_m

    def dam_outline(self) -> list:
        """Profile corners (x, vertical) counter-clockwise from the heel: heel, toe, knee,
        crest downstream, crest upstream."""
        H, B, bc, yk = (self.dam_height_m, self.base_width_m, self.crest_width_m,
                        self.knee_elevation_m)
        return [(0.0, 0.0), (B, 0.0), (bc, yk), (bc, H), (0.0, H)]

    @property
    def vertical_axis(self) -> int:
        return self.dim - 1

    @property
    def h_far_m(self) -> float:
        h = self.mesh_size_far_m or _DEFAULT_MESH[self.dim][0]
        return h / 2 ** self.refine

    @property
    def h_impact_m(self) -> float:
        h = self.mesh_size_impact_m or _DEFAULT_MESH[self.dim][1]
        return min(h / 2 ** self.refine, self.h_far_m)

    @property
    def h_log_m(self) -> float:
        """Element size on the log (h_impact when not set, never coarser): the shaft's
        waves and bending, which a thin log at the impact zone's size resolves by one or
        two elements across."""
        if self.mesh_size_log_m is None:
            return self.h_impact_m
        return min(self.mesh_size_log_m / 2 ** self.refine, self.h_impact_m)

    @property
    def h_contact_m(self) -> float:
        """Element size within ``contact_zone_m`` of the first-contact point, where a
        crushing end's patch must be resolved (h_log when not set)."""
        if self.mesh_size_contact_m is None:
            return self.h_log_m
        return min(self.mesh_size_contact_m / 2 ** self.refine, self.h_log_m)

    # ---- water -------------------------------------------------------------------------
    def hydrostatic_resultant_N_per_m(self) -> float:
        """ρ_w g h²/2 on the upstream face per unit width, acting at h/3 above the base."""
        return 0.5 * self.water_density_kg_m3 * self.gravity_m_s2 * self.water_level_m ** 2

    # ---- log ---------------------------------------------------------------------------
    @property
    def log_radius_m(self) -> float:
        return 0.5 * self.log_diameter_m

    @property
    def log_density_ratio(self) -> float:
        return self.wood.rho_kg_m3 / self.water_density_kg_m3

    @property
    def log_draft_m(self) -> float:
        return floating_draft_m(self.log_radius_m, self.log_density_ratio)

    @property
    def log_axis_elevation_m(self) -> float:
        """Elevation of the floating log's axis: water level − draft + radius."""
        return self.water_level_m - self.log_draft_m + self.log_radius_m

    @property
    def log_axis(self) -> np.ndarray:
        """Unit vector along the log, pointing at the dam (front end)."""
        t, p = math.radians(self.log_pitch_deg), math.radians(self.log_yaw_deg)
        if self.dim == 2:
            return np.array([math.cos(t), math.sin(t)])
        return np.array([math.cos(t) * math.cos(p), math.cos(t) * math.sin(p), math.sin(t)])

    @property
    def log_end(self) -> LogEnd:
        """The front end's shape, with the defaults filled in (chamfer D/8, cap radius D)."""
        D = self.log_diameter_m
        c = D / 8 if self.log_end_chamfer_m is None else self.log_end_chamfer_m
        rho = D if self.log_end_radius_m is None else self.log_end_radius_m
        return LogEnd(self.log_end_shape, c, rho)

    def _log_support(self, direction: np.ndarray):
        return self.log_end.support(self.log_length_m, self.log_radius_m, self.log_axis,
                                    direction)

    def _log_reach(self, direction: np.ndarray) -> float:
        """Largest extent of the log beyond its centre along a unit ``direction``."""
        return self._log_support(direction)[0]

    @property
    def log_centre(self) -> np.ndarray:
        """Centre of the log (m): the nearest point to the dam is ``log_gap_m`` from x = 0."""
        ex = np.eye(self.dim)[0]
        c = np.zeros(self.dim)
        c[0] = -self.log_gap_m - self._log_reach(ex)
        c[-1] = self.log_axis_elevation_m
        if self.dim == 3:
            c[1] = 0.5 * self.dam_width_m if self.log_across_m is None else self.log_across_m
        return c

    @property
    def log_front_point(self) -> np.ndarray:
        """The log's point nearest the dam (first contact): a corner of a flat end, a point
        of a bevel's rim or of the cap, or the front face's centre for a log square to the
        face."""
        _, x, q = self._log_support(np.eye(self.dim)[0])
        return self.log_centre + x * self.log_axis + q

    @property
    def log_lowest_elevation_m(self) -> float:
        ez = np.eye(self.dim)[-1]
        return float(self.log_centre[-1] - self._log_reach(-ez))

    def log_mass_kg(self) -> float:
        """Mass of the 3D log, ρ times its volume (πR²L less what the end's shape removes),
        kg."""
        if self.log_end_shape == "flat":
            return self.wood.rho_kg_m3 * math.pi * self.log_radius_m ** 2 * self.log_length_m
        return self.wood.rho_kg_m3 * self.log_end.volume_m3(self.log_length_m,
                                                            self.log_radius_m)

    def log_mass_2d_kg_per_m(self) -> float:
        """Mass per unit width of the plane-strain log (a slab L × D, less what the end's
        shape removes), kg/m."""
        if self.log_end_shape == "flat":
            return self.wood.rho_kg_m3 * self.log_length_m * self.log_diameter_m
        return self.wood.rho_kg_m3 * self.log_end.area_m2(self.log_length_m,
                                                          self.log_radius_m)

    def log_added_mass_kg(self) -> float:
        """C_a times the displaced water's mass (= the floating log's mass), kg."""
        return self.added_mass_coefficient * self.log_mass_kg()
