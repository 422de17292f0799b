"""The packages' dependencies point one way, downwards.

Each room of ``stabilize`` has a rank; a module may import from its own room or from a
room of lower rank, never from one above it or beside it (imports inside functions
count too). ``rotation`` and ``flow`` import nothing from ``stabilize``.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RANK = {
    "__main__": 10,  # python -m stabilize: the command line, and nothing else
    "cli": 9,
    "batch": 8,
    "pipeline": 7,
    "evaluate": 7,
    "shutter": 6,
    "gyro": 5,
    "path": 5,  # the plan follows the motion: its shots are those of motion.cuts
    "motion": 4,
    "warp": 3,
    "synth": 2,
    "settings": 2,
    "progress": 2,
    "video": 1,
    "lazy": 0,
}


def imports(path: Path) -> list[str]:
    names = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.append(node.module)
        elif isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
    return names


def room(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if parts[0] == "stabilize" and len(parts) > 1 else None


STABILIZE = sorted((ROOT / "stabilize").rglob("*.py"))


@pytest.mark.parametrize("path", STABILIZE, ids=lambda p: str(p.relative_to(ROOT)))
def test_a_module_imports_only_from_its_room_or_below(path):
    rel = path.relative_to(ROOT / "stabilize")
    if rel.name == "__init__.py" and len(rel.parts) == 1:
        return  # the public API names every stage
    own = rel.parts[0].removesuffix(".py")
    assert own in RANK, f"{rel}: a room without a rank"
    for module in imports(path):
        other = room(module)
        if other is None or other == own:
            continue
        assert other in RANK, f"{rel} imports {module}: a room without a rank"
        assert RANK[other] < RANK[own], f"{rel} ({own}) imports {module} ({other}) from above"


@pytest.mark.parametrize("package", ["rotation", "flow"])
def test_the_estimator_and_the_flow_know_no_video(package):
    for path in sorted((ROOT / package).rglob("*.py")):
        assert not any(m.split(".")[0] == "stabilize" for m in imports(path)), path
