"""A griffe extension of the API reference: the docstrings' doctest examples (`>>>` lines and
their output) are shown as Python console code blocks, as doctest reads them, instead of as
running text; and Sphinx roles (``:class:`Settings` ``, ``:meth:`~phsplit.Solution.state` ``),
which Markdown does not know, are shown as the code names they stand for."""
from __future__ import annotations

import re

import griffe

_ROLE = re.compile(r":(?:py:)?(?:class|meth|func|attr|mod|obj|data|exc):`~?([^`]+)`")


def _fence(text: str) -> str:
    lines = text.split("\n")
    out: list[str] = []
    i = 0
    while i < len(lines):
        line = lines[i]
        stripped = line.lstrip()
        if stripped.startswith(">>>") and not (out and out[-1].lstrip().startswith("```")):
            indent = line[: len(line) - len(stripped)]
            block = []
            while i < len(lines) and lines[i].strip():
                block.append(lines[i][len(indent):] if lines[i].startswith(indent) else lines[i].lstrip())
                i += 1
            out.append(f"{indent}```pycon")
            out.extend(indent + b for b in block)
            out.append(f"{indent}```")
            continue
        out.append(line)
        i += 1
    return "\n".join(out)


class DoctestBlocks(griffe.Extension):
    def on_object(self, *, obj, **kwargs) -> None:  # griffe 1.x and 2.x
        if obj.docstring is None:
            return
        value = _ROLE.sub(r"`\1`", obj.docstring.value)
        if ">>>" in value:
            value = _fence(value)
        obj.docstring.value = value
