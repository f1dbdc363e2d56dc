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


DOCS = README.parent / "docs"


def test_every_python_example_of_the_docs_runs_in_their_build():
    """A ```python block of a page is either executed by `make docs` (markdown-exec's
    exec="on") or it is not an example; none is left to rot unexecuted."""
    idle = []
    for page in sorted(DOCS.rglob("*.md")):
        for m in re.finditer(r"^```python(.*)$", page.read_text(encoding="utf-8"), re.M):
            if 'exec="on"' not in m.group(1):
                idle.append(f"{page.relative_to(DOCS)}: ```python{m.group(1)}")
    assert not idle, "Python examples the docs build does not run:\n" + "\n".join(idle)


def test_docs_model_md_lists_every_numbered_section_where_it_is():
    """The code cites the model as `docs/model.md §N.M`: docs/model.md must list each numbered
    section of the explanation pages with a link to its page and anchor, and nothing else."""
    index = (DOCS / "model.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"\]\((explanation/[^)#]+)#(sec-[\d-]+)\)", index))
    present = set()
    for page in (DOCS / "explanation").rglob("*.md"):
        rel = page.relative_to(DOCS).as_posix()
        for anchor in re.findall(r"^#+ \d+(?:\.\d+)?\.? .*\{ #(sec-[\d-]+) \}$", page.read_text(encoding="utf-8"), re.M):
            present.add((rel, anchor))
    assert present, "no numbered sections found"
    assert listed == present, (sorted(present - listed), sorted(listed - present))
