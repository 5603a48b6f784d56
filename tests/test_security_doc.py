"""docs/security.md names, for each promise, the tests that prove it: every test it names
must exist, so the page cannot point at a test that was renamed or removed."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _defined_tests() -> set[str]:
    names: set[str] = set()
    for path in (ROOT / "tests").rglob("test_*.py"):
        names.update(re.findall(r"^\s*def (test_\w+)\(", path.read_text(), re.MULTILINE))
    return names


def _test_files() -> set[str]:
    return {path.name for path in (ROOT / "tests").rglob("test_*.py")}


def test_every_test_the_security_page_names_exists() -> None:
    text = (ROOT / "docs" / "security.md").read_text()
    named = set(re.findall(r"`(?:[\w/]+\.py)?(?:::)?(test_\w+)`", text))
    named |= set(re.findall(r"::(test_\w+)", text))
    assert len(named) > 50, "the page names the tests behind its promises"
    missing = sorted(named - _defined_tests())
    assert not missing, f"docs/security.md names tests that do not exist: {missing}"
    files = set(re.findall(r"`(?:tests/[\w/]+/)?(test_\w+\.py)", text))
    assert not sorted(files - _test_files()), sorted(files - _test_files())
