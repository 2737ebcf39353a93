"""Package-wide rules (python-control style meta-tests): public API shape, lint, README and CI in step."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import wmrkit

ROOT = Path(__file__).resolve().parents[1]


def _public_modules():
    for info in pkgutil.walk_packages(wmrkit.__path__, prefix="wmrkit."):
        if not any(part.startswith("_") for part in info.name.split(".")):
            yield importlib.import_module(info.name)


def _public_functions():
    for module in _public_modules():
        for name, obj in vars(module).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
                continue
            if inspect.isfunction(obj):
                yield f"{module.__name__}.{name}", obj
            elif inspect.isclass(obj):
                for meth_name, meth in vars(obj).items():
                    if not meth_name.startswith("_") and inspect.isfunction(meth):
                        yield f"{module.__name__}.{name}.{meth_name}", meth


def test_no_public_function_takes_var_keyword():
    """House rule 8: no **kwargs in the public API (unknown keywords must fail loudly)."""
    offenders = [
        name for name, fn in _public_functions()
        if any(p.kind is p.VAR_KEYWORD for p in inspect.signature(fn).parameters.values())
    ]
    assert offenders == []


def test_every_public_function_has_a_docstring():
    missing = [name for name, fn in _public_functions() if not (fn.__doc__ or "").strip()]
    assert missing == []


def test_public_names_exist():
    for name in wmrkit.__all__:
        assert hasattr(wmrkit, name), name


def test_modules_stay_small():
    """House rule: one concept per module, about 400 lines at most (some slack for docstrings)."""
    sizes = {p.relative_to(ROOT).as_posix(): len(p.read_text().splitlines()) for p in (ROOT / "src").rglob("*.py")}
    assert {k: v for k, v in sizes.items() if v > 500} == {}


def test_readme_test_command_is_what_ci_runs():
    readme = (ROOT / "README.md").read_text()
    ci = (ROOT / ".ci" / "run").read_text()
    commands = re.findall(r"^(pip install .*&& pytest.*)$", readme, flags=re.M)
    assert commands, "README must show the test command"
    assert commands[0] in ci


def test_no_eval_of_user_text():
    sources = "\n".join(p.read_text() for p in (ROOT / "src").rglob("*.py"))
    assert not re.search(r"(?<![\w.])eval\(|(?<![\w.])exec\(|yaml\.load\(|sympify\(", sources)


@pytest.mark.skipif(shutil.which("ruff") is None and not Path(sys.executable).with_name("ruff").exists(),
                    reason="ruff not installed")
def test_ruff_clean():
    ruff = shutil.which("ruff") or str(Path(sys.executable).with_name("ruff"))
    out = subprocess.run([ruff, "check", "src", "tests", "benchmarks"], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr


def test_every_test_cited_by_the_errata_exists():
    """Each erratum names the test that proves the correction: that test must exist."""
    text = (ROOT / "docs" / "errata.md").read_text()
    cited, path = set(), None
    for full, name in re.findall(r"(tests/[\w/]+\.py)?::(\w+)", text):  # '::name' alone: the file cited before
        path = full or path
        if path is not None:
            cited.add((path, name))
    assert len(cited) > 30
    def defined(path: str, name: str) -> bool:
        return (ROOT / path).exists() and re.search(rf"^def {name}\b", (ROOT / path).read_text(), re.M) is not None

    missing = [f"{path}::{name}" for path, name in cited if not defined(path, name)]
    assert missing == []


def test_every_erratum_is_classified():
    """Issue 8: each erratum says what it is (thesis error, extraction artefact, missing qualification, extension)."""
    text = (ROOT / "docs" / "errata.md").read_text()
    entries = re.split(r"^### ", text, flags=re.M)[1:]
    classes = ("thesis error", "extraction artefact", "missing qualification", "wmrkit extension")
    unclassified = [e.splitlines()[0] for e in entries if not any(c in e.lower() for c in classes)]
    assert unclassified == []
