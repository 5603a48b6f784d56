"""What a benchmark ran on, printed before its figures: CPU, load, accelerator, versions."""

from __future__ import annotations

import importlib.metadata
import os
import platform
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager


def versions(packages: tuple[str, ...]) -> dict[str, str]:
    """Installed version of each distribution (``"absent"`` when not installed)."""
    out = {}
    for name in packages:
        try:
            out[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            out[name] = "absent"
    return out


def peer_version(python: str, package: str) -> str:
    """``package``'s version in another interpreter (a peer run in its own environment)."""
    code = f"import importlib.metadata as m; print(m.version({package!r}))"
    try:
        done = subprocess.run(
            [python, "-c", code], capture_output=True, text=True, timeout=60, check=True
        )
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return done.stdout.strip() or "unknown"


def print_peer(python: str | None, package: str) -> None:
    """One line naming the peer's version and the interpreter it runs in."""
    if python:
        print(f"peer: {package} {peer_version(python, package)} (run by {python})")
    else:
        print(f"peer: {package} not run (no interpreter given)")


def cpu_model() -> str:
    """The CPU's model name (Linux's /proc/cpuinfo; the platform's processor elsewhere)."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def machine(packages: tuple[str, ...] = ()) -> dict[str, object]:
    """CPU cores, 1-minute load average, GPU (torch's view) and package versions."""
    info: dict[str, object] = {
        "python": platform.python_version(),
        "cpu": cpu_model(),
        "cpu_cores": os.cpu_count(),
        "load_average": round(os.getloadavg()[0], 2),
    }
    try:
        import torch

        info["gpu"] = torch.cuda.get_device_name(0) if torch.cuda.is_available() else None
    except ImportError:
        info["gpu"] = None
    info["versions"] = versions(("robotwright", *packages))
    return info


def print_machine(info: dict[str, object]) -> None:
    """One line for the machine, one for the versions."""
    print(
        f"Python {info['python']}, {info.get('cpu', 'unknown CPU')}, {info['cpu_cores']} CPU "
        f"cores, load {info['load_average']}, GPU: {info['gpu'] or 'none'}"
    )
    print("versions: " + ", ".join(f"{k} {v}" for k, v in info["versions"].items()))


@contextmanager
def measured(packages: tuple[str, ...] = ()) -> Iterator[None]:
    """Print the machine, the load and the versions (MuJoCo's and numpy's, and
    ``packages``) before the block (a benchmark's figures), and the load after it: a
    figure is read with the load it ran under."""
    print_machine(machine(("mujoco", "numpy", *packages)))
    try:
        yield
    finally:
        print(f"load average after: {os.getloadavg()[0]:.2f} (1 min), {os.cpu_count()} CPU cores")
