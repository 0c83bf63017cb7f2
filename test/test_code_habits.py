"""The habits of ../shared/STYLE.md that a machine can check (core tier, no master): warnings are
errors on every C++ target, cores know nothing of ROS communication, node wrappers stay thin,
every package has a README. `make test` also runs ruff (lint and format) over all Python."""

import glob
import os
import re

import pytest

WORKSPACE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SRC = os.path.join(WORKSPACE, "src")
PACKAGES = sorted(
    os.path.basename(os.path.dirname(p)) for p in glob.glob(os.path.join(SRC, "*", "package.xml"))
)
CPP_PACKAGES = [
    p for p in PACKAGES if glob.glob(os.path.join(SRC, p, "**", "*.cpp"), recursive=True)
]
ROS_IN_CORE = re.compile(r"ros/ros\.h|NodeHandle|ROS_(INFO|WARN|ERROR|DEBUG)|ros::")
MAX_NODE_LINES = 350


def _read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


@pytest.mark.parametrize("package", CPP_PACKAGES)
def test_warnings_are_errors_on_every_cpp_target(package):
    text = _read(os.path.join(SRC, package, "CMakeLists.txt"))
    # add_compile_options before the first target covers every target of the package, the
    # gtest targets included; a target-only option would miss new ones.
    opts = text.find("add_compile_options(-Wall -Wextra -Werror)")
    first = min(
        (
            i
            for i in (
                text.find("add_library("),
                text.find("add_executable("),
                text.find("catkin_add_gtest("),
            )
            if i >= 0
        ),
        default=len(text),
    )
    assert 0 <= opts < first, (
        "%s/CMakeLists.txt: add_compile_options(-Wall -Wextra -Werror) "
        "before the first target" % package
    )


@pytest.mark.parametrize("package", CPP_PACKAGES)
def test_cpp_cores_know_nothing_of_ros(package):
    offenders = [
        path
        for path in glob.glob(os.path.join(SRC, package, "src", "core", "*.[ch]pp"))
        + glob.glob(os.path.join(SRC, package, "include", package, "*.hpp"))
        if ROS_IN_CORE.search(_read(path))
    ]
    assert not offenders, offenders


def test_node_wrappers_are_thin():
    big = [
        "%s: %d lines" % (os.path.relpath(p, WORKSPACE), n)
        for p in glob.glob(os.path.join(SRC, "*", "src", "node", "*.[ch]pp"))
        if (n := _read(p).count("\n")) > MAX_NODE_LINES
    ]
    assert not big, "node wrappers translate and wire; move logic into the core: %s" % big


def test_python_cores_get_ros_injected():
    """rospy only in the node-side modules (ros_*, run_*, cli) and in clients of ROS APIs."""
    allowed = {"ros_rig.py", "ros_config.py", "ros_session.py", "cli.py", "sim_rig.py"}
    allowed |= {"run_batch.py", "run_calibrate.py", "run_teach.py"}
    src = os.path.join(SRC, "rascal_tasks", "src", "rascal_tasks")
    offenders = [
        os.path.relpath(p, WORKSPACE)
        for p in glob.glob(os.path.join(src, "**", "*.py"), recursive=True)
        if os.path.basename(p) not in allowed
        and re.search(r"^\s*(import rospy|from rospy)", _read(p), re.M)
    ]
    offenders += [
        os.path.relpath(p, WORKSPACE)
        for p in glob.glob(
            os.path.join(SRC, "rascal_workcell", "src", "**", "*.py"), recursive=True
        )
        if re.search(r"^\s*(import rospy|from rospy)", _read(p), re.M)
    ]
    assert not offenders, offenders


@pytest.mark.parametrize("package", PACKAGES)
def test_every_package_has_a_readme_with_build_and_usage(package):
    path = os.path.join(SRC, package, "README.md")
    assert os.path.exists(path)
    text = _read(path)
    assert re.search(r"^(## )?Build and test", text, re.M), path
