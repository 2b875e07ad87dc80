"""The first example of python/README.md runs as written."""

from __future__ import annotations

import pathlib
import re


def test_readme_first_example_runs() -> None:
    text = (pathlib.Path(__file__).resolve().parents[1] / "README.md").read_text()
    m = re.search(r"```python\n(.*?)```", text, re.S)
    assert m is not None
    code = m.group(1)
    assert len(code.splitlines()) <= 20
    exec(compile(code, "README.md", "exec"), {})
