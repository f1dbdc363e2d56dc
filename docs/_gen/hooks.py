"""MkDocs hooks of the site (mkdocs.yml `hooks:`).

The error catalogue (docs/errors.md) quotes messages that contain matrix indices such as
`entry [1][5]`; outside a code span Markdown would read those as reference links. They are
escaped here, at build time, so the catalogue's entries stay as their owners write them.
"""
from __future__ import annotations

import re

_CODE = re.compile(r"(`+)(.+?)\1")
_INDEX_PAIR = re.compile(r"\[(-?\d+)\]\[(-?\d+)\]")


def _escape(line: str) -> str:
    out, last = [], 0
    for m in _CODE.finditer(line):
        out.append(_INDEX_PAIR.sub(r"\\[\1\\]\\[\2\\]", line[last:m.start()]))
        out.append(m.group(0))
        last = m.end()
    out.append(_INDEX_PAIR.sub(r"\\[\1\\]\\[\2\\]", line[last:]))
    return "".join(out)


def on_page_markdown(markdown: str, page, **kwargs) -> str:
    if page.file.src_uri != "errors.md":
        return markdown
    return "\n".join(_escape(line) for line in markdown.split("\n"))
