"""Hostile readers and noisy inputs: output stays quiet and exits stay right.

A reader that closes the pipe at any point (before reading, after one byte, after a
block), and warnings that list hundreds of values with awkward text in them.
"""

from __future__ import annotations

import os
import random
import subprocess
import sys

import pytest

from robotwright.errors import ConversionWarning

COMMANDS = [
    ["info", "mini_humanoid"],
    ["info", "arm6"],
    ["robots"],
    ["robots", "--json"],
    ["export", "--help"],
    ["--version"],
]
#: Bytes the reader takes before it closes the pipe (0: closed before the command runs).
READS = [0, 1, 64, 4096]


def _reader_closes_after(argv: list[str], take: int) -> subprocess.CompletedProcess:
    read, write = os.pipe()
    if take == 0:
        os.close(read)
    proc = subprocess.Popen(
        [sys.executable, "-m", "robotwright", *argv],
        stdout=write,
        stderr=subprocess.PIPE,
        text=True,
    )
    os.close(write)
    if take:
        with os.fdopen(read, "rb") as reader:
            reader.read(take)
    try:
        _, err = proc.communicate(timeout=600)  # a hang guard only
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return subprocess.CompletedProcess(proc.args, proc.returncode, "", err)


@pytest.mark.parametrize("take", READS)
@pytest.mark.parametrize("argv", COMMANDS, ids=" ".join)
def test_reader_leaving_at_any_point_is_a_quiet_exit_0(argv: list[str], take: int) -> None:
    done = _reader_closes_after(argv, take)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""


def _listing(rng: random.Random) -> tuple[str, int]:
    """A loss warning of a random number of values, with awkward text in the values."""
    awkward = ["", "a: b", "x\ty", "naïve", "  - nested", "\u202e", "(paren", "100%", "{}"]
    count = rng.randint(2, 400)
    items = [
        f"joint.csv: row {i}: column 'c{rng.randint(0, 5)}': {rng.choice(awkward)} value"
        for i in range(count)
    ]
    return f"robot 'r' to MJCF: {count} value(s) not written:\n" + "\n".join(
        f"  - {item}" for item in items
    ), count


@pytest.mark.parametrize("seed", range(20))
def test_long_loss_listings_display_as_one_line_and_keep_every_value(seed: int) -> None:
    message, count = _listing(random.Random(seed))
    warning = ConversionWarning(message)
    shown = f"{warning}"
    assert "\n" not in shown and shown.endswith("str(warning) lists each")
    # The counts shown add up to the number of values.
    counts = shown.split("not written: ", 1)[1].rsplit(";", 1)[0]
    assert sum(int(part.split()[0]) for part in counts.split(", ")) == count
    assert str(warning) == message


@pytest.mark.parametrize("seed", range(3))
def test_display_of_a_listing_through_the_warnings_module(seed: int) -> None:
    """What Python prints for a warning nobody filters: the message line and the source
    line, however many values the warning lists."""
    message, count = _listing(random.Random(seed))
    code = (
        "import warnings\n"
        "from robotwright.errors import ConversionWarning\n"
        f"warnings.warn(ConversionWarning({message!r}))\n"
    )
    done = subprocess.run(
        [sys.executable, "-W", "always", "-c", code], capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    assert 1 <= len(lines) <= 2 and f"{count} value(s) not written" in lines[0]
