"""The layout is the architecture (README "How the code is laid out"): these tests keep it so.

- the import contracts of ``pyproject.toml`` hold, and each kind of forbidden import breaks them
  (checked on a copy of the packages with one bad import added);
- no file over 400 lines in the parts of the system, no function over 60 lines anywhere;
- every function the equation table of docs/architecture.md names exists.
"""

from __future__ import annotations

import ast
import importlib
import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from tests.teamrun import limit

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("model", "protocol", "runtime", "agents", "coordinator", "logger", "simulator", "anicov")
SIZE_LIMITED = ("model", "protocol", "runtime", "agents", "coordinator", "logger", "simulator")
MAX_FILE_LINES = 400
MAX_FUNCTION_LINES = 60
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")


def lint_imports(root: Path) -> subprocess.CompletedProcess[str]:
    environment = os.environ | {"PYTHONPATH": str(root)}
    return subprocess.run(
        [str(LINT_IMPORTS), "--no-cache"],
        cwd=root,
        env=environment,
        capture_output=True,
        text=True,
        timeout=limit(120),
    )


def sources(packages: tuple[str, ...]) -> list[Path]:
    return sorted(path for package in packages for path in (ROOT / package).rglob("*.py"))


def test_the_packages_of_the_contracts_are_the_packages_installed():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert sorted(project["tool"]["setuptools"]["packages"]["find"]["include"]) == sorted(f"{p}*" for p in PACKAGES)
    assert sorted(project["tool"]["importlinter"]["root_packages"]) == sorted(PACKAGES)


def test_the_import_contracts_are_kept():
    result = lint_imports(ROOT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


@pytest.mark.parametrize(
    ("module", "bad_import", "broken"),
    [
        ("model/paper/geometry.py", "import zenoh", "model is not allowed to import zenoh"),
        ("model/paper/control.py", "import subprocess", "model is not allowed to import subprocess"),
        ("model/paper/sensing.py", "import model.world.ground", "model.paper is not allowed to import model.world"),
        ("model/world/clearance.py", "import model.safety.safety", "model.world is not allowed to import model.safety"),
        ("model/step.py", "import model.controllers.anicov", "model.step is not allowed to import model.controllers"),
        (
            "agents/node.py",
            "import model.controllers.anicov.lane_planner",
            "agents is not allowed to import model.controllers.anicov",
        ),
        ("model/controllers/paper.py", "import model.controllers.anicov", "model.controllers.paper is not allowed"),
        ("model/step.py", "import protocol.keys", "model is not allowed to import protocol"),
        ("agents/robot.py", "import coordinator.node", "agents is not allowed to import coordinator"),
        ("logger/replay.py", "import agents.robot", "logger is not allowed to import agents"),
        ("protocol/keys.py", "import runtime.lifecycle", "protocol is not allowed to import runtime"),
        ("coordinator/node.py", "import anicov.engine", "coordinator is not allowed to import anicov"),
        ("anicov/secure.py", "import anicov.launch", "No cycles are allowed in anicov"),
    ],
)
def test_a_forbidden_import_breaks_the_contracts(tmp_path, module, bad_import, broken):
    for package in PACKAGES:
        shutil.copytree(ROOT / package, tmp_path / package, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    if broken.startswith("No cycles"):
        # A cycle needs both directions: anicov.launch imports anicov.secure already (--secure).
        assert "anicov.secure" in (ROOT / "anicov/launch.py").read_text()
    with open(tmp_path / module, "a", encoding="utf-8") as source:
        source.write(f"\n{bad_import}  # noqa: E402, F401\n")
    result = lint_imports(tmp_path)
    assert result.returncode != 0
    assert broken in result.stdout, result.stdout


@pytest.mark.parametrize("path", sources(SIZE_LIMITED), ids=lambda path: str(path.relative_to(ROOT)))
def test_no_file_of_the_system_is_over_400_lines(path):
    lines = path.read_text(encoding="utf-8").count("\n")
    assert lines <= MAX_FILE_LINES, f"{path.relative_to(ROOT)} has {lines} lines; split it by job"


def long_functions(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [
        f"{node.name} ({node.end_lineno - node.lineno + 1} lines, from line {node.lineno})"
        for node in ast.walk(tree)
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
        and node.end_lineno is not None
        and node.end_lineno - node.lineno + 1 > MAX_FUNCTION_LINES
    ]


@pytest.mark.parametrize("package", [*PACKAGES, "bench"])
def test_no_function_is_over_60_lines(package):
    too_long = {str(path.relative_to(ROOT)): long_functions(path) for path in sources((package,))}
    assert {path: names for path, names in too_long.items() if names} == {}


def readme_section(title: str) -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    start = text.index(f"## {title}\n")
    end = text.find("\n## ", start + 1)
    return text[start : end if end >= 0 else None]


def equation_table_names() -> list[str]:
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = text[text.index("## Where each part of the paper lives\n") :]
    table = section[section.index("| paper | what it is | function |") :]
    return re.findall(r"`((?:model|protocol|runtime|agents|coordinator|logger|simulator|anicov)(?:\.\w+)+)`", table)


def test_the_equation_table_names_many_functions():
    names = equation_table_names()
    assert len(names) >= 20
    assert any(name.startswith("model.paper.control.") for name in names)


@pytest.mark.parametrize("dotted", equation_table_names())
def test_every_function_of_the_equation_table_exists(dotted):
    parts = dotted.split(".")
    for split in range(len(parts) - 1, 0, -1):
        try:
            target = importlib.import_module(".".join(parts[:split]))
        except ModuleNotFoundError:
            continue
        for attribute in parts[split:]:
            target = getattr(target, attribute)
        break
    else:
        pytest.fail(f"no module in {dotted}")
    assert callable(target), f"{dotted} is not a function or class"
    assert (target.__doc__ or "").strip(), f"{dotted} has no docstring saying what it computes"


def test_the_layout_table_names_every_folder_of_the_system():
    section = readme_section("How the code is laid out")
    for package in PACKAGES:
        assert f"| `{package}/` |" in section, package
