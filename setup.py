"""`pip install .` of the Python module aerocal (tools/python/README.md "Packaging").

The extension is built by the project's own CMake (the same libraries as the `aerocal` command,
Debian's pybind11; nothing is downloaded): configure AEROCAL_BUILD_DIR (default: build/ of this
checkout, so an existing tools/setup.sh build is reused), build the target `aerocal_python`, and
package the folder it fills, build/python/aerocal. There is no pyproject.toml on purpose: with one,
pip builds in an isolated environment and downloads setuptools, which an offline machine cannot.
"""
import os
import re
import shutil
import subprocess

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def project_version():
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        return re.search(r"project\(aerocal VERSION ([0-9.]+)", f.read()).group(1)


class CMakeBuild(build_ext):
    """Builds `aerocal_python` with CMake and copies the package into the wheel's tree."""

    def build_extension(self, ext):
        build_dir = os.environ.get("AEROCAL_BUILD_DIR", os.path.join(ROOT, "build"))
        if not os.path.exists(os.path.join(build_dir, "CMakeCache.txt")):  # else: as configured
            configure = ["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release"]
            if shutil.which("ccache"):
                configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
            subprocess.run(configure, check=True, stdout=subprocess.DEVNULL)
        subprocess.run(["cmake", "--build", build_dir, "--target", "aerocal_python",
                        "-j", str(os.cpu_count() or 1)], check=True)
        package = os.path.join(build_dir, "python", "aerocal")
        target = os.path.join(self.build_lib, "aerocal")
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(package, target)
        # setuptools expects the extension where get_ext_fullpath says; the copy put it there.
        built = [f for f in os.listdir(target) if f.startswith("_aerocal") and f.endswith(".so")]
        if len(built) != 1:
            raise RuntimeError(f"{package}: expected one _aerocal*.so, found {built}")
        os.replace(os.path.join(target, built[0]), self.get_ext_fullpath(ext.name))


setup(
    name="aerocal",
    version=project_version(),
    description="Calibration of large-format and multi-head aerial cameras (Python module)",
    packages=["aerocal"],
    package_dir={"aerocal": "tools/python/aerocal"},
    package_data={"aerocal": ["__init__.pyi", "py.typed"]},
    ext_modules=[Extension("aerocal._aerocal", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    python_requires=">=3.9",
    install_requires=["numpy"],
    zip_safe=False,
    # setuptools' own build folders, kept apart from the CMake tree's files
    options={"build": {"build_base": "build/setuptools"}, "egg_info": {"egg_base": "build"}},
)
