"""ament_python package: `colcon build` installs the console scripts under lib/mount_twin, the
ament index marker, package.xml, config/, launch/ and bags/ under share/mount_twin."""

import os
import site
import subprocess
import sys
from glob import glob

from setuptools import find_packages, setup
from setuptools.command.install import install

PACKAGE = "mount_twin"


class InstallAndWarmUp(install):
    """`setup.py install` (what `colcon build` runs), then `mount-twin warm-up` on the installed
    copy, so numba's kernel cache sits beside the installed sources and the first `ros2 run` or
    replay starts in seconds instead of compiling for 20-60 s. Skipped for staged installs (a
    wheel or a distribution package: `--root`) and with MOUNT_TWIN_NO_WARM_UP=1."""

    def run(self) -> None:
        super().run()
        if self.root or os.environ.get("MOUNT_TWIN_NO_WARM_UP") == "1":
            return
        scenes = [os.path.abspath(p) for p in sorted(glob("config/*.scene.yaml"))]
        lib = os.path.abspath(self.install_lib)
        # `python -S`: no site .pth files, so an editable install of this package elsewhere (its
        # import hook outranks PYTHONPATH) cannot shadow the installed copy being warmed; the
        # site directories are given back through PYTHONPATH, after the install.
        paths = [lib, *site.getsitepackages(), site.getusersitepackages()]
        env = {
            **os.environ,
            "PYTHONPATH": os.pathsep.join([*paths, os.environ.get("PYTHONPATH", "")]),
        }
        print(f"mount_twin: compiling kernels into {lib} (warm-up, 20-60 s)", flush=True)
        check = (
            "import sys, mount_twin.cli as c\n"
            f"if not c.__file__.startswith({lib!r}):\n"
            "    sys.exit('mount_twin: warm-up would warm ' + c.__file__ + ', not the install')\n"
            "sys.exit(c.main(sys.argv[1:]))"
        )
        subprocess.run(
            [sys.executable, "-S", "-c", check, "warm-up", *scenes], cwd=lib, env=env, check=True
        )


setup(
    name=PACKAGE,
    version="0.1.0",
    packages=find_packages(include=[PACKAGE, f"{PACKAGE}.*"]),
    package_data={PACKAGE: ["py.typed"]},  # PEP 561: the package ships its type hints
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
        "numba>=0.58",
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
        ],
        "plot": ["matplotlib>=3.6"],
        "sweep": ["dask[distributed]>=2024.1"],
        # bench/peers.py's MuJoCo peer (measured with mujoco 4.0.0)
        "bench": ["mujoco>=4.0,<5"],
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
    cmdclass={"install": InstallAndWarmUp},
    zip_safe=False,  # numba caches the compiled kernels beside the installed sources
    maintainer="mount_twin maintainers",
    maintainer_email="mount_twin@example.com",
    description="Real-time digital twin of a rigid machine on compliant mounts",
    license="BSD-3-Clause",
    tests_require=["pytest"],
    entry_points={
        "console_scripts": [
            "mount_twin_node = mount_twin.ros.node:main",
            "mount-twin = mount_twin.cli:main",
        ],
    },
)
