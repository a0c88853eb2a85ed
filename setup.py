"""ament_python package: `colcon build` installs the console scripts under lib/mount_twin, the
ament index marker, package.xml, config/, launch/ and bags/ under share/mount_twin; both it and
`pip install` compile the C++17 core (src/core, pybind11) into mount_twin/_core: nothing
compiles at run time. Needs a C++17 compiler (g++ ≥ 9 or clang ≥ 10) and Python's headers."""

import importlib.util
import os
from concurrent.futures import ThreadPoolExecutor
from glob import glob

from setuptools import Extension, find_packages, setup
from setuptools.command.build_ext import build_ext

PACKAGE = "mount_twin"
_spec = importlib.util.spec_from_file_location("core_sources", f"{PACKAGE}/core_sources.py")
core_sources = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(core_sources)
"""mount_twin/core_sources.py, loaded by path (the package's own imports need numpy)."""
CORE_SOURCES = sorted(["src/core/module.cpp", *glob("src/core/*/bind.cpp")])
"""The compiled core's translation units: the module and one binding file per area (each
includes the header-only code it binds)."""


def pybind11_include() -> str:
    """pybind11's headers: from its Python package (pip's build isolation installs it from
    pyproject.toml), else the system's (`pybind11-dev`, rosdep key `pybind11-dev`, for
    `colcon build`)."""
    try:
        import pybind11
    except ImportError:
        for prefix in ("/usr/include", "/usr/local/include"):
            if os.path.isfile(os.path.join(prefix, "pybind11", "pybind11.h")):
                return prefix
        msg = (
            "mount_twin needs pybind11 to build its core: pip install pybind11, "
            "or apt/rosdep pybind11-dev"
        )
        raise SystemExit(msg) from None
    return pybind11.get_include()


class ParallelBuildExt(build_ext):
    """build_ext compiling the core's translation units in parallel, one per core (setuptools
    runs one extension's sources one after another), so `pip install` and `colcon build`
    build it in well under 90 s on 2 cores."""

    def build_extensions(self) -> None:
        serial = self.compiler.compile

        def compile_each(sources: list[str], *args: object, **kwargs: object) -> list[str]:
            with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
                parts = pool.map(lambda src: serial([src], *args, **kwargs), sources)
                return [obj for objs in parts for obj in objs]

        self.compiler.compile = compile_each
        super().build_extensions()


CORE = Extension(
    f"{PACKAGE}._core_ext",
    sources=CORE_SOURCES,
    include_dirs=["src/core", pybind11_include()],
    depends=sorted(glob("src/core/**/*.hpp", recursive=True)),
    language="c++",
    # the sources' fingerprint: `mount_twin._core` refuses a build older than src/core
    define_macros=[("MT_SOURCE_SHA256", f'"{core_sources.fingerprint()}"')],
    # -O3 without -ffast-math and without fused multiply-adds: IEEE arithmetic in the order
    # written, the same bits on every machine; no -march: the wheel runs on any x86-64/arm64.
    extra_compile_args=[
        "-std=c++17",
        "-O3",
        "-g0",
        "-ffp-contract=off",
        "-fno-math-errno",
        "-fvisibility=hidden",
        "-Wall",
        "-Wextra",
    ],
)


setup(
    name=PACKAGE,
    version="0.1.0",
    packages=find_packages(include=[PACKAGE, f"{PACKAGE}.*"]),
    # PEP 561: the package ships its type hints, the compiled core's stubs among them
    package_data={PACKAGE: ["py.typed", "_core_ext.pyi"]},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (
            f"share/{PACKAGE}/config",
            sorted(
                glob("config/*.yaml")
                + glob("config/*.xml")
                + glob("config/*.json")
                + glob("config/*.csv")
            ),
        ),
        (f"share/{PACKAGE}/launch", glob("launch/*.launch.py")),
        *((f"share/{PACKAGE}/{d}", glob(f"{d}/*")) for d in sorted(glob("bags/*"))),
    ],
    python_requires=">=3.10",
    install_requires=[
        "numpy>=1.24",
        "scipy>=1.10",
        "PyYAML>=6",
        "tqdm>=4.60",
        "rosbags>=0.11,<0.12",
    ],
    extras_require={
        "test": [
            "pytest>=7",
            "pytest-xdist>=3",  # the README's test command runs on two workers
            "ruff>=0.5",
            "hypothesis>=6.100",
            "matplotlib>=3.6",
            "dask[distributed]>=2024.1",
            "pyyeti>=1.4.7",  # test_srs holds the SRS to pyyeti.srs.srs
            "mujoco>=4.0,<5",  # test_mujoco_peer: the peer poses the twin's problem
            "mcap>=1.1,<2",  # test_mcap_io: the MCAP project's reader checks the bags we write
        ],
        "plot": ["matplotlib>=3.6"],
        "sweep": ["dask[distributed]>=2024.1"],
        # bench/peers.py's MuJoCo peer (measured with mujoco 4.0.0; numba compiles its callback)
        "bench": ["mujoco>=4.0,<5", "numba>=0.58"],
        # Jazzy's rclpy and message packages from the package registry, for a machine without a
        # ROS install (a sourced Jazzy has them: do not install a second rclpy there). The
        # node reaches into rclpy 7.x in one module (ros/rclpy_private.py): pinned.
        "ros": [
            "ros-jazzy-rclpy[fastrtps]>=7.1,<8",
            "ros-jazzy-sensor-msgs",
            "ros-jazzy-geometry-msgs",
            "ros-jazzy-diagnostic-msgs",
            "ros-jazzy-std-msgs",
        ],
    },
    ext_modules=[CORE],
    cmdclass={"build_ext": ParallelBuildExt},
    zip_safe=False,
    maintainer="mount_twin maintainers",
    maintainer_email="mount_twin@example.com",
    description="Real-time digital twin of a rigid machine on compliant mounts",
    license="BSD-3-Clause",
    tests_require=["pytest"],
    entry_points={
        "console_scripts": [
            "mount_twin_node = mount_twin.ros.start:main",
            "mount-twin = mount_twin.cli:main",
        ],
    },
)
