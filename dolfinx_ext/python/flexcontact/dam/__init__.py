"""A floating log and a concrete gravity dam: the scenario, the mesh, stage 1 (statics).

* :class:`DamScenario` (``scenario.py``) holds and checks every parameter;
* ``flexcontact.meshes.dam.build(comm, scenario)`` meshes it with named groups
  (``flexcontact.meshes.dam_tags``);
* :func:`solve_stage1` (``stage1.py``) solves the static state before the impact:
  self-weight, reservoir and tailwater pressure, the log held;
* :mod:`~flexcontact.dam.section` linearises the base section (heel and toe stresses) and
  finds peak stresses at an offset from a point.
"""
from .buoyancy import floating_draft_m, segment_area_m2, westergaard_added_mass_kg_m2
from .scenario import CONCRETE, ROCK, WOOD, DamScenario

__all__ = ["DamScenario", "CONCRETE", "ROCK", "WOOD", "floating_draft_m", "segment_area_m2",
           "westergaard_added_mass_kg_m2"]
