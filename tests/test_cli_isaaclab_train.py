"""``robotwright isaaclab-train``'s own checks, before any Isaac Lab import: every number
bounded, the device named, and without Isaac Lab one error line saying what to install
(the training itself: tests/isaaclab/test_semantic_nav.py, in the Isaac Lab stage)."""

from __future__ import annotations

import importlib.util

import pytest

from robotwright.cli import main

TASK = "Robotwright-Isaac-SemanticNav-Go2-v0"


@pytest.mark.parametrize(
    ("extra", "said"),
    [
        (["--num-envs", "0"], "--num-envs"),
        (["--num-envs", "1e9"], "--num-envs"),
        (["--max-iterations", "-3"], "--max-iterations"),
        (["--terrain-rows", "1000"], "--terrain-rows"),
        (["--seed", "x"], "--seed"),
        (["--device", "cuda;rm -rf"], "--device"),
    ],
)
def test_bad_numbers_and_devices_are_refused_by_name(extra, said, capsys) -> None:
    with pytest.raises(SystemExit) as done:
        main(["isaaclab-train", TASK, *extra])
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert said in err and "Traceback" not in err


@pytest.mark.skipif(
    importlib.util.find_spec("isaaclab_newton") is not None, reason="Isaac Lab is installed here"
)
def test_without_isaac_lab_one_line_says_what_to_install(capsys) -> None:
    assert main(["isaaclab-train", TASK, "--num-envs", "4"]) == 2
    err = capsys.readouterr().err
    assert "Isaac Lab 3" in err and "robotwright[isaaclab]" in err and "Traceback" not in err
