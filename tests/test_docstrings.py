"""Every example in a docstring runs and gives what it shows: the examples are the
documentation a user reads first (``help(stabilize)``), so one that drifted from the code
would teach the wrong thing."""

import doctest
import importlib
import pkgutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def modules_with_examples() -> list[str]:
    names = []
    for package in ("rotation", "flow", "stabilize"):
        for info in pkgutil.walk_packages([str(ROOT / package)], prefix=f"{package}."):
            source = ROOT / (
                info.name.replace(".", "/") + ("/__init__.py" if info.ispkg else ".py")
            )
            if ">>> " in source.read_text():
                names.append(info.name)
        if ">>> " in (ROOT / package / "__init__.py").read_text():
            names.append(package)
    return sorted(names)


@pytest.mark.parametrize("name", modules_with_examples())
def test_the_examples_in_the_docstrings_run(name):
    found = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert found.attempted > 0 and found.failed == 0
