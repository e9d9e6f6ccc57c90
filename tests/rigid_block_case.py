"""A steel block (hertz2d without its cylinder) pressed by a rigid circle through one contact
interface: the candidate-zone guard's case, with contact and with crushing."""
import ufl
from mpi4py import MPI

import flexcontact as fc
from demo_runner import A_TARGET, R_HERTZ, STEEL
from flexcontact import compat, forms
from flexcontact.meshes import hertz2d, tags

STEEL_M = forms.Material(E_Pa=STEEL["E_Pa"], nu=STEEL["nu"], name="steel")


def rigid_block(zone_factor, name, **interface):
    """(problem, circle, geo): the block under a rigid circle of radius R_HERTZ; candidate
    zone w = zone_factor·a; ``interface``: ContactInterface keywords (zone_edge, ...)."""
    msh, _, facets, geo = hertz2d.build(MPI.COMM_WORLD, R=R_HERTZ, a_expected=A_TARGET,
                                        zone_factor=zone_factor, with_cylinder=False)
    V = compat.vector_space(msh)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = forms.elasticity_form(u, v, STEEL_M, ufl.dx(domain=msh), "plane_strain")
    fixed, _ = fc.dirichlet(V, facets, tags.FIXED)
    circle = fc.RigidTarget("circle", point_m=(0.0, R_HERTZ), radius_m=R_HERTZ)
    problem = fc.ContactProblem(a, None, fixed, fc.ContactInterface(
        facets, tags.MASTER, circle, 0.0, name=name, **interface))
    return problem, circle, geo
