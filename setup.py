"""Build the compiled module ``flexcontact._cpp`` with the project's CMake build.

Everything else (name, packages, the forms/ and meshes/ mapping) is in pyproject.toml. The
parallel level of the C++ build follows CMAKE_BUILD_PARALLEL_LEVEL (serial when unset).
"""
import os
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


class CMakeExtension(Extension):
    """An extension whose sources CMake knows; setuptools only needs its name."""

    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        # Put the module exactly where setuptools will look for it when it makes the wheel.
        target = Path(self.get_ext_fullpath(ext.name)).resolve()
        build = Path(self.build_temp).resolve() / "cmake"
        build.mkdir(parents=True, exist_ok=True)
        config = "Debug" if self.debug else "Release"
        configure = [
            "cmake", "-S", str(ROOT), "-B", str(build),
            f"-DCMAKE_BUILD_TYPE={config}",
            # The interpreter that runs pip is the one that will import the module.
            f"-DPython3_EXECUTABLE={sys.executable}",
            f"-DFLEXCONTACT_MODULE_DIR={target.parent}",
            "-DFLEXCONTACT_TESTS=OFF",
        ]
        configure += os.environ.get("FLEXCONTACT_CMAKE_ARGS", "").split()
        subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", str(build), "--target", "_cpp"], check=True)
        if not target.exists():
            raise RuntimeError(f"CMake did not produce {target}")


setup(ext_modules=[CMakeExtension("flexcontact._cpp")], cmdclass={"build_ext": CMakeBuild})
