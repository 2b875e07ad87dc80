"""The Python examples of python/README.md and of the repository's README run as written."""

from __future__ import annotations

import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]


def first_python_block(path: pathlib.Path) -> str:
    m = re.search(r"```python\n(.*?)```", path.read_text(), re.S)
    assert m is not None, path
    return m.group(1)


def test_readme_first_example_runs() -> None:
    code = first_python_block(ROOT / "python" / "README.md")
    assert len(code.splitlines()) <= 20
    exec(compile(code, "python/README.md", "exec"), {})


def test_root_readme_python_example_runs() -> None:
    code = first_python_block(ROOT / "README.md")
    exec(compile(code, "README.md", "exec"), {})
