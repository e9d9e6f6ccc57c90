"""What flexcontact runs on: versions, linear solvers, and the BLAS actually loaded."""
from __future__ import annotations

import platform
from pathlib import Path


def loaded_blas() -> list[str]:
    """Shared BLAS/LAPACK libraries mapped into this process (resolved through the
    alternatives links, so OpenBLAS shows even when loaded as libblas.so.3)."""
    found = set()
    try:
        for line in Path("/proc/self/maps").read_text().splitlines():
            path = line.split()[-1] if "/" in line else ""
            name = Path(path).name
            # Python extension wrappers (scipy's _fblas…) are not BLAS implementations.
            if any(k in name for k in ("blas", "lapack", "mkl")) and "-packages" not in path:
                found.add(str(Path(path).resolve()))
    except OSError:
        pass
    return sorted(found)


def describe() -> dict:
    import dolfinx
    import petsc4py
    from petsc4py import PETSc

    from . import __version__
    return {
        "flexcontact": __version__,
        "dolfinx": dolfinx.__version__,
        "petsc": ".".join(map(str, PETSc.Sys.getVersion())),
        "petsc4py": petsc4py.__version__,
        "mumps": PETSc.Sys.hasExternalPackage("mumps"),
        "blas": loaded_blas(),
        "python": platform.python_version(),
        "machine": f"{platform.machine()} {platform.system()} {platform.release()}",
    }
