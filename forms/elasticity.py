"""Small-strain linear elasticity in UFL: strain, stress, stiffness form, stress measures.

A material argument is either a :class:`Material` (constants) or a pair ``(mu, lmbda)`` of
UFL expressions (Constants, DG0 Functions, ...) holding the shear modulus μ and the *3D*
Lamé constant λ in Pa. For ``kind="plane_stress"`` the pair is converted to the effective
λ* = 2μλ/(λ + 2μ) here, so the same fields serve every kind.
"""

import ufl
from ufl.domain import extract_unique_domain

from .material import Material, check_kind
from flexcontact.errors import InputError


def _lame(material, kind):
    """(μ, λ_kind) in Pa as floats or UFL expressions."""
    if isinstance(material, Material):
        return material.lame(kind)
    try:
        mu, lmbda = material
    except (TypeError, ValueError):
        raise InputError(
            f"material={material!r}: expected a Material or a pair (mu, lmbda)") from None
    if kind == "plane_stress":
        lmbda = 2.0 * mu * lmbda / (lmbda + 2.0 * mu)
    return mu, lmbda


def _check_dim(u, kind):
    check_kind(kind)
    d = u.ufl_shape[0] if len(u.ufl_shape) == 1 else None
    want = 3 if kind == "3d" else 2
    if d != want:
        raise InputError(
            f"kind={kind!r} needs a vector field of dimension {want}, got shape {u.ufl_shape}")


def epsilon(u):
    """Small strain ε(u) = sym(∇u) (dimensionless; u in m)."""
    return ufl.sym(ufl.grad(u))


def sigma(u, material, kind="plane_strain"):
    """In-plane (2D) or full (3D) Cauchy stress σ(u) = 2μ ε + λ tr(ε) I in Pa."""
    _check_dim(u, kind)
    mu, lmbda = _lame(material, kind)
    eps = epsilon(u)
    return 2.0 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(u.ufl_shape[0])


def stress_3x3(u, material, kind="plane_strain"):
    """Full 3×3 stress tensor in Pa; in 2D σ_zz = λ tr ε (plane strain) or 0 (plane stress)."""
    s = sigma(u, material, kind)
    if kind == "3d":
        return s
    if kind == "plane_strain":
        # ε_zz = 0 ⇒ σ_zz = λ tr(ε) = ν (σ_xx + σ_yy), with the 3D λ.
        _, lmbda = _lame(material, "plane_strain")
        szz = lmbda * ufl.tr(epsilon(u))
    else:
        szz = 0.0
    return ufl.as_matrix([[s[0, 0], s[0, 1], 0.0],
                          [s[1, 0], s[1, 1], 0.0],
                          [0.0, 0.0, szz]])


def von_mises(u, material, kind="plane_strain"):
    """Von Mises equivalent stress sqrt(3/2 s:s) in Pa, s the deviator of the 3×3 stress."""
    s3 = stress_3x3(u, material, kind)
    dev = s3 - ufl.tr(s3) / 3.0 * ufl.Identity(3)
    return ufl.sqrt(1.5 * ufl.inner(dev, dev))


def max_principal_stress(u, material, kind="plane_strain"):
    """Largest principal value of the 3×3 stress tensor in Pa (tension positive).

    In 2D this is max(in-plane σ₁, σ_zz): the out-of-plane stress is itself a principal value.
    In 3D the closed-form (trigonometric) eigenvalue of a symmetric 3×3 matrix is used.
    """
    if kind != "3d":
        s = sigma(u, material, kind)
        c = 0.5 * (s[0, 0] + s[1, 1])
        r = ufl.sqrt((0.5 * (s[0, 0] - s[1, 1])) ** 2 + s[0, 1] ** 2)
        szz = stress_3x3(u, material, kind)[2, 2]
        return ufl.max_value(c + r, szz)
    a = sigma(u, material, kind)
    q = ufl.tr(a) / 3.0
    dev = a - q * ufl.Identity(3)
    p = ufl.sqrt(ufl.inner(dev, dev) / 6.0)
    # A spherical stress (p = 0) would divide by zero; the floor makes B = 0 there, hence
    # r = 0 and the formula returns q, the correct (triple) eigenvalue.
    b = dev / ufl.max_value(p, 1e-300)
    r = ufl.max_value(ufl.min_value(0.5 * ufl.det(b), 1.0), -1.0)
    phi = ufl.acos(r) / 3.0
    return q + 2.0 * p * ufl.cos(phi)


def elasticity_form(u, v, materials, dx=None, kind="plane_strain", cell_tags=None):
    """Bilinear form a(u, v) = Σ_tag ∫ σ(u):ε(v) dx(tag) (J; u, v in m).

    Args:
        u, v: trial and test functions (vector, dimension 2 or 3).
        materials: ``{cell_tag: Material}``, or one Material / (mu, lmbda) pair for the whole
            domain.
        dx: a cell Measure; for a dict it must carry the cell tags as ``subdomain_data``.
            Built from ``cell_tags`` if omitted.
        kind: "plane_strain", "plane_stress" or "3d".
        cell_tags: DOLFINx MeshTags of the cells; also used to check (collectively) that
            every tag present in the mesh has a material.
    """
    _check_dim(u, kind)
    if dx is None:
        dx = ufl.Measure("dx", domain=extract_unique_domain(u), subdomain_data=cell_tags)
    if not isinstance(materials, dict):
        return ufl.inner(sigma(u, materials, kind), epsilon(v)) * dx
    if not materials:
        raise InputError("materials={}: need at least one cell tag -> Material")
    if cell_tags is None and dx.subdomain_data() is None:
        raise InputError(
            "materials is a dict but neither dx has subdomain_data nor cell_tags was given")
    if cell_tags is not None:
        _check_tags_covered(cell_tags, materials)
    forms = [ufl.inner(sigma(u, m, kind), epsilon(v)) * dx(tag)
             for tag, m in sorted(materials.items())]
    return sum(forms[1:], forms[0])


def _check_tags_covered(cell_tags, materials):
    """Raise ValueError on every rank if some cell tag of the mesh has no material."""
    import numpy as np
    from flexcontact import compat
    local = set(int(t) for t in np.unique(cell_tags.values))
    comm = compat.tags_comm(cell_tags)
    present = set().union(*comm.allgather(local))
    missing = sorted(present - set(materials))
    if missing:
        raise InputError(
            f"cell tags {missing} have no material (materials given for {sorted(materials)})")


def lame_fields(msh, cell_tags, materials, kind="3d"):
    """Piecewise-constant (DG0) fields (μ, λ) in Pa from ``{cell_tag: Material}``.

    λ is the 3D Lamé constant; pass the pair to :func:`sigma` with any ``kind``. Cells
    without a tag raise ValueError (on every rank), so a forgotten body cannot silently get
    zero stiffness. ``kind`` is accepted for symmetry with the other functions only.
    """
    import numpy as np
    import dolfinx.fem as fem
    from flexcontact import compat
    check_kind(kind)
    _check_tags_covered(cell_tags, materials)
    V0 = compat.scalar_space(msh, "DG", 0)
    mu, lmbda = fem.Function(V0, name="mu_Pa"), fem.Function(V0, name="lambda_Pa")
    tdim = msh.topology.dim
    n_local = msh.topology.index_map(tdim).size_local + msh.topology.index_map(tdim).num_ghosts
    seen = np.zeros(n_local, dtype=bool)
    for tag, m in materials.items():
        cells = cell_tags.indices[cell_tags.values == tag]
        seen[cells] = True
        dofs = compat.cell_dofs(V0).reshape(-1)  # DG0: one dof per cell, cell order
        mu.x.array[dofs[cells]] = m.mu_Pa
        lmbda.x.array[dofs[cells]] = m.lmbda_Pa
    n_owned = msh.topology.index_map(tdim).size_local
    n_missing = msh.comm.allreduce(int(np.count_nonzero(~seen[:n_owned])))
    if n_missing:
        raise InputError(f"{n_missing} cells carry no cell tag, so no material")
    mu.x.scatter_forward()
    lmbda.x.scatter_forward()
    return mu, lmbda
