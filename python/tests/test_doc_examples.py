"""The documentation's examples run as tests, so it cannot drift from the code: the runnable
examples in the docstrings of the public numerics modules (doctest), and the README's Python
example. The pages of the documentation site run theirs in `make docs` (markdown-exec)."""
from __future__ import annotations

import doctest
import re
from pathlib import Path

import pytest

import phsplit
from phsplit import events, results, rigid_body, so3, special

README = Path(__file__).resolve().parents[2] / "README.md"


@pytest.mark.parametrize("module", [special, rigid_body, so3, results, events, phsplit], ids=lambda m: m.__name__)
def test_docstring_examples_run(module):
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    assert result.attempted > 0, f"{module.__name__} has no examples"
    assert result.failed == 0


@pytest.mark.parametrize(
    "func",
    [special.ellipj, special.ellipk, special.ellipkinc, special.ellipkm1, so3.exp, so3.log, so3.euler_zyx,
     so3.from_euler_zyx, so3.quaternion, so3.from_quaternion, rigid_body.FreeRigidBody.momentum,
     rigid_body.FreeRigidBody.flow, rigid_body.FreeRigidBody.period],
    ids=lambda f: f.__qualname__,
)
def test_every_public_function_has_an_example(func):
    assert ">>>" in (func.__doc__ or ""), f"{func.__qualname__} has no runnable example"


def _readme_python_blocks() -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", README.read_text(encoding="utf-8"), re.S | re.M)


def test_the_readme_example_runs(tmp_path, monkeypatch):
    blocks = _readme_python_blocks()
    assert blocks, "the README has no Python example"
    monkeypatch.chdir(tmp_path)  # anything an example writes stays out of the repository
    for i, code in enumerate(blocks):
        exec(compile(code, f"README.md, Python example {i + 1}", "exec"), {"__name__": "__readme__"})


def test_the_readme_stays_short_and_shows_the_two_commands():
    text = README.read_text(encoding="utf-8")
    assert len(text.encode("utf-8")) <= 8192
    assert "make run" in text and "make test" in text
    assert "docs/figures/fig2.png" in text
