"""tools/fetch_test_data.py (inside the README's test command) installs no system
package: no package manager is named in it, and without a Chromium it says the browser
test will skip rather than installing one."""

from __future__ import annotations

import ast
import importlib.util
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "tools" / "fetch_test_data.py"
MANAGERS = {"apt", "apt-get", "aptitude", "dpkg", "yum", "dnf", "zypper", "pacman", "brew", "snap"}


def _package_manager_commands(source: str) -> tuple[list[str], int]:
    """Command lists in ``source`` whose program is a package manager, and the number of
    ``subprocess`` calls (a manager may be named in advice printed, never run)."""
    found, calls = [], 0
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.List, ast.Tuple)) and node.elts:
            first = node.elts[0]
            if isinstance(first, ast.Constant) and str(first.value) in MANAGERS:
                found.append(ast.unparse(node))
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and isinstance(node.func.value, ast.Name)
            and node.func.value.id == "subprocess"
        ):
            calls += 1
    return found, calls


def test_no_command_it_runs_is_a_package_manager() -> None:
    found, calls = _package_manager_commands(SCRIPT.read_text())
    assert found == []
    assert calls >= 3  # pip and venv runs: the scan sees the script's commands
    # The scan catches what the script used to do.
    old = 'for cmd in (["apt-get", "update"], ["apt-get", "install", "chromium"]):\n'
    old += "    subprocess.run(cmd)\n"
    assert len(_package_manager_commands(old)[0]) == 2


def test_without_chromium_it_says_the_test_will_skip(monkeypatch, capsys) -> None:
    monkeypatch.syspath_prepend(str(SCRIPT.parent))  # its helper module sits beside it
    spec = importlib.util.spec_from_file_location("fetch_test_data", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    monkeypatch.setattr(module.shutil, "which", lambda name: None)
    monkeypatch.delenv("CHROMIUM", raising=False)
    module.check_chromium()
    said = capsys.readouterr().out
    assert "will skip" in said and "installs no system package" in said
