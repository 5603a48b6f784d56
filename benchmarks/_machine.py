"""What a benchmark ran on, printed before its figures: CPU, load, accelerator, versions."""

from __future__ import annotations

import importlib.metadata
import os
import platform


def versions(packages: tuple[str, ...]) -> dict[str, str]:
    """Installed version of each distribution (``"absent"`` when not installed)."""
    out = {}
    for name in packages:
        try:
            out[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            out[name] = "absent"
    return out


def machine(packages: tuple[str, ...] = ()) -> dict[str, object]:
    """CPU cores, 1-minute load average, GPU (torch's view) and package versions."""
    info: dict[str, object] = {
        "python": platform.python_version(),
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
        f"Python {info['python']}, {info['cpu_cores']} CPU cores, load {info['load_average']}, "
        f"GPU: {info['gpu'] or 'none'}"
    )
    print("versions: " + ", ".join(f"{k} {v}" for k, v in info["versions"].items()))
