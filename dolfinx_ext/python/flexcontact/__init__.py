"""flexcontact: frictional contact and impact for FEniCSx by the condensed flexibility
(mixed) method of Feng & Touzot."""
# forms/ and meshes/ are top-level folders of the repository and the subpackages
# flexcontact.forms and flexcontact.meshes: the wheel maps them in (pyproject.toml), and a
# checkout registered by scripts/setup.sh finds them as an editable install would
# (dolfinx_ext/python/flexcontact_checkout.py).
from .petsc_comm import init_for_futures as _init_for_futures

_init_for_futures()  # before anything initialises PETSc: see petsc_comm.py
from . import _cpp  # noqa: F401  (the compiled kernel and PETSc/MUMPS bridge)
# Errors users catch, all under FlexcontactError (errors.py): bad input (InputError, a
# ValueError), a singular K (a body held by nothing), MUMPS or PETSc failing, no local solver
# converging (SolveErrors, RuntimeErrors).
from ._cpp import (ConvergenceError, MumpsError, PetscError, SingularStiffnessError,
                   SolverOptions)
from .errors import FlexcontactError, InputError, InputTypeError, SolveError
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
from .problem_files import load_problem

__version__ = "0.1.0"

__all__ = [
    "ContactInterface", "ContactProblem", "IncrementSummary", "SolverOptions",
    "ImpactProblem", "ImpactStepRecord",
    "RigidTarget", "ContactZoneWarning", "ContactZoneError",
    "dirichlet", "hold_body", "ResultWriter", "results_folder", "write_summary",
    "FlexibilityMethod", "SolverName", "FLEXIBILITY_METHODS", "SOLVER_NAMES", "Ordering",
    "ORDERINGS",
    "FlexcontactError", "InputError", "InputTypeError", "SolveError",
    "ConvergenceError", "SingularStiffnessError", "MumpsError", "PetscError",
    "NoEquilibriumError", "FreeModeWarning", "TippingWarning", "ContactMemoryError",
    "load_problem", "__version__",
]
