"""The test examples in README.md and docs/ run as written, from any folder."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from tests.conftest import REPO

DOCUMENTS = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]


def documented_tests():
    """Python blocks that define a pytest test, by document."""
    found = []
    for document in DOCUMENTS:
        for block in re.findall(r"```python\n(.*?)```", document.read_text(encoding="utf-8"), re.S):
            if re.search(r"^def test_", block, re.M):
                found.append((document.name, block))
    return found


@pytest.mark.parametrize("document, block", documented_tests(), ids=lambda v: v if v.endswith(".md") else "")
def test_a_documented_test_runs_outside_the_repository(tmp_path, document, block):
    """Written into an empty folder and run by pytest there, the documented test passes."""
    (tmp_path / "test_documented.py").write_text(block, encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test_documented.py"],
                          cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
