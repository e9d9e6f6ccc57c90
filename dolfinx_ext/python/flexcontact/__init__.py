"""flexcontact: frictional contact and impact for FEniCSx by the condensed flexibility
(mixed) method of Feng & Touzot."""
from . import _cpp  # noqa: F401  (the compiled kernel and PETSc/MUMPS bridge)
from ._cpp import ConvergenceError, SolverOptions  # noqa: F401
from .problem import ContactInterface, ContactProblem, IncrementSummary  # noqa: F401
from .boundary import dirichlet  # noqa: F401
from .output import ResultWriter, results_folder, write_summary  # noqa: F401

__version__ = "0.1.0"
