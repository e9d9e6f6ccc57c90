"""flexcontact: frictional contact and impact for FEniCSx by the condensed flexibility
(mixed) method of Feng & Touzot."""
from pathlib import Path as _Path

# forms/ and meshes/ sit at the top of a source checkout (README, "Layout") and inside
# the package once installed (pyproject.toml maps them). Run from a checkout, let the
# subpackages flexcontact.forms and flexcontact.meshes be found there.
_checkout = _Path(__file__).resolve().parents[3]
if not (_Path(__file__).parent / "forms").is_dir() and (_checkout / "forms" / "elasticity.py").is_file():
    __path__.append(str(_checkout))  # noqa: F821 (a package's own __path__)
from .petsc_comm import init_for_futures as _init_for_futures

_init_for_futures()  # before anything initialises PETSc: see petsc_comm.py
from . import _cpp  # noqa: F401  (the compiled kernel and PETSc/MUMPS bridge)
# Errors users catch: a singular K (a body held by nothing), MUMPS or PETSc failing, no local
# solver converging. All four are RuntimeErrors.
from ._cpp import (ConvergenceError, MumpsError, PetscError, SingularStiffnessError,
                   SolverOptions)
from .boundary import dirichlet, hold_body
from .names import FLEXIBILITY_METHODS, ORDERINGS, SOLVER_NAMES, FlexibilityMethod, Ordering, \
    SolverName
from .output import ResultWriter, results_folder, write_summary
from .problem import (ContactInterface, ContactProblem, ContactZoneError, ContactZoneWarning,
                      IncrementSummary)
from .rigid import RigidTarget
from .floating import FreeModeWarning, NoEquilibriumError, TippingWarning
from .dynamics import ImpactProblem, ImpactStepRecord
from .memory import ContactMemoryError

__version__ = "0.1.0"

__all__ = [
    "ContactInterface", "ContactProblem", "IncrementSummary", "SolverOptions",
    "ImpactProblem", "ImpactStepRecord",
    "RigidTarget", "ContactZoneWarning", "ContactZoneError",
    "dirichlet", "hold_body", "ResultWriter", "results_folder", "write_summary",
    "FlexibilityMethod", "SolverName", "FLEXIBILITY_METHODS", "SOLVER_NAMES", "Ordering",
    "ORDERINGS",
    "ConvergenceError", "SingularStiffnessError", "MumpsError", "PetscError",
    "NoEquilibriumError", "FreeModeWarning", "TippingWarning", "ContactMemoryError",
    "__version__",
]
