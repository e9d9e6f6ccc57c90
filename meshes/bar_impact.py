"""Two 2D strips end to end for the bar impact demos: a striker and a target.

Geometry (m), the bar axis along x, the contact plane x = 0:

* striker (tag UPPER, slave): [0, length] × [0, height]; its left end is the slave surface
  (tag SLAVE);
* target (tag BASE, master): a rigid wall [−wall, 0] × [0, height] (``target="wall"``, one
  element thick: every node of it can be held by a Dirichlet condition on its cells) or an
  identical bar [−length, 0] × [0, height] (``target="bar"``); its right end is the master
  surface (tag MASTER).

Structured (transfinite) triangles, ``n`` elements along a bar and ``ny`` across, so the two
end faces carry matching nodes and, with ν = 0, a uniform axial motion stays exactly
one-dimensional (each column of nodes shares one x).
"""

from . import _check, _gmsh
from .tags import BASE, MASTER, NAMES, SLAVE, UPPER
from flexcontact.errors import InputError

TARGETS = ("wall", "bar")


def build(comm, length=1.0, height=0.05, n=50, ny=2, target="wall", wall=None):
    """Mesh on ``comm``; returns ``(mesh, cell_tags, facet_tags, info)``.

    Args:
        length, height: bar length and height (m).
        n, ny: elements along and across a bar.
        target: "wall" or "bar".
        wall: wall thickness (m); default one element length.

    ``info``: length, height, n, ny, h (element length), target, wall.
    """
    L = _check.positive("length", length)
    H = _check.positive("height", height)
    for name, value in (("n", n), ("ny", ny)):
        if not (isinstance(value, int) and value >= 1):
            raise InputError(f"{name}={value!r}: must be an integer >= 1")
    if target not in TARGETS:
        raise InputError(f"target={target!r}: must be one of {TARGETS}")
    h = L / n
    tw = _check.positive("wall", h if wall is None else wall)
    info = dict(length=L, height=H, n=n, ny=ny, h=h, target=target, wall=tw)

    def model():
        import gmsh
        geo = gmsh.model.geo

        def strip(x0, x1, nx):
            p = [geo.addPoint(x, y, 0) for x, y in [(x0, 0), (x1, 0), (x1, H), (x0, H)]]
            lines = [geo.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
            s = geo.addPlaneSurface([geo.addCurveLoop(lines)])
            for c, k in zip(lines, (nx, ny, nx, ny)):
                geo.mesh.setTransfiniteCurve(c, k + 1)
            geo.mesh.setTransfiniteSurface(s)
            return s, lines

        s_bar, l_bar = strip(0.0, L, n)
        x_t = -tw if target == "wall" else -L
        s_tgt, l_tgt = strip(x_t, 0.0, 1 if target == "wall" else n)
        geo.synchronize()
        _gmsh.physical(2, [s_tgt], BASE, NAMES[BASE])
        _gmsh.physical(2, [s_bar], UPPER, NAMES[UPPER])
        _gmsh.physical(1, [l_tgt[1]], MASTER, NAMES[MASTER])   # target's end at x = 0
        _gmsh.physical(1, [l_bar[3]], SLAVE, NAMES[SLAVE])     # striker's end at x = 0
        gmsh.model.mesh.generate(2)
        return info

    return _gmsh.generate(comm, "bar_impact", model, gdim=2)
