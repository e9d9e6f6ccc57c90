"""Two elastic cylinders of different radii pressed together (plane strain), non-matching.

Geometry (m), y up, the bodies touching at the origin:

* cylinder 1 (tag BASE): the upper half of the disc of radius R1 centred at (0, −R1); its
  flat bottom y = −R1 is held (FIXED); its arc near the origin is the candidate zone MASTER;
* cylinder 2 (tag UPPER): the lower half of the disc of radius R2 centred at (0, R2); its
  flat top y = R2 is loaded (LOADED); its arc near the origin is the candidate zone SLAVE.

The tags MASTER and SLAVE only name the two zones: either may be the slave of the contact.
The initial gap at abscissa x is g1(x) + g2(x), g_i(x) = R_i − sqrt(R_i² − x²), so that near
the contact the pair acts as one cylinder of radius R = (1/R1 + 1/R2)⁻¹ on a plane: Hertz's
half-width a = sqrt(4 P R / (π E*)).

The candidate zone |x| ≤ w (w = zone_factor · a_expected) of each arc is a chain of straight
one-element segments with nodes on the circle; cylinder 2's nodes are spaced h, cylinder
1's ``spacing_ratio`` · h, so that no node faces another (non-matching meshes). Elements
grow from h to h_far away from the zone. The loaded and held faces pass through the
centres, as in hertz2d.py; Hertz needs a ≪ R1, R2.
"""

import math

import numpy as np

from . import _check, _gmsh
from .tags import BASE, FIXED, LOADED, MASTER, NAMES, SLAVE, UPPER
from flexcontact.errors import InputError


def gap(x, R):
    """Height g(x) = R − sqrt(R² − x²) in m of a circle of radius R above its lowest point."""
    x = np.asarray(x, dtype=float)
    return R - np.sqrt(R * R - x * x)


def effective_radius(R1, R2):
    """R = (1/R1 + 1/R2)⁻¹ in m, the radius of Hertz's equivalent cylinder on a plane."""
    R1, R2 = _check.positive("R1", R1), _check.positive("R2", R2)
    return 1.0 / (1.0 / R1 + 1.0 / R2)


def _zone_abscissae(w, h):
    """Symmetric abscissae of spacing ≤ h over [−w, w], x = 0 among them."""
    n = math.ceil(w / h - 1e-9)
    return [w * i / n for i in range(-n, n + 1)]


def build(comm, R1=0.05, R2=0.03, a_expected=None, h_contact=None, h_far=None, refine=0,
          zone_factor=2.0, spacing_ratio=0.7):
    """Build the mesh on ``comm``; returns ``(mesh, cell_tags, facet_tags, info)``.

    Args:
        R1, R2: radii of cylinder 1 (below) and cylinder 2 (above) in m.
        a_expected: expected contact half-width a in m, sets the zone; default R/10 with R
            the effective radius.
        h_contact: cylinder 2's element size in the candidate zone (m); default
            a_expected/10.
        h_far: element size far from the zone (m); default min(R1, R2)/4.
        refine: each level halves h_contact and h_far (≈ 4× the cells).
        zone_factor: candidate zone half-width w = zone_factor · a_expected (≥ 1).
        spacing_ratio: cylinder 1's zone spacing relative to cylinder 2's (≠ 1 for
            non-matching meshes).

    ``info`` holds R1, R2, R (effective), a_expected, w, h_contact (cylinder 2's zone
    spacing), h_cylinder1 (cylinder 1's), h_far and the zone node counts n_nodes_1, n_nodes_2.
    """
    R1, R2 = _check.positive("R1", R1), _check.positive("R2", R2)
    R = effective_radius(R1, R2)
    _, a, w = _check.hertz_zone(R, a_expected, zone_factor)
    _check.less("zone half-width w = zone_factor * a_expected", w, "min(R1, R2)", min(R1, R2))
    refine = _check.refine_level(refine)
    h = _check.positive("h_contact", a / 10 if h_contact is None else h_contact) / 2 ** refine
    hf = _check.positive("h_far", min(R1, R2) / 4 if h_far is None else h_far) / 2 ** refine
    ratio = _check.positive("spacing_ratio", spacing_ratio, "dimensionless")
    if max(h, ratio * h) > w:
        raise InputError(f"h_contact={h!r} (after refine={refine}, spacing_ratio={ratio!r}) "
                         f"exceeds the zone half-width w={w!r}")
    hf = max(hf, h, ratio * h)
    x2, x1 = _zone_abscissae(w, h), _zone_abscissae(w, ratio * h)
    info = dict(R1=R1, R2=R2, R=R, a_expected=a, w=w, h_contact=2 * w / (len(x2) - 1),
                h_cylinder1=2 * w / (len(x1) - 1), h_far=hf, n_nodes_1=len(x1),
                n_nodes_2=len(x2))

    def model():
        import gmsh
        geo = gmsh.model.geo
        # Cylinder 1 (below), counter-clockwise: bottom, right arc, zone right to left, left arc.
        c1 = geo.addPoint(0, -R1, 0)
        bl, br = geo.addPoint(-R1, -R1, 0), geo.addPoint(R1, -R1, 0)
        p1 = [geo.addPoint(x, -float(gap(x, R1)), 0) for x in x1]
        zone1 = [geo.addLine(p1[i], p1[i + 1]) for i in range(len(x1) - 1)]
        bottom = geo.addLine(bl, br)
        arc1r, arc1l = geo.addCircleArc(br, c1, p1[-1]), geo.addCircleArc(p1[0], c1, bl)
        cyl1 = geo.addPlaneSurface([geo.addCurveLoop(
            [bottom, arc1r] + [-s for s in reversed(zone1)] + [arc1l])])
        # Cylinder 2 (above), counter-clockwise: zone left to right, right arc, top, left arc.
        c2 = geo.addPoint(0, R2, 0)
        p2 = [geo.addPoint(x, float(gap(x, R2)), 0) for x in x2]
        zone2 = [geo.addLine(p2[i], p2[i + 1]) for i in range(len(x2) - 1)]
        tr, tl = geo.addPoint(R2, R2, 0), geo.addPoint(-R2, R2, 0)
        arc2r, top = geo.addCircleArc(p2[-1], c2, tr), geo.addLine(tr, tl)
        arc2l = geo.addCircleArc(tl, c2, p2[0])
        cyl2 = geo.addPlaneSurface([geo.addCurveLoop(zone2 + [arc2r, top, arc2l])])
        for s in zone1 + zone2:
            geo.mesh.setTransfiniteCurve(s, 2)  # one element per segment: nodes = points
        geo.synchronize()

        _gmsh.physical(2, [cyl1], BASE, NAMES[BASE])
        _gmsh.physical(2, [cyl2], UPPER, NAMES[UPPER])
        _gmsh.physical(1, [bottom], FIXED, NAMES[FIXED])
        _gmsh.physical(1, [top], LOADED, NAMES[LOADED])
        _gmsh.physical(1, zone1, MASTER, NAMES[MASTER])
        _gmsh.physical(1, zone2, SLAVE, NAMES[SLAVE])
        near = 0.25 * w
        _gmsh.size_field(zone1 + zone2, 1, h, hf, near, near + 3 * (hf - h), points_per_curve=4)
        gmsh.model.mesh.generate(2)
        return info

    return _gmsh.generate(comm, "two_cylinders", model, gdim=2)
